"""The clearance checks (issue 34 item 5, multilift_sim.physics.clearance and the obstacle
types of multilift_sim.obstacles): each signed distance against its analytic value (point -
box at a face, an edge, a corner and inside, turned by a yaw; point - cylinder; a segment
past a cylinder and through it; segment - segment, skew and parallel; point - segment), the
compiled functions against their uncompiled run (`kernels.uncompiled`) bit for bit, the
tick's measure over a hand-built formation against distances worked out by hand, and the
`world:` section's one-line errors."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.obstacles import OBSTACLE_TYPES, type_index
from multilift_sim.physics import clearance, layout
from multilift_sim.scenario import ScenarioError

pytest.importorskip('numba')
SCENARIOS = Path(__file__).resolve().parents[2] / 'scenarios'


def _row(kind: str, center, half, yaw: float = 0.0) -> np.ndarray:
    row = np.zeros(layout.OBSTACLE_COLUMNS)
    row[layout.OBSTACLE_TYPE] = type_index(kind)
    row[layout.OBSTACLE_CENTER:layout.OBSTACLE_CENTER + 3] = center
    row[layout.OBSTACLE_HALF:layout.OBSTACLE_HALF + 3] = half
    row[layout.OBSTACLE_COS_YAW], row[layout.OBSTACLE_SIN_YAW] = math.cos(yaw), math.sin(yaw)
    row[layout.OBSTACLE_BOUND] = float(np.linalg.norm(half))
    return row


def _point(row, p) -> float:
    return clearance.point_distance(row, p[0], p[1], p[2], np.empty(1))


BOX = _row('box', (1.0, 2.0, 3.0), (0.5, 1.0, 1.5))


@pytest.mark.parametrize('point, expected', [
    ((2.5, 2.0, 3.0), 1.0),                          # off the +x face
    ((1.0, 2.0, 0.5), 1.0),                          # below the -z face
    ((2.5, 4.0, 3.0), math.hypot(1.0, 1.0)),         # off the +x, +y edge
    ((2.5, 4.0, 5.5), math.sqrt(3.0)),               # off the corner (1, 1, 1) away
    ((1.0, 2.0, 3.0), -0.5),                         # the centre: the nearest face 0.5 in
    ((1.3, 2.0, 3.0), -0.2),                         # inside, 0.2 from the +x face
])
def test_point_to_box(point, expected):
    assert _point(BOX, point) == pytest.approx(expected, abs=1e-12)


def test_a_turned_box_measures_in_its_own_axes():
    # a 2 x 0.2 box turned 90 deg about z: its long side along world y
    row = _row('box', (0.0, 0.0, 0.0), (1.0, 0.1, 0.5), yaw=math.pi / 2)
    assert _point(row, (0.0, 1.5, 0.0)) == pytest.approx(0.5, abs=1e-12)
    assert _point(row, (0.5, 0.0, 0.0)) == pytest.approx(0.4, abs=1e-12)


CYLINDER = _row('cylinder', (0.0, 0.0, 1.0), (0.2, 0.2, 1.0))  # radius 0.2, z from 0 to 2


@pytest.mark.parametrize('point, expected', [
    ((1.0, 0.0, 1.0), 0.8),                          # beside it
    ((0.0, 0.0, 2.5), 0.5),                          # above its top
    ((0.6, 0.0, 2.3), 0.5),                          # off the top rim: (0.4, 0.3) away
    ((0.1, 0.0, 1.0), -0.1),                         # inside, nearer the side
    ((0.0, 0.0, 1.9), -0.1),                         # inside, nearer the top
])
def test_point_to_cylinder(point, expected):
    assert _point(CYLINDER, point) == pytest.approx(expected, abs=1e-12)


def test_point_to_sphere():
    row = _row('sphere', (1.0, 1.0, 1.0), (0.5, 0.5, 0.5))
    assert _point(row, (1.0, 1.0, 3.0)) == pytest.approx(1.5, abs=1e-12)
    assert _point(row, (1.0, 1.2, 1.0)) == pytest.approx(-0.3, abs=1e-12)


@pytest.mark.parametrize('a, b, expected', [
    # a horizontal segment passing the axis 0.7 m away at mid-height: 0.7 - 0.2
    ((-2.0, 0.7, 1.0), (3.0, 0.7, 1.0), 0.5),
    # a slanted one whose closest approach to the axis is off the segment's middle: the
    # line x = t, y = 0.5 + t (z = 1): its distance to the axis is 0.5 / sqrt(2)
    ((-2.0, -1.5, 1.0), (1.0, 1.5, 1.0), 0.5 / math.sqrt(2.0) - 0.2),
    # one that ends before reaching it: its end (0.5, 0, 1) is 0.3 from the side
    ((3.0, 0.0, 1.0), (0.5, 0.0, 1.0), 0.3),
    # a vertical one above the top: its lower end 0.4 over the top
    ((0.0, 0.0, 2.4), (0.0, 0.0, 4.0), 0.4),
    # through the cylinder along a diameter at mid-height: the axis, 0.2 in
    ((-1.0, 0.0, 1.0), (1.0, 0.0, 1.0), -0.2),
    # passing over the top rim diagonally: from (0.5, 0, 2.5) to (-0.5, 0, 2.5), 0.5 above
    ((0.5, 0.0, 2.5), (-0.5, 0.0, 2.5), 0.5),
])
def test_segment_to_cylinder(a, b, expected):
    got = clearance.segment_distance(CYLINDER, np.array(a, float), np.array(b, float),
                                     np.empty(1))
    assert got == pytest.approx(expected, abs=1e-9)


def test_segment_to_box_past_an_edge():
    # the line through (1.5, 4.5, 3) and (2.5, 3.5, 3) passes the box's +x, +y edge at
    # (1.5, 3, .): its distance to that edge is the distance from (1.5, 3) to x + y = 6, 1.5/sqrt 2
    got = clearance.segment_distance(BOX, np.array([0.5, 5.5, 3.0]), np.array([3.5, 2.5, 3.0]),
                                     np.empty(1))
    assert got == pytest.approx(1.5 / math.sqrt(2.0), abs=1e-9)


@pytest.mark.parametrize('p1, q1, p2, q2, expected', [
    # skew, crossing 0.3 apart: along x at z = 0 and along y at z = 0.3
    ((-1, 0, 0), (1, 0, 0), (0, -1, 0.3), (0, 1, 0.3), 0.3),
    # skew with the closest points off both segments: ends (1, 0, 0) and (2, 0.5, 0)
    ((-1, 0, 0), (1, 0, 0), (2, 0.5, 0), (2, 3, 0), math.hypot(1.0, 0.5)),
    # parallel, 0.4 apart and overlapping
    ((0, 0, 0), (2, 0, 0), (1, 0.4, 0), (3, 0.4, 0), 0.4),
    # collinear, a 0.5 gap between them
    ((0, 0, 0), (1, 0, 0), (1.5, 0, 0), (3, 0, 0), 0.5),
    # touching at a shared end
    ((0, 0, 0), (1, 1, 1), (1, 1, 1), (2, 0, 0), 0.0),
    # a point (degenerate segment) over a segment's middle
    ((0.5, 0.0, 0.7), (0.5, 0.0, 0.7), (0, 0, 0), (1, 0, 0), 0.7),
])
def test_segment_to_segment(p1, q1, p2, q2, expected):
    args = [np.array(v, dtype=float) for v in (p1, q1, p2, q2)]
    assert clearance.segment_segment(*args) == pytest.approx(expected, abs=1e-12)
    assert clearance.segment_segment(*args[2:], *args[:2]) == pytest.approx(expected, abs=1e-12)


def test_point_to_segment():
    a, b = np.array([0.0, 0.0, 0.0]), np.array([2.0, 0.0, 0.0])
    assert clearance.point_segment(1.0, 0.3, 0.4, a, b) == pytest.approx(0.5, abs=1e-15)
    assert clearance.point_segment(3.0, 0.0, 0.0, a, b) == pytest.approx(1.0, abs=1e-15)


def test_compiled_and_uncompiled_agree_bit_for_bit():
    rng = np.random.default_rng(34)
    rows = [BOX, CYLINDER, _row('sphere', (0.2, -0.1, 0.4), (0.7, 0.7, 0.7)),
            _row('box', (0.1, 0.2, 0.3), (0.4, 0.6, 0.2), yaw=0.7)]
    for _ in range(40):
        a, b = rng.uniform(-3, 4, 3), rng.uniform(-3, 4, 3)
        for row in rows:
            for function, args in (
                    (clearance.point_distance, (row, *a, np.empty(1))),
                    (clearance.segment_distance, (row, a, b, np.empty(1)))):
                assert function(*args) == kernels.uncompiled(function)(*args)
        c, d = rng.uniform(-3, 4, 3), rng.uniform(-3, 4, 3)
        assert clearance.segment_segment(a, b, c, d) == kernels.uncompiled(
            clearance.segment_segment)(a, b, c, d)
        assert clearance.point_segment(*c, a, b) == kernels.uncompiled(
            clearance.point_segment)(*c, a, b)


def _formation_state(uavs: np.ndarray, payload: np.ndarray) -> np.ndarray:
    """A point payload's state of n UAVs at rest, level (unit quaternions)."""
    n = len(uavs)
    state = np.zeros(layout.attitude_slot(n))
    for i in range(n):
        state[layout.uav_slot(i):layout.uav_slot(i) + 3] = uavs[i]
    state[layout.payload_slot(n):layout.payload_slot(n) + 3] = payload
    for i in range(n):
        state[layout.uav_attitude_slot(n, i)] = 1.0
    return state


