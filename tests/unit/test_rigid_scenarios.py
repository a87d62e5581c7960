"""Rigid-body payloads in scenarios (issue 20 items 1 and 4): `payload.type: rigid_body`
validated (its shape, a rigid body's inertia, one attach point per cable), `box_lift` and
`beam_lift` starting on the constraint manifold and flying the §4.2 mission within Algorithm
1's tolerance, the point payloads unchanged, and the payload's attitude in the messages."""
from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import fly
from multilift_sim import scenario as scenario_io
from multilift_sim.dynamics import FormationModel
from multilift_sim.payloads.rigid_body import solid_inertia
from multilift_sim.start import initial_state


def _edited(name: str, **payload) -> str:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['payload'].update(payload)
    for key in [k for k, v in payload.items() if v is None]:
        del data['payload'][key]
    return yaml.safe_dump(data)


def test_the_box_starts_level_on_every_cable_with_the_solid_s_inertia():
    scenario = scenario_io.load('box_lift')
    payload = scenario.payload
    assert payload.type == 'rigid_body' and payload.shape == 'box'
    assert payload.inertia == pytest.approx(
        (2.0 / 12 * (0.36 + 0.16), 2.0 / 12 * (1.0 + 0.16), 2.0 / 12 * (1.0 + 0.36)))
    model = FormationModel(scenario.formation_params())
    x = initial_state(scenario)
    assert x.size == model.layout.size == 2 * (3 * 4 + 3) + 7 * 4 + 7  # the UAVs' blocks, then its
    g, g_dot = model.constraint_residuals(x)
    assert np.abs(g).max() < 1e-12 and np.abs(g_dot).max() == 0.0
    assert model.layout.payload_quaternion(x).tolist() == [1.0, 0.0, 0.0, 0.0]
    # each UAV over its corner's side, the box under the rectangle's centre
    uavs, payload_position = model.layout.uav_positions(x), model.layout.payload_position(x)
    assert np.allclose(uavs[:, :2].mean(axis=0), payload_position[:2])


def test_cylinder_inertia_and_the_point_payload_unchanged():
    assert solid_inertia('cylinder', 1.5, (3.0, 0.03)) == pytest.approx(
        (0.5 * 1.5 * 0.03 ** 2, 1.5 / 12 * (3 * 0.03 ** 2 + 9.0), 1.5 / 12 * (3 * 0.03 ** 2 + 9.0)))
    twin = scenario_io.load('twin_lift')
    assert twin.payload.type == 'point' and twin.formation_params().payload_inertia is None
    assert initial_state(twin).size == 2 * (3 * 2 + 3) + 7 * 2


@pytest.mark.parametrize('payload,message', [
    ({'inertia': [0.1, 0.1, 0.5]}, r"payload\.inertia: \[0\.1, 0\.1, 0\.5\] is no rigid body's"),
    ({'attach_points': [[0.5, 0.3, 0.2]]}, r'attach_points: .* one \[x, y, z\] per cable \(4\)'),
    ({'shape': 'sphere'}, r'payload\.shape: .sphere. must be one of box, cylinder'),
    ({'size': [1.0, 0.6]}, r'payload\.size: .* must be a list of 3 numbers'),
    ({'type': 'blob'}, r'payload\.type: .blob. must be one of point, rigid_body'),
    ({'spin': 1.0}, r'payload\.spin: unknown key')])
def test_bad_rigid_payloads_name_key_and_rule(payload, message):
    with pytest.raises(scenario_io.ScenarioError, match=message):
        scenario_io.loads(_edited('box_lift', **payload))


def test_a_rigid_payload_needs_the_baumgarte_dae():
    data = yaml.safe_load((SCENARIOS / 'box_lift.yaml').read_text())
    data['cable_model'] = 'slack'  # slack cables on a body: tests/unit/test_slack_bodies.py
    assert scenario_io.loads(yaml.safe_dump(data)).cable_model == 'slack'
    data['simulation']['integrator'] = 'nullspace'
    with pytest.raises(scenario_io.ScenarioError, match='rigid_body needs simulation.integrator'):
        scenario_io.loads(yaml.safe_dump(data))


