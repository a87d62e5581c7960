"""Modal analysis with cables held off the UAVs' centres (uavs[i].attach_point a_i, body FLU;
multilift_sim.analysis, docs/rigid_payload.md), held against physics worked out here: the
equilibrium rests in the full DAE with the rotors cancelling the cable's moment about each
centre; a_i = 0 written out is the seed's case; G is the derivative of the constraint; a
payload on a held UAV swings as a plain pendulum from the attach point; the full DAE started
along a free formation's swing keeps the linear period, and along its (open-loop) unstable
mode grows as cosh(lambda t)."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.coordinates import (displaced_state, formation_jacobian,
                                                seed_coordinates_of,
                                                formation_residuals)
from multilift_sim.analysis.equilibrium import scenario_equilibrium, static_equilibrium
from multilift_sim.analysis.modal import modal_analysis, mode_state, scenario_modal_analysis
from multilift_sim.analysis.modes import motion_shares
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.start import formation_start

G = 9.81
BELOW = (0.0, 0.0, -0.1)          # a_i [m], body FLU: 10 cm under the centre of mass


def attached(name: str, points, tmp_path) -> scenario_io.Scenario:
    """Scenario `name` with uavs[i].attach_point = points[i], through a YAML file."""
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    for uav, point in zip(data['uavs'], points):
        uav['attach_point'] = list(point)
    path = tmp_path / f'{name}_attached.yaml'
    path.write_text(yaml.safe_dump(data))
    return scenario_io.load(str(path))


def _twin(half: float, length: float, attach, uav_mass: float | None = None):
    """Two twin-lift UAVs at (+-half, 0) holding a 0.8 kg point payload at the origin on cables
    of `length` from their attach points `attach` (or their centres: None): (params, eq)."""
    vehicle = scenario_io.load(str(SCENARIOS / 'twin_lift.yaml')).uavs[0].vehicle
    params = FormationParams(uavs=(vehicle, vehicle), cable_lengths=(length, length),
                             payload_mass=0.8, payload_drag_coefficient=0.0,
                             baumgarte_alpha=0.0, baumgarte_beta=0.0, gravity=G,
                             uav_attach_points=None if attach is None else (attach, attach))
    lift = math.sqrt(length ** 2 - half ** 2) - (0.0 if attach is None else attach[2])
    return params, static_equilibrium(params, [[half, 0.0, lift], [-half, 0.0, lift]],
                                       [0.0, 0.0, 0.0])


# ------------------------------------------------------------------------ the equilibrium
@pytest.mark.parametrize('name,points', [('twin_lift', [BELOW, BELOW]),
                                         ('single_lift_swing', [(0.05, 0.02, -0.1)])])
def test_the_equilibrium_rests_and_the_rotors_cancel_the_cable_s_moment(name, points,
                                                                        tmp_path):
    """1 s of the full DAE (Baumgarte 20) under the equilibrium's rotor speeds: nothing moves
    (1e-9). Written out here per UAV: the cable starts where the simulator starts it
    (formation_start: r_i + Rz(psi) a_i of the level UAV), thrust + pull = weight, and the
    rotors' torque tau = -a_i x R_i^T (2 lambda_i d_i) (the pull at s_i turns the UAV by
    a_i x R_i^T F about its centre), not zero."""
    scenario = attached(name, points, tmp_path)
    eq = scenario_equilibrium(scenario)
    params = dataclasses.replace(scenario.formation_params(), gusts=())
    model = FormationModel(params)
    layout = model.layout
    x = eq.state
    g, g_dot = model.constraint_residuals(x)
    assert np.abs(g).max() < 1e-11 and np.abs(g_dot).max() == 0.0
    acc, multipliers = model.accelerations(0.0, x, list(eq.rotor_speeds))
    assert np.abs(acc).max() < 1e-10
    assert eq.multipliers == pytest.approx(multipliers, rel=1e-9)
    uavs, euler = layout.uav_positions(x), layout.uav_euler(x)
    payload = layout.payload_position(x)
    if scenario.n_uavs > 1:
        starts, _ = formation_start(scenario)
    else:
        starts = np.array([scenario.uavs[0].position])
    for i, uav in enumerate(params.uavs):
        a = np.array(points[i])
        rotation = rotation_matrix(euler[i])
        yaw = rotation_matrix([0.0, 0.0, scenario.uavs[i].yaw])
        end = uavs[i] + rotation @ a                                   # the cable's upper end
        assert np.abs(end - (starts[i] + yaw @ a)).max() < 1e-12
        pull = 2.0 * multipliers[i] * (payload - end)
        wrench = uav.allocator().wrench(eq.rotor_speeds[i])
        assert np.abs(wrench - eq.wrenches[i]).max() < 1e-12
        balance = wrench[0] * rotation[:, 2] + pull - [0.0, 0.0, uav.mass * G]
        assert np.abs(balance).max() < 1e-9 * uav.mass * G
        moment = np.cross(a, rotation.T @ pull)                      # the cable's, body FLU
        assert np.linalg.norm(moment) > 1e-3                          # N m: something to hold
        assert np.abs(wrench[1:] + moment).max() < 1e-9 * np.linalg.norm(moment)
        assert euler[i, 2] == pytest.approx(scenario.uavs[i].yaw, abs=1e-15)
    if scenario.n_uavs == 1:                  # a vertical cable: the UAV level, centre kept
        assert np.array_equal(euler[0, :2], [0.0, 0.0])
        assert np.abs(uavs[0] - scenario.uavs[0].position).max() < 1e-15
    else:                                     # slanted cables: tilted about s_i, centre moved
        assert np.abs(euler[:, :2]).max() > 0.01
    start = x.copy()
    for k in range(200):
        x = model.step(k * 0.005, x, list(eq.rotor_speeds), 0.005)
    assert np.abs(layout.uav_positions(x) - layout.uav_positions(start)).max() < 1e-9
    assert np.abs(layout.payload_position(x) - layout.payload_position(start)).max() < 1e-9
    assert np.abs(x - start).max() < 1e-9


def test_attach_points_written_as_zero_are_the_seed_s_case():
    """uav_attach_points all (0, 0, 0): the same equilibrium and eigenvalues (1e-9) as none."""
    scenario = scenario_io.load(str(SCENARIOS / 'twin_lift.yaml'))
    seed = scenario.formation_params(0.0, 0.0)
    zero = dataclasses.replace(seed, uav_attach_points=((0.0, 0.0, 0.0),) * 2)
    base = scenario_modal_analysis(scenario)
    eq = scenario_equilibrium(scenario)
    eq_zero = static_equilibrium(zero, *formation_start(scenario),
                                 [u.yaw for u in scenario.uavs])
    assert np.abs(eq_zero.state - eq.state).max() < 1e-12
    assert np.abs(eq_zero.wrenches - eq.wrenches).max() < 1e-12
    analysis = modal_analysis(zero, eq_zero)
    assert analysis.kinds == base.kinds
    scale = np.abs(base.eigenvalues).max()
    assert np.abs(analysis.eigenvalues - base.eigenvalues).max() < 1e-9 * scale
    assert analysis.pendulum_periods == pytest.approx(base.pendulum_periods, rel=1e-9)


# --------------------------------------------------------------------------------- G
@pytest.mark.parametrize('rigid', [False, True])
def test_g_is_the_derivative_of_the_constraint_with_the_uavs_tilted(rigid):
    """G against central differences of g (the DAE's own residuals too) at UAV attitudes far
    from level, a_i off every axis; a rigid payload with its attach points b_i as well."""
    params, eq = _twin(2.0, 10.26, BELOW)
    params = dataclasses.replace(params, uav_attach_points=((0.05, -0.08, -0.1),
                                                             (-0.03, 0.1, 0.12)))
    n = 2
    layout = StateLayout(n, rigid)
    euler = [[0.2, -0.3, 0.7], [-0.25, 0.15, -1.1]]
    uavs = [[2.0, 0.1, 9.9], [-2.1, -0.2, 9.8]]
    if rigid:
        params = dataclasses.replace(params, payload_inertia=(0.1, 0.2, 0.3),
                                     payload_attach_points=((0.3, 0.1, 0.2),
                                                            (-0.3, -0.1, 0.2)))
        x = layout.pack(uavs, euler, [0.1, -0.2, 0.3],
                        payload_quaternion=[1.0, 0.0, 0.0, 0.0])
    else:
        x = layout.pack(uavs, euler, [0.1, -0.2, 0.3])
    jacobian = formation_jacobian(params, x)
    size = jacobian.shape[1]
    assert size == 6 * n + (6 if rigid else 3)
    own = np.concatenate((jacobian[0, 3:6], jacobian[1, 9:12]))   # each UAV's Euler columns
    assert np.abs(own).min() > 1e-3
    h = 1e-5
    numeric = np.empty_like(jacobian)
    dae = np.empty_like(jacobian)
    model = FormationModel(params)
    for k in range(size):
        step = np.zeros(size)      # q_f's coordinate k (the rotation vector: turn the body)
        step[k] = h
        plus = displaced_state(layout, x, step, np.zeros(size))
        minus = displaced_state(layout, x, -step, np.zeros(size))
        numeric[:, k] = (formation_residuals(params, plus)
                         - formation_residuals(params, minus)) / (2 * h)
        dae[:, k] = (model.constraint_residuals(plus)[0]
                     - model.constraint_residuals(minus)[0]) / (2 * h)
    scale = np.abs(jacobian).max()
    assert np.abs(jacobian - numeric).max() < 1e-7 * scale
    assert np.abs(jacobian - dae).max() < 1e-7 * scale
    assert np.abs(formation_residuals(params, x) - model.constraint_residuals(x)[0]).max() \
        < 1e-12


# ---------------------------------------------------------------------- the pendulums
def test_a_held_uav_s_payload_swings_from_the_attach_point():
    """One UAV held (hold_uavs), its cable 10 cm below its centre: the attach point is fixed,
    the payload a plain pendulum of the cable's length, 2 pi sqrt(l / g) in x and y (1e-6)."""
    scenario = scenario_io.load(str(SCENARIOS / 'single_lift_swing.yaml'))
    length = scenario.uavs[0].cable_length
    params = dataclasses.replace(scenario.formation_params(0.0, 0.0),
                                 uav_attach_points=(BELOW,))
    eq = static_equilibrium(params, [[0.0, 0.0, 0.0]],
                            [0.0, 0.0, -0.1 - length])
    held = modal_analysis(params, eq, hold_uavs=True)
    assert len(held.pendulum_modes) == 2
    assert held.pendulum_periods == pytest.approx([2 * math.pi * math.sqrt(length / G)] * 2,
                                                  rel=1e-6)
    # the same cable from the centre (no attach point) would be 0.1 m longer: a 2 % slower
    # pendulum, so the test tells the two apart
    assert 2 * math.pi * math.sqrt((length + 0.1) / G) / held.pendulum_periods[0] > 1.019


@pytest.fixture(scope='module')
def twin():
    params, eq = _twin(2.0, 10.26, BELOW)
    return params, eq, modal_analysis(params, eq)


def _simulate(analysis, params, mode, amplitude, periods, value):
    """The full DAE (Baumgarte 20) from mode_state: the projection on the mode's shape per
    step of value / 200 [s] (amplitude 1 at the start)."""
    model = FormationModel(dataclasses.replace(params, baumgarte_alpha=20.0,
                                               baumgarte_beta=20.0))
    x = mode_state(analysis, mode, amplitude)
    assert np.abs(model.constraint_residuals(x)[0]).max() < 1e-12
    shape = analysis.shapes[mode].real
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    rest = seed_coordinates_of(layout, analysis.equilibrium.state)
    dt = value / 200
    out = [1.0]
    for k in range(200 * periods):
        x = model.step(k * dt, x, list(analysis.equilibrium.rotor_speeds), dt)
        out.append((seed_coordinates_of(layout, x) - rest) @ shape[:rest.size]
                   / (amplitude * shape @ shape))
    return np.arange(len(out)) * dt, np.array(out)


def test_free_uavs_swing_at_the_linear_period(twin):
    """A twin-lift (UAVs 4 m apart, 10.26 m cables, a_i = (0, 0, -0.1)) free under its
    equilibrium's rotors: the swing across the UAVs' line (swing y with the UAVs) has the
    period the analysis predicts in the full DAE, started 1 mm along it (1e-3; 4 periods).
    The amplitude is small because the open-loop formation has unstable modes (below) that
    the swing's second-order motion feeds."""
    params, _, analysis = twin
    mode = max(analysis.pendulum_modes, key=lambda k: motion_shares(analysis, k)['swing y'])
    assert motion_shares(analysis, mode)['swing y'] > 0.2
    period = 2 * math.pi / analysis.eigenvalues[mode].imag
    assert 4.9 < period < 5.2
    t, amplitude = _simulate(analysis, params, mode, 1e-3, 4, period)
    k = np.nonzero(np.sign(amplitude[:-1]) != np.sign(amplitude[1:]))[0]
    crossings = t[k] - amplitude[k] * (t[1] - t[0]) / (amplitude[k + 1] - amplitude[k])
    assert len(crossings) >= 7
    measured = 2.0 * (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    assert measured == pytest.approx(period, rel=1e-3)
    assert np.abs(amplitude).max() < 1.05
    # held at the centres instead, the same formation swings elsewhere: the test can tell
    centred = modal_analysis(*_twin(2.0, 10.26, None))
    assert np.abs(centred.pendulum_periods / period - 1.0).min() > 0.01


def test_the_open_loop_instability_is_the_dae_s(twin):
    """Held below their centres under fixed rotor speeds, the UAVs' tilt and the cables'
    slant feed each other: the analysis finds a real pair +-lambda; the full DAE started
    1e-6 along it grows as cosh(lambda t) (2 %, 3 s)."""
    params, _, analysis = twin
    unstable = [k for k in analysis.indices('unstable') if abs(analysis.eigenvalues[k]) > 0.1]
    assert unstable
    mode = max(unstable, key=lambda k: analysis.eigenvalues[k].real)
    rate = analysis.eigenvalues[mode].real
    assert 0.5 < rate < 1.0 and analysis.eigenvalues[mode].imag == 0.0
    t, amplitude = _simulate(analysis, params, mode, 1e-6, 1, 3.0)
    assert amplitude[-1] == pytest.approx(math.cosh(rate * t[-1]), rel=2e-2)
    assert amplitude[100] == pytest.approx(math.cosh(rate * t[100]), rel=2e-2)