def test_measure_names_the_least_of_each_kind_and_the_first_contact():
    uavs = np.array([[0.0, 0.0, 1.5], [0.6, 0.0, 1.5]])
    payload = np.array([0.3, 0.0, 1.1])
    state = _formation_state(uavs, payload)
    world = np.array([1.0, 0.0, 0.05, 0.0])  # checked, ground z = 0, payload radius 0.05
    pillar = _row('cylinder', (0.3, 0.5, 1.0), (0.1, 0.1, 1.0))  # 0.5 m beside the payload
    constants = np.zeros((2, layout.UAV_COLUMNS))
    radii = np.array([0.07, 0.07])
    least = np.zeros((layout.CLEARANCE_KINDS, layout.CLEARANCE_COLUMNS))
    least[:, layout.CLEARANCE_VALUE] = math.inf
    contact = np.full(layout.CLEARANCE_COLUMNS, -1.0)
    args = (world, pillar[None, :], radii, constants, state, 2.5, least, contact)
    touched = clearance.measure(*args)
    assert not touched and contact[layout.CLEARANCE_KIND] == -1.0
    value = least[:, layout.CLEARANCE_VALUE]
    # each UAV: sqrt(0.3^2 + 0.5^2) from the axis, at z 1.5 within the height: less 0.1, 0.07
    assert value[layout.CLEARANCE_UAV_WORLD] == pytest.approx(math.hypot(0.3, 0.5) - 0.17)
    # the payload: 0.5 from the axis, less 0.1 and its 0.05; the ground is farther (1.05)
    assert value[layout.CLEARANCE_PAYLOAD_WORLD] == pytest.approx(0.35)
    # a cable from (0, 0, 1.5) to (0.3, 0, 1.1): nearest the axis at its payload end, 0.5 - 0.1
    assert value[layout.CLEARANCE_CABLE_WORLD] == pytest.approx(0.4, abs=1e-9)
    assert value[layout.CLEARANCE_UAV_UAV] == pytest.approx(0.6 - 0.14)
    # uav1 to cable 2 (u = (-0.3, 0, -0.4) from (0.6, 0, 1.5)): the perpendicular meets it
    # inside (at 0.72 of its length), |w x u| / |u| = 0.24 / 0.5 away, w = (-0.6, 0, 0)
    assert value[layout.CLEARANCE_UAV_CABLE] == pytest.approx(0.48 - 0.07)
    assert math.isinf(value[layout.CLEARANCE_CABLE_CABLE])  # a point payload's cables meet
    assert least[layout.CLEARANCE_UAV_WORLD, layout.CLEARANCE_TIME] == 2.5
    # the same bits uncompiled
    copies = [a.copy() if isinstance(a, np.ndarray) else a for a in args]
    copies[-2][:, layout.CLEARANCE_VALUE] = math.inf
    copies[-1][:] = -1.0
    kernels.uncompiled(clearance.measure)(*copies)
    assert np.array_equal(copies[-2], least)
    # the pillar moved onto uav2: a contact, named, kept as the first
    pillar[layout.OBSTACLE_CENTER:layout.OBSTACLE_CENTER + 2] = (0.6, 0.1)
    assert clearance.measure(*args)
    assert contact[layout.CLEARANCE_KIND] == layout.CLEARANCE_UAV_WORLD
    assert (contact[layout.CLEARANCE_FIRST], contact[layout.CLEARANCE_SECOND]) == (1.0, 0.0)
    assert contact[layout.CLEARANCE_VALUE] == pytest.approx(-0.07)