@pytest.mark.parametrize('name', ['box_lift', 'beam_lift'])
def test_the_lifts_fly_the_mission_within_the_tolerance(name):
    """40 s of the §4.2 mission (the climb, the +x leg, the first corner): |g| far inside
    eps_g, the rotors unsaturated, the leader within 0.3 m rms of its path, the body's
    quaternion of unit length and its tilt moderate."""
    scenario = scenario_io.load(name).with_duration(40.0)
    run = fly(scenario)
    summary = run.summary()
    assert run.error is None
    assert summary['sim']['max_abs_constraint'] < 1e-6
    assert max(summary['sim']['saturated_time']) == 0.0
    assert summary['leader']['rms_tracking_error'] < 0.3
    layout = FormationModel(scenario.formation_params()).layout
    quaternion = layout.payload_quaternion(run.engine.state[0])
    assert abs(np.linalg.norm(quaternion) - 1.0) < 1e-14
    tilt = 2.0 * math.degrees(math.asin(min(1.0, math.hypot(quaternion[1], quaternion[2]))))
    assert tilt < 20.0


def test_the_payload_s_attitude_is_in_its_odometry_tf_and_plots(tmp_path):
    """The headless bag's /payload/odom carries the box's orientation (not the identity once
    it tilts in the climb) and body rates, /tf's payload frame the same rotation and a frame
    per attach point under it, and `multilift plot` draws the payload's attitude (a figure a
    point payload skips)."""
    from pathlib import Path

    from rosbags.highlevel import AnyReader

    from multilift_tools.headless_bag import record_headless
    scenario = scenario_io.load('box_lift').with_duration(3.0)
    record_headless(scenario, tmp_path / 'bag')
    with AnyReader([Path(tmp_path / 'bag')]) as reader:
        odom = [c for c in reader.connections if c.topic == '/payload/odom']
        tf = [c for c in reader.connections if c.topic == '/tf']
        poses = [reader.deserialize(raw, c.msgtype).pose.pose.orientation
                 for c, _, raw in reader.messages(odom)]
        frames = [[t for t in reader.deserialize(raw, c.msgtype).transforms
                   if t.child_frame_id == 'payload'][0].transform.rotation
                  for c, _, raw in reader.messages(tf)]
        connection, _, raw = next(iter(reader.messages(tf)))
        attach = [(t.header.frame_id, t.child_frame_id, t.transform.translation.x)
                  for t in reader.deserialize(raw, connection.msgtype).transforms
                  if t.child_frame_id.startswith('payload/')]
    assert attach == [('payload', f'payload/attach{i}', x)
                      for i, x in enumerate((0.5, -0.5, -0.5, 0.5), start=1)]
    last, frame = poses[-1], frames[-1]
    assert (last.x, last.y, last.z, last.w) == (frame.x, frame.y, frame.z, frame.w)
    assert abs(last.w) < 1.0 - 1e-6 and (poses[0].x, poses[0].w) == (0.0, 1.0)
    from multilift_tools.figures import plot_main
    assert plot_main([str(tmp_path / 'bag'), '--out', str(tmp_path / 'plots')]) == 0
    assert (tmp_path / 'plots' / 'payload_attitude.png').stat().st_size > 15_000


@pytest.mark.parametrize('name,kind', [('box_lift', 1), ('beam_lift', 3)])
def test_the_markers_draw_the_body_and_end_the_cables_at_its_attach_points(name, kind):
    """/visualization/markers of a rigid payload: its shape (a CUBE of the box's size, a
    CYLINDER of the beam's length laid along its x axis) at its pose, each cable from its UAV
    to its attach point r_p + R_p b_i."""
    from multilift_sim.physics.layout import attitude_slot
    from multilift_sim.physics.rigid_payload import payload_rotation
    from multilift_sim.simulation import FormationSimulator
    from multilift_sim.wire.scene import CABLE_SEGMENTS, FormationScene

    scenario = scenario_io.load(name)
    simulator = FormationSimulator(scenario)
    hover = [np.full(4, 1900.0)] * scenario.n_uavs
    for _ in range(150):
        simulator.advance(hover, [np.zeros(4, bool)] * scenario.n_uavs)
    snap = simulator.snapshot()
    scene = FormationScene(scenario)
    scene.update([u.position for u in snap.uavs], [u.euler for u in snap.uavs],
                 snap.payload_position, [1.0] * scenario.n_uavs, None,
                 snap.payload_attitude[0])
    assert scene.payload.type == kind
    rotation = payload_rotation(simulator.state, attitude_slot(scenario.n_uavs))
    for cable, attach in zip(scene.cables, scenario.payload.attach_points):
        end = snap.payload_position + rotation @ np.array(attach)
        assert np.abs(np.array(cable.points[2 * CABLE_SEGMENTS - 1]) - end).max() < 1e-12
    # the drawn body's axes: the box's x (the cylinder's marker z) along the payload's x
    x, y, z, w = scene.payload.orientation
    drawn = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    axis = drawn[:, 0] if kind == 1 else drawn[:, 2]
    assert np.abs(axis - rotation[:, 0]).max() < 1e-12


