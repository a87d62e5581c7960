"""Cable-force allocation for a rigid body (issue 35 item 3, `formation.reorganize: cable_forces`,
multilift_control.laws.rigid_allocation) against mechanics solved apart: the wrench the forces
give the level body (summed here with np.cross), the least effort by scipy's SLSQP, a box's
diagonal shares in closed form, Eq. 2.73's equilibrium of multilift_sim's analysis with the
UAVs where the law puts them; compiled against uncompiled; v3_box_mixed allocated flies."""
from __future__ import annotations

import numpy as np
import pytest
import yaml
from scipy.optimize import minimize

from conftest import SCENARIOS
from multilift_control.controllers.followers import cable_forces
from multilift_control.headless import fly
from multilift_control.laws import reorganize
from multilift_control.laws import rigid_allocation as laws
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.equilibrium import static_equilibrium
from multilift_sim.scenario import ScenarioError
from test_compiled_laws import Checker

G = 9.81


def _allocated(name='v3_box_mixed', **uav3):
    """Scenario `name` with `reorganize: cable_forces` (start_places kept where it has them),
    UAV 3's keys `uav3` changed, and its follower's constants."""
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['formation']['reorganize'] = 'cable_forces'
    data['uavs'][2].update(uav3)
    s = scenario_io.loads(yaml.safe_dump(data))
    return s, cable_forces.arrays(s, 1)[0]


def _box_mixed():
    """box_lift's four UAVs (3 m x 2 m about the 1.0 x 0.6 x 0.4 m box's top corners, 4 m
    cables), UAV 3's rotors to 2050 rad/s, with `cable_forces` as a three-UAV formation would
    fly it (its constants built the same way; the parse allocates three UAVs only)."""
    data = yaml.safe_load((SCENARIOS / 'box_lift.yaml').read_text())
    data['uavs'][2]['rotor_speed_max'] = 2050.0
    data['formation']['reorganize'] = 'thrust_margin'
    s = scenario_io.loads(yaml.safe_dump(data))
    return s, cable_forces.arrays(s, 1)[0]


def _spare(s, effective):
    return np.array([u.vehicle.max_thrust - u.vehicle.mass * np.linalg.norm(effective)
                     for u in s.uavs])


@pytest.mark.parametrize('effective', [np.array([0.0, 0.0, G]), np.array([0.8, -0.5, G + 0.3])])
def test_the_forces_give_the_level_body_its_apparent_weight_and_no_torque(effective):
    for s, constants in (_allocated(), _box_mixed()):
        forces = laws.body_cable_forces(constants, effective)
        attach = np.array(s.payload.attach_points)
        np.testing.assert_allclose(forces.sum(axis=0), s.payload.mass * effective, atol=1e-9)
        np.testing.assert_allclose(np.cross(attach, forces).sum(axis=0), 0.0, atol=1e-9)
        null = laws.internal_forces(laws.wrench_rows(attach))
        np.testing.assert_allclose(laws.wrench_rows(attach) @ null, 0.0, atol=1e-12)
        np.testing.assert_allclose(null.T @ null, np.eye(null.shape[1]), atol=1e-12)


def test_the_least_effort_forces_are_the_weighted_minimum():
    """Against SLSQP: min sum |f_i|^2 / c_i subject to the wrench, c_i each UAV's spare
    thrust (UAV 3's the least)."""
    s, constants = _box_mixed()
    effective = np.array([0.3, 0.0, G])
    attach = np.array(s.payload.attach_points)
    rows = laws.wrench_rows(attach)
    wrench = np.concatenate((s.payload.mass * effective, np.zeros(3)))
    spare = _spare(s, effective)
    forces = laws.least_effort_forces(rows, wrench, spare)
    weights = np.repeat(1.0 / spare, 3)
    best = minimize(lambda f: float(f @ (weights * f)), np.zeros(12), method='SLSQP',
                    jac=lambda f: 2.0 * weights * f,
                    constraints=[{'type': 'eq', 'fun': lambda f: rows @ f - wrench,
                                  'jac': lambda f: rows}], options={'ftol': 1e-14})
    np.testing.assert_allclose(forces, best.x, atol=1e-6)