def _cf2(**world) -> dict:
    data = yaml.safe_load((SCENARIOS / 'cf2_payload.yaml').read_text())
    data['world'] = world
    return data


@pytest.mark.parametrize('world, message', [
    ({'obstacles': [{'type': 'box', 'center': [3, 0, 1], 'size': [1, -1, 1]}]},
     'world.obstacles[0].size: [1, -1, 1] must be > 0'),
    ({'obstacles': [{'type': 'cylinder', 'center': [3, 0, 1], 'radius': 0.1}]},
     'world.obstacles[0].height'),
    ({'obstacles': [{'type': 'cone', 'center': [3, 0, 1]}]}, 'world.obstacles[0].type'),
    ({'on_contact': 'bounce'}, 'world.on_contact'),
    ({'obstacles': [{'type': 'sphere', 'center': [3, 0, 1], 'radius': 0.1, 'name': 'a'},
                    {'type': 'sphere', 'center': [4, 0, 1], 'radius': 0.1, 'name': 'a'}]},
     "world.obstacles[1].name: 'a' is the name of an obstacle before it"),
    ({'obstacles': [{'type': 'sphere', 'center': [0, 0, 1.5], 'radius': 0.1,
                     'name': 'ball'}]}, "world: uav1 starts touching obstacle 'ball'"),
    ({'ground': 1.2}, 'world: cable1 starts touching ground'),  # before the payload
    ({'colour': 'green'}, 'world.colour'),
])
def test_bad_worlds_are_one_line(world, message):
    with pytest.raises(ScenarioError) as error:
        scenario_io.from_mapping(_cf2(**world), 'cf2_payload.yaml')
    assert message in str(error.value) and '\n' not in str(error.value)