def test_cables_off_the_uav_centres_in_a_scenario():
    """`uavs[i].attach_point` (issue 20 item 2; body FLU, default the centre): validated, the
    start on the manifold (the twin-lift's swing about the cables' upper ends), the engine
    and the per-object path to the bit, the mission flown within the tolerance."""
    from multilift_control.engine import Engine
    from multilift_control.headless import run_headless

    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    data['uavs'][0]['attach_point'] = [0.02, 0.0, -0.1]
    data['uavs'][1]['attach_point'] = [0.3, 0.1, -0.25]
    data['simulation']['duration'] = 3.0
    scenario = scenario_io.loads(yaml.safe_dump(data))
    assert scenario.formation_params().uav_attach_points == ((0.02, 0.0, -0.1),
                                                              (0.3, 0.1, -0.25))
    model = FormationModel(scenario.formation_params())
    g, g_dot = model.constraint_residuals(initial_state(scenario))
    assert np.abs(g).max() < 1e-12 and np.abs(g_dot).max() == 0.0
    engine = Engine(scenario)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert run.summary()['sim']['max_abs_constraint'] < 1e-6
    # the follower holds the altitude it starts at (its cable's upper end off its centre too)
    from multilift_control.formation import FormationFollower
    from multilift_control.laws.layout import FOLLOWER_ALTITUDE_OFFSET
    start = model.layout.uav_positions(initial_state(scenario))
    follower = FormationFollower.from_scenario(scenario, 1)
    assert follower.constants[FOLLOWER_ALTITUDE_OFFSET] == pytest.approx(
        start[1, 2] - start[0, 2], abs=1e-12)
    with pytest.raises(scenario_io.ScenarioError,
                       match=r'uavs\[0\]\.attach_point need simulation\.integrator'):
        scenario_io.loads(yaml.safe_dump(dict(data, simulation=dict(data['simulation'],
                                                                    integrator='nullspace'))))
    data['uavs'][1]['attach_point'] = [0.1, 0.0]
    with pytest.raises(scenario_io.ScenarioError, match=r'uavs\[1\]\.attach_point: .* list of 3'):
        scenario_io.loads(yaml.safe_dump(data))


@pytest.mark.parametrize('name', ['box_lift', 'beam_lift'])
def test_the_engine_flies_a_rigid_body_as_the_per_object_path(tmp_path, monkeypatch, name):
    """The batched engine and the per-object path (the simulator node's) fly a rigid payload to
    the bit, and write byte-identical bags (the body's pose in /payload/odom, /tf and the
    markers), over chunk boundaries."""
    from multilift_control.engine import Engine
    from multilift_control.headless import run_headless
    from multilift_tools import headless_bag

    scenario = scenario_io.load(name).with_duration(1.5)
    engine = Engine([scenario] * 2)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert np.array_equal(engine.state[1], run.simulator.state)
    monkeypatch.setattr(headless_bag, 'CHUNK_TICKS', 37)
    headless_bag.record_headless(scenario, tmp_path / 'engine' / 'bag')
    headless_bag._record_per_object(scenario, tmp_path / 'objects' / 'bag')
    for path in (tmp_path / 'engine' / 'bag').iterdir():
        assert path.read_bytes() == (tmp_path / 'objects' / 'bag' / path.name).read_bytes()