def test_a_box_s_diagonals_share_by_their_spare_thrust():
    """The box's corners lie 0.2 m above its centre at (+-0.5, +-0.3): its moment rows leave
    the diagonals' split free, V_1 = V_3 = a, V_2 = V_4 = W / 2 - a, and the least
    a^2 (1/c_1 + 1/c_3) + (W/2 - a)^2 (1/c_2 + 1/c_4) is at a = W/2 (1/c_2 + 1/c_4) / sum 1/c_i:
    the weak UAV 3 and the leader across from it carry less than the even W / 4."""
    s, constants = _box_mixed()
    effective = np.array([0.0, 0.0, G])
    inverse = 1.0 / _spare(s, effective)
    weight = s.payload.mass * G
    a = weight / 2.0 * (inverse[1] + inverse[3]) / inverse.sum()
    forces = laws.body_cable_forces(constants, effective)
    np.testing.assert_allclose(forces[:, 2], [a, weight / 2 - a, a, weight / 2 - a], rtol=1e-9)
    assert a < 0.9 * weight / 4.0


def test_where_the_law_puts_the_uavs_the_level_body_is_at_rest_with_those_tensions():
    """Eq. 2.73's equilibrium (analysis.equilibrium, which refuses a force or moment left
    over) of the level body with the UAVs at b_i + l_i f_i / |f_i|: the three top points'
    tensions are determined and are the law's (the law's own rigid statics find them too);
    the box's four are not (its diagonals' split is free along these cables: the least-norm
    equilibrium shares evenly), but the allocated tensions hold it at rest as well."""
    effective = np.array([0.0, 0.0, G])
    for (s, constants), determined in ((_allocated(), True), (_box_mixed(), False)):
        forces = laws.body_cable_forces(constants, effective)
        places = laws.body_allocated_places(constants, effective)
        attach = np.array(s.payload.attach_points)
        lengths = np.array([u.cable_length for u in s.uavs])
        body = attach[0] + lengths[0] * forces[0] / np.linalg.norm(forces[0])
        # the body's centre at -body from the leader, level (the default attitude)
        equilibrium = static_equilibrium(s.formation_params(0.0, 0.0), places, -body)
        tensions = np.linalg.norm(forces, axis=1)
        units = forces / tensions[:, None]
        np.testing.assert_allclose(units.T @ equilibrium.tensions, s.payload.mass * effective,
                                   atol=1e-9)
        np.testing.assert_allclose(units.T @ tensions, s.payload.mass * effective, atol=1e-9)
        if determined:
            np.testing.assert_allclose(equilibrium.tensions, tensions, rtol=1e-9)
            statics, _, found = reorganize.cable_statics(constants, places, effective)
            assert found
            np.testing.assert_allclose(statics, tensions, rtol=1e-7)
        else:
            np.testing.assert_allclose(equilibrium.tensions, s.payload.mass * G / 4.0
                                       / units[0, 2], rtol=1e-9)


def test_the_allocation_compiled_equals_its_uncompiled_run():
    check = Checker()
    s, constants = _box_mixed()
    effective = np.array([0.2, -0.1, G])
    attach = np.array(s.payload.attach_points)
    rows = laws.wrench_rows(attach)
    check(laws.wrench_rows, attach)
    check(laws.least_effort_forces, rows, np.array([0.0, 0.0, 19.6, 0.0, 0.0, 0.0]),
          _spare(s, effective))
    check(laws.internal_forces, rows)
    check(laws.body_cable_forces, constants, effective)
    check(laws.body_allocated_places, constants, effective)


def test_v3_box_mixed_allocated_flies_its_mission_level():
    """cable_forces on v3_box_mixed flies the whole mission (Algorithm 1 does not stop it):
    held level, the box's three top points fix its vertical shares, so the allocation keeps
    the V even and UAV 3 is left with the fixed V's thin margin (docs/loads.md)."""
    s, constants = _allocated()
    effective = np.array([0.0, 0.0, G])
    places = laws.body_allocated_places(constants, effective)
    margins = reorganize.static_margins(constants, places, effective)
    assert margins[2] < 0.02 and margins[0] == pytest.approx(margins[1], abs=1e-9)
    summary = fly(s).summary()
    assert summary['sim']['simulated_time'] == pytest.approx(s.simulation.duration)


def test_cable_forces_refuses_a_rigid_body_held_off_the_uavs_centres():
    data = yaml.safe_load((SCENARIOS / 'v3_box_mixed.yaml').read_text())
    data['formation']['reorganize'] = 'cable_forces'
    del data['formation']['start_places']
    data['uavs'][0]['attach_point'] = [0.0, 0.0, -0.1]
    with pytest.raises(ScenarioError) as error:
        scenario_io.loads(yaml.safe_dump(data))
    assert "'cable_forces' allocates a point payload's cables or a rigid body's" in str(
        error.value) and '\n' not in str(error.value)
