"""markers.formation_markers on its own: what each marker shows, checked against the simulator's
snapshot, the leader's mission path and the scenario's gusts; its cost."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from builtin_interfaces.msg import Time
from multilift_control.mission import MissionPath
from rclpy.serialization import deserialize_message, serialize_message
from visualization_msgs.msg import Marker, MarkerArray

from multilift_sim import scenario as scenario_io
from multilift_sim.ros.markers import (BODY_DIAMETER_ARMS, FormationMarkers, formation_markers,
                                   mission_corners, tension_color)
from multilift_sim.simulation import FormationSimulator
from multilift_sim.wire.scene import CABLE_SEGMENTS


def by_key(array: MarkerArray) -> dict[tuple[str, int], Marker]:
    return {(m.ns, m.id): m for m in array.markers}


def _rotation(q) -> np.ndarray:
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def xyz(p) -> np.ndarray:
    return np.array([p.x, p.y, p.z])


def test_every_marker_in_world_at_the_stamp(twin):
    scenario, snapshot = twin
    array = formation_markers(snapshot, [4.0, 5.0], scenario, 1_230_000_000)
    markers = by_key(array)
    assert sorted(markers) == sorted([('uav', 1), ('uav', 2), ('uav_heading', 1),
                                      ('uav_heading', 2), ('cable', 1), ('cable', 2),
                                      ('payload', 0), ('mission_path', 0), ('gust_zone', 0),
                                      ('gust_zone', 1)])
    for marker in array.markers:
        assert marker.header.frame_id == 'world'
        assert (marker.header.stamp.sec, marker.header.stamp.nanosec) == (1, 230_000_000)
        assert marker.action == Marker.ADD
        assert marker.color.a > 0
    stamped = formation_markers(snapshot, [4.0, 5.0], scenario, Time(sec=7, nanosec=5))
    assert all((m.header.stamp.sec, m.header.stamp.nanosec) == (7, 5) for m in stamped.markers)


def test_bodies_cables_and_payload_follow_the_snapshot(twin):
    scenario, snapshot = twin
    markers = by_key(formation_markers(snapshot, [4.0, 5.0], scenario, 0))
    payload = markers[('payload', 0)]
    assert np.allclose(xyz(payload.pose.position), snapshot.payload_position)
    for i, uav in enumerate(snapshot.uavs, start=1):
        body = markers[('uav', i)]
        assert body.type == Marker.CYLINDER
        assert np.allclose(xyz(body.pose.position), uav.position)
        assert np.allclose(_rotation(body.pose.orientation), uav.rotation, atol=1e-9)
        arm = scenario.uavs[i - 1].vehicle.arm_length
        assert body.scale.x == pytest.approx(BODY_DIAMETER_ARMS * arm)
        heading = markers[('uav_heading', i)]
        assert heading.type == Marker.ARROW
        assert np.allclose(_rotation(heading.pose.orientation) @ [1, 0, 0],
                           uav.rotation[:, 0])  # the arrow points along body x
        cable = markers[('cable', i)]
        assert cable.type == Marker.LINE_LIST and len(cable.points) == 2 * CABLE_SEGMENTS
        points = np.array([xyz(p) for p in cable.points])
        assert np.allclose(points[0], uav.position)
        assert np.allclose(points[-1], snapshot.payload_position)
        # taut: the segments join end to end into one solid line
        assert np.allclose(points[1:-1:2], points[2::2])
        length = np.linalg.norm(points[-1] - points[0])
        assert length == pytest.approx(scenario.uavs[i - 1].cable_length, rel=1e-3)
    assert not np.allclose(snapshot.uavs[0].euler, 0.0)  # the check above saw an attitude


def test_a_slack_cable_is_dashed(twin):
    scenario, snapshot = twin
    markers = by_key(formation_markers(snapshot, [0.0, 5.0], scenario, 0, taut=[False, True]))
    slack = np.array([xyz(p) for p in markers[('cable', 1)].points])
    taut = np.array([xyz(p) for p in markers[('cable', 2)].points])
    gaps = np.linalg.norm(slack[2::2] - slack[1:-1:2], axis=1)
    dashes = np.linalg.norm(slack[1::2] - slack[::2], axis=1)
    assert np.allclose(gaps, dashes[1:]) and np.all(gaps > 0)   # half drawn, half gap
    assert np.allclose(slack[0], snapshot.uavs[0].position)
    assert np.allclose(taut[1:-1:2], taut[2::2])             # the other cable stays solid


def test_cables_coloured_by_tension():
    reference = 4.0
    assert tension_color(0.0, reference) == (0.0, 0.0, 1.0)
    assert tension_color(reference, reference) == (0.0, 1.0, 0.0)
    assert tension_color(2 * reference, reference) == (1.0, 0.0, 0.0)
    assert tension_color(10 * reference, reference) == (1.0, 0.0, 0.0)
    assert tension_color(-0.5, reference) == (0.9, 0.1, 0.9)  # compression
    assert tension_color(float('nan'), reference) == (0.9, 0.1, 0.9)
    reds = [tension_color(t, reference)[0] for t in np.linspace(reference, 2 * reference, 9)]
    assert reds == sorted(reds)


def test_cable_colour_in_the_array(twin):
    scenario, snapshot = twin
    builder = FormationMarkers(scenario)
    share = scenario.payload.mass * scenario.simulation.gravity / 2
    assert builder.reference_tension == pytest.approx(share)
    markers = by_key(builder.build(snapshot, [0.0, 2 * share], 0))
    one, two = markers[('cable', 1)].color, markers[('cable', 2)].color
    assert (one.r, one.g, one.b) == (0.0, 0.0, 1.0)
    assert (two.r, two.g, two.b) == (1.0, 0.0, 0.0)


def test_mission_path_is_the_leader_reference(twin):
    scenario, snapshot = twin
    path = by_key(formation_markers(snapshot, [4.0, 5.0], scenario, 0))[('mission_path', 0)]
    # the mission's corners: the raw path (mission.reference_filter_time rounds them within
    # about 2 tau of each corner, and both end where the path ends)
    reference = MissionPath(dataclasses.replace(scenario.mission, reference_filter_time=0.0))
    ends = [0.0] + [s.end_time for s in scenario.mission.segments]
    assert len(path.points) == len(ends)
    for point, t in zip(path.points, ends):
        assert np.allclose(xyz(point), reference(t).position)
    assert mission_corners(scenario)[2] == pytest.approx((7.5, 0.0, 3.0))  # climb, then +x


def test_gust_zones_are_cylinders_of_radius_h(twin):
    scenario, snapshot = twin
    markers = by_key(formation_markers(snapshot, [4.0, 5.0], scenario, 0))
    for k, gust in enumerate(scenario.gusts):
        zone = markers[('gust_zone', k)]
        assert zone.type == Marker.CYLINDER
        assert zone.scale.x == zone.scale.y == pytest.approx(2 * gust.gradient_distance)
        assert (zone.pose.position.x, zone.pose.position.y) == pytest.approx(gust.center)
        bottom = zone.pose.position.z - zone.scale.z / 2
        top = zone.pose.position.z + zone.scale.z / 2
        assert bottom < snapshot.payload_position[2] < top  # the payload's heights


def test_round_trip_and_five_uavs(twin):
    scenario, snapshot = twin
    array = formation_markers(snapshot, [4.0, 5.0], scenario, 0)
    copy = deserialize_message(serialize_message(array), MarkerArray)
    assert [(m.ns, m.id, m.type) for m in copy.markers] == [
        (m.ns, m.id, m.type) for m in array.markers]
    # five UAVs: a body, a heading and a cable each (the cost per call is a benchmark's business)
    v5 = scenario_io.load('v5')
    five = formation_markers(FormationSimulator(v5).snapshot(), [5.0] * 5, v5, 0)
    assert len(five.markers) == len(array.markers) + 3 * 3
    with pytest.raises(ValueError, match='2 UAVs'):
        formation_markers(snapshot, [4.0], scenario, 0)


def test_obstacles_are_drawn_at_their_size_and_yaw():
    # window's walls are boxes, forest's trees cylinders; a turned sphere-free box and a ball
    # added to the window: each marker at its centre, its full size, turned by its yaw
    import math

    from multilift_sim.wire.scene import obstacle_specs
    scenario = scenario_io.load('window')
    ball = dataclasses.replace(scenario.world.obstacles[0], name='ball', type='sphere',
                               half=(0.2, 0.2, 0.2), center=(3.0, 1.0, 1.0))
    turned = dataclasses.replace(scenario.world.obstacles[0], name='turned',
                                 yaw=math.radians(30.0))
    world = dataclasses.replace(scenario.world,
                                obstacles=scenario.world.obstacles + (ball, turned))
    specs = obstacle_specs(dataclasses.replace(scenario, world=world))
    assert [(s.ns, s.id) for s in specs] == [('obstacle', k) for k in range(6)]
    wall = specs[0]
    assert wall.type == Marker.CUBE and wall.scale == pytest.approx((0.05, 1.35, 2.2))
    assert wall.position == pytest.approx([1.5, 0.825, 1.1])
    assert specs[4].type == Marker.SPHERE and specs[4].scale == pytest.approx((0.4,) * 3)
    q = specs[5].orientation  # (x, y, z, w) of 30 deg about z
    assert q == pytest.approx([0.0, 0.0, math.sin(math.radians(15)), math.cos(math.radians(15))])
    trees = obstacle_specs(scenario_io.load('forest'))
    assert all(t.type == Marker.CYLINDER and t.scale == pytest.approx((0.16, 0.16, 3.0))
               for t in trees)
    assert obstacle_specs(scenario_io.load('twin_lift')) == []  # no world: nothing drawn


def test_a_cable_held_off_the_uav_s_centre_is_drawn_from_its_hold(twin):
    """twin_lift's cables held 0.1, 0.05, -0.1 m off each UAV's centre (body FLU): each cable
    marker starts at r_i + R_i a_i, R_i the snapshot's attitude (tilted), not at r_i."""
    scenario, snapshot = twin
    attach = np.array([0.1, 0.05, -0.1])
    held = dataclasses.replace(scenario, uavs=tuple(
        dataclasses.replace(u, attach_point=tuple(attach)) for u in scenario.uavs))
    markers = by_key(formation_markers(snapshot, [4.0, 5.0], held, 0))
    for i, uav in enumerate(snapshot.uavs, start=1):
        start = xyz(markers[('cable', i)].points[0])
        assert np.allclose(start, uav.position + uav.rotation @ attach, atol=1e-9)
        assert np.linalg.norm(start - uav.position) > 0.1