def test_the_obstacle_registry_ships_three_types():
    assert list(OBSTACLE_TYPES) == ['box', 'cylinder', 'sphere']


def test_a_rigid_payloads_cables_are_measured_against_each_other():
    # two cables to a rigid body's ends, crossing in x-z at their middles in the planes
    # y = +-0.05: 0.1 m apart; from (-0.5, 0.05, 1) to the attach point (0.5, 0.05, 0) and
    # from (0.5, -0.05, 1) to (-0.5, -0.05, 0), the body level at the origin
    n = 2
    state = np.zeros(layout.attitude_slot(n) + layout.PAYLOAD_ATTITUDE)
    state[layout.uav_slot(0):layout.uav_slot(0) + 3] = (-0.5, 0.05, 1.0)
    state[layout.uav_slot(1):layout.uav_slot(1) + 3] = (0.5, -0.05, 1.0)
    for i in range(n):
        state[layout.uav_attitude_slot(n, i)] = 1.0
    state[layout.attitude_slot(n) + layout.PAYLOAD_QUATERNION] = 1.0
    constants = np.zeros((n, layout.UAV_COLUMNS))
    constants[0, layout.UAV_PAYLOAD_ATTACH:layout.UAV_PAYLOAD_ATTACH + 3] = (0.5, 0.05, 0.0)
    constants[1, layout.UAV_PAYLOAD_ATTACH:layout.UAV_PAYLOAD_ATTACH + 3] = (-0.5, -0.05, 0.0)
    least = np.zeros((layout.CLEARANCE_KINDS, layout.CLEARANCE_COLUMNS))
    least[:, layout.CLEARANCE_VALUE] = math.inf
    contact = np.full(layout.CLEARANCE_COLUMNS, -1.0)
    world = np.array([1.0, math.nan, 0.0, 0.0])  # checked, no ground
    assert not clearance.measure(world, np.zeros((0, layout.OBSTACLE_COLUMNS)), np.zeros(n),
                                 constants, state, 0.0, least, contact)
    row = least[layout.CLEARANCE_CABLE_CABLE]
    assert row[layout.CLEARANCE_VALUE] == pytest.approx(0.1, abs=1e-12)
    assert (row[layout.CLEARANCE_FIRST], row[layout.CLEARANCE_SECOND]) == (0.0, 1.0)
    assert math.isinf(least[layout.CLEARANCE_UAV_WORLD, layout.CLEARANCE_VALUE])  # no world
