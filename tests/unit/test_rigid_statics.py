"""A rigid body's statics in the reorganising law (issue 35, multilift_control.laws.rigid_statics)
against mechanics solved apart: Eq. 2.73's equilibrium of multilift_sim's analysis
(`static_equilibrium`, `multilift loads` at hover) at the pose the law finds, the pose of least
potential energy (`multilift_sim.rigid_hang`, SLSQP), and a symmetric beam's closed form
m g / (2 cos theta), also swung by a sideways apparent gravity; the laws compiled against their
uncompiled run."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from multilift_control.controllers.followers import thrust_margin
from multilift_control.laws import reorganize
from multilift_control.laws import rigid_statics as laws
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.equilibrium import static_equilibrium
from multilift_sim.analysis.loads import hover_loads
from multilift_sim.rigid_hang import hanging_body
from multilift_sim.start import formation_start
from test_compiled_laws import Checker

G = 9.81
# UAVs 2 and 3 moved off v3_box_mixed's V: the box tilts and UAV 3's cable carries little
MOVED = np.array([[0.0, 0.0, 0.0], [-5.149, 1.968, 0.0], [-2.935, -0.625, 0.0]])


def _quaternion(rotation):
    """(w, x, y, z) of a rotation matrix whose angle is below 180 degrees."""
    w = math.sqrt(1.0 + np.trace(rotation)) / 2.0
    return np.array([w, (rotation[2, 1] - rotation[1, 2]) / (4 * w),
                     (rotation[0, 2] - rotation[2, 0]) / (4 * w),
                     (rotation[1, 0] - rotation[0, 1]) / (4 * w)])


def _box():
    """v3_box_mixed at its geometry's places and its follower's constants."""
    s = _table(scenario_io.load('v3_box_mixed'))
    constants, _, _, _ = thrust_margin.arrays(s, 1)
    return s, constants


def _attach(s):
    return np.array(s.payload.attach_points, dtype=float)


def test_the_law_s_box_is_at_rest_by_eq_2_73_and_its_margins_are_the_equilibrium_s():
    """At MOVED the law's pose is an equilibrium of the rigid body's force and moment rows
    (`static_equilibrium` refuses a pose whose cables leave 1e-9 of the weight's moment), whose
    least-norm tensions and rotor thrusts give the law's tensions and margins."""
    s, constants = _box()
    lengths = np.array([u.cable_length for u in s.uavs])
    position, rotation, multipliers, found = laws.hang_body(
        MOVED, lengths, _attach(s), np.array([0.0, 0.0, s.payload.mass * G]))
    assert found
    equilibrium = static_equilibrium(s.formation_params(0.0, 0.0), MOVED, position,
                                     payload_quaternion=_quaternion(rotation))
    tensions, units, found = reorganize.cable_statics(constants, MOVED, np.array([0, 0, G]))
    assert found
    np.testing.assert_allclose(tensions, equilibrium.tensions, rtol=1e-8)
    largest = np.array([u.vehicle.max_thrust for u in s.uavs])
    margins = reorganize.static_margins(constants, MOVED, np.array([0.0, 0.0, G]))
    np.testing.assert_allclose(margins, 1.0 - equilibrium.wrenches[:, 0] / largest, atol=1e-9)
    # the box tilts (its top points lie 0.3 m above its centre) and UAV 3 carries far less
    assert math.degrees(math.acos(rotation[2, 2])) > 10.0
    assert tensions[2] < 0.5 * tensions[:2].min()


def test_the_law_s_pose_is_the_pose_of_least_potential_energy():
    s, _ = _box()
    lengths = np.array([u.cable_length for u in s.uavs])
    for down in (np.array([0.0, 0.0, -1.0]), np.array([0.1, -0.05, -1.0]) / math.sqrt(1.0125)):
        position, rotation, _, found = laws.hang_body(MOVED, lengths, _attach(s),
                                                      -s.payload.mass * G * down)
        lowest, quaternion = hanging_body(MOVED, lengths, _attach(s), down)
        assert found
        np.testing.assert_allclose(position, lowest, atol=1e-9)
        np.testing.assert_allclose(_quaternion(rotation), quaternion, atol=1e-9)


def test_at_hover_the_law_gives_multilift_loads():
    """At v3_box_mixed's geometry (the box level, the shares even) and at its start places
    (tilted): the law's tensions and margins are `multilift loads`' at hover."""
    for s in (_table(scenario_io.load('v3_box_mixed')), scenario_io.load('v3_box_mixed')):
        constants, _, _, _ = thrust_margin.arrays(s, 1)
        uavs, _ = formation_start(s)
        hover = hover_loads(s)
        tensions, _, found = reorganize.hover_statics(constants, uavs - uavs[0])
        assert found
        np.testing.assert_allclose(tensions, hover.tensions, rtol=1e-8)
        margins = reorganize.static_margins(constants, uavs - uavs[0], np.array([0, 0, G]))
        np.testing.assert_allclose(margins, hover.margins, atol=1e-9)


def _table(s):
    """The scenario at its geometry's places (Table 3.1's V), start_places left out."""
    return dataclasses.replace(s, formation=dataclasses.replace(s.formation, start_places=()))


def test_a_symmetric_beam_s_cables_carry_m_g_over_two_cos_theta():
    """Two UAVs 5 m apart, a 3 m beam by its ends on 4 m cables: each cable leans out by
    sin theta = 1 / 4 and carries m g / (2 cos theta). A sideways apparent gravity swings the
    beam about the UAVs' line as one pendulum: |g_eff| in place of g, the beam below the line
    along g_eff."""
    m_p, length = 1.5, 4.0
    uavs = np.array([[2.5, 0.0, 0.0], [-2.5, 0.0, 0.0]])
    attach = np.array([[1.5, 0.0, 0.0], [-1.5, 0.0, 0.0]])
    cos_theta = math.sqrt(1.0 - (1.0 / length) ** 2)
    for effective in (np.array([0.0, 0.0, G]), np.array([0.0, 1.2, G])):
        size = float(np.linalg.norm(effective))
        position, rotation, multipliers, found = laws.hang_body(
            uavs, np.full(2, length), attach, m_p * effective)
        assert found
        gaps = uavs - position - attach @ rotation.T
        tensions = multipliers * np.linalg.norm(gaps, axis=1)
        np.testing.assert_allclose(tensions, m_p * size / (2.0 * cos_theta), rtol=1e-9)
        np.testing.assert_allclose(position, -length * cos_theta * effective / size, atol=1e-9)


def test_a_cable_that_cannot_reach_is_no_hang():
    uavs = np.array([[20.0, 0.0, 0.0], [-20.0, 0.0, 0.0]])
    attach = np.array([[1.5, 0.0, 0.0], [-1.5, 0.0, 0.0]])
    *_, found = laws.hang_body(uavs, np.full(2, 4.0), attach, np.array([0.0, 0.0, 15.0]))
    assert not found


def test_the_rigid_statics_compiled_equal_their_uncompiled_run():
    check = Checker()
    s, constants = _box()
    lengths = np.array([u.cable_length for u in s.uavs])
    check(laws.hang_body, MOVED, lengths, _attach(s), np.array([0.3, -0.2, 7.8]))
    check(laws.body_tensions, constants, MOVED, np.array([0.3, -0.2, G]))
    check(reorganize.cable_statics, constants, MOVED, np.array([0.3, -0.2, G]))
    check(reorganize.static_margins, constants, MOVED, np.array([0.3, -0.2, G]))
    check(laws._level_start, MOVED, lengths, _attach(s))
    jacobian = np.random.default_rng(5).normal(size=(9, 9))
    check(laws._solved, jacobian, np.arange(9.0))
    jacobian[:, 4] = 0.0  # a null direction: the SVD's minimum norm
    check(laws._solved, jacobian, np.arange(9.0))
    check(laws._turned, np.eye(3), np.array([0.1, -0.2, 0.05]))
    check(laws._product, np.eye(3) * 2.0, np.arange(9.0).reshape(3, 3))
    check(laws._applied, np.arange(9.0).reshape(3, 3), np.array([1.0, -2.0, 0.5]))
    check(laws._cross, np.array([1.0, 2.0, 3.0]), np.array([-1.0, 0.5, 2.0]))


def test_the_hover_feedforward_of_a_rigid_body_is_its_cable_s_vertical_pull():
    s, constants = _box()
    tensions, units, found = reorganize.cable_statics(constants, MOVED, np.array([0.0, 0.0, G]))
    assert found
    for i in range(3):
        assert reorganize.hover_mass(constants, tensions, units, found, i) == pytest.approx(
            s.uavs[i].vehicle.mass + tensions[i] * units[i, 2] / G, rel=1e-12)
    # the vertical pulls carry the box's weight
    assert sum(tensions * units[:, 2]) == pytest.approx(s.payload.mass * G, rel=1e-9)


def test_the_newton_step_solves_regular_and_singular_systems():
    """Elimination on a regular system equals numpy's solve; with a zero column (a beam's spin)
    it falls back to the minimum-norm least squares, numpy's lstsq."""
    rng = np.random.default_rng(7)
    matrix = rng.normal(size=(9, 9))
    rhs = rng.normal(size=9)
    np.testing.assert_allclose(laws._solved(matrix, rhs), np.linalg.solve(matrix, rhs),
                               rtol=1e-10, atol=1e-12)
    matrix[:, 4] = 0.0
    matrix[4, :] = 0.0
    rhs[4] = 0.0
    np.testing.assert_allclose(laws._solved(matrix, rhs),
                               np.linalg.lstsq(matrix, rhs, rcond=None)[0], atol=1e-10)
