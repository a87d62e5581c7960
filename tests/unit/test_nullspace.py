"""Null-space integrator (seed Eq. 2.71-2.72 with Eq. 2.57): the same accelerations as the
multiplier form, |g| held at rounding level by its projection, the same trajectories as the
Baumgarte DAE and the reduced model, and the Baumgarte study (seed Fig. 4.2-4.3)."""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from conftest import SCENARIOS
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.equilibrium import scenario_equilibrium
from multilift_sim.analysis.reduced_model import ReducedSingleLiftModel, rest_state
from multilift_sim.wind.gusts import Gust
from multilift_sim.dynamics import FormationModel, initial_state_single_lift
from multilift_sim.formation_params import StateLayout
from multilift_sim.formulations import make_formulation
from multilift_sim.nullspace import NullSpaceModel
from multilift_sim.start import initial_state
from multilift_tools.studies import study_main

SWING = str(SCENARIOS / 'single_lift_swing.yaml')
ALPHA0, BETA0 = math.radians(15.0), math.radians(25.0)          # seed Sec. 4.1 release


def load(name: str) -> scenario_io.Scenario:
    return scenario_io.load(str(SCENARIOS / f'{name}.yaml'))


def simulate(model, x0: np.ndarray, rotor_speeds, duration: float, dt: float) -> np.ndarray:
    steps = int(round(duration / dt))
    states = np.empty((steps + 1, x0.size))
    states[0] = x = x0
    for k in range(steps):
        x = model.step(k * dt, x, rotor_speeds, dt)
        states[k + 1] = x
    return states


@pytest.fixture(scope='module')
def swing():
    """single_lift_swing: params, release state, weight-balancing rotor speeds."""
    scenario = load('single_lift_swing')
    x0 = initial_state(scenario)
    return scenario, x0, list(scenario_equilibrium(scenario).rotor_speeds)


@pytest.mark.parametrize('name', ['single_lift_swing', 'twin_lift', 'multi_lift', 'v5'])
def test_accelerations_equal_the_multiplier_form(name):
    # Eq. 2.72 + 2.57 and Eq. 2.58 are the same equations: at any state (on the manifold,
    # moving, tilted, with drag and a gust on the payload) q_ddot and Lambda agree.
    scenario = load(name)
    rng = np.random.default_rng(7)
    x = initial_state(scenario)
    layout = StateLayout(scenario.n_uavs)
    payload = layout.payload_position(x)[:2]
    gust = Gust(center=tuple(payload + 0.5), direction=(0.0, 1.0, 0.0), gradient_distance=2.0,
                reference_speed=3.0)                            # ~2 m/s at the payload
    params = dataclasses.replace(scenario.formation_params(0.0, 0.0),
                                 payload_drag_coefficient=0.3, gusts=(gust,))
    nullspace, multiplier = NullSpaceModel(params), FormationModel(params)
    size = layout.n_coordinates
    for _ in range(3):
        state = x.copy()
        layout.coordinates(state)[:] += 0.05 * rng.standard_normal(size)
        layout.rates(state)[:] = rng.standard_normal(size)
        layout.set_uav_euler(state, layout.uav_euler(state)
                             + 0.05 * rng.standard_normal((scenario.n_uavs, 3)))  # tilted
        layout.uav_body_rates(state)[:] = rng.standard_normal((scenario.n_uavs, 3))
        state = nullspace.project(state)
        wrenches = np.column_stack((rng.uniform(20, 40, scenario.n_uavs),
                                    rng.uniform(-0.5, 0.5, (scenario.n_uavs, 3))))
        q_ddot, lam = nullspace.accelerations_from_wrenches(state, wrenches)
        q_ddot_ref, lam_ref = multiplier.accelerations_from_wrenches(state, wrenches)
        assert q_ddot == pytest.approx(q_ddot_ref, abs=1e-10 * np.abs(q_ddot_ref).max())
        assert lam == pytest.approx(lam_ref, rel=1e-10)


def test_projection_puts_a_state_on_the_manifold():
    scenario = load('twin_lift')
    model = NullSpaceModel(scenario.formation_params())
    x = initial_state(scenario)
    layout = model.layout
    size = layout.n_coordinates
    rng = np.random.default_rng(3)
    layout.coordinates(x)[:] += 1e-3 * rng.standard_normal(size)
    layout.rates(x)[:] = rng.standard_normal(size)
    layout.uav_body_rates(x)[:] = rng.standard_normal((2, 3))
    projected = model.project(x)
    g, g_dot = model.constraint_residuals(projected)
    assert np.abs(g).max() < 1e-12 and np.abs(g_dot).max() < 1e-12
    assert np.array_equal(layout.uav_attitudes(projected),          # only translations move
                          layout.uav_attitudes(x))


def test_projection_holds_the_residual_where_the_unstabilised_dae_drifts(swing):
    # seed Fig. 4.2 at a coarse 10 ms step: alpha_f = 0 drifts, the projected null-space
    # integrator stays at rounding level, and without its projection it IS alpha_f = 0.
    scenario, x0, speeds = swing
    projected = simulate(NullSpaceModel(scenario.formation_params()), x0, speeds, 20.0, 0.01)
    free = simulate(NullSpaceModel(scenario.formation_params(), projection=False), x0, speeds,
                    20.0, 0.01)
    unstabilised = FormationModel(scenario.formation_params(0.0, 0.0))
    baumgarte = simulate(unstabilised, x0, speeds, 20.0, 0.01)
    residual = np.array([unstabilised.constraint_residuals(x) for x in projected])
    assert np.abs(residual).max() < 1e-12                          # g and g_dot
    drift = abs(unstabilised.constraint_residuals(baumgarte[-1])[0][0])
    assert drift > 1e-6
    assert np.abs(free - baumgarte).max() < 1e-9                    # the same ODE


def test_agrees_with_the_reduced_model_and_the_baumgarte_dae(swing):
    scenario, x0, speeds = swing
    dt, duration = 0.002, 6.0
    nullspace = NullSpaceModel(scenario.formation_params())
    states = simulate(nullspace, x0, speeds, duration, dt)
    baumgarte = simulate(FormationModel(scenario.formation_params(20.0, 20.0)), x0, speeds,
                         duration, dt)
    uav = scenario.uavs[0]
    reduced = ReducedSingleLiftModel(uav.vehicle, scenario.payload.mass, uav.cable_length,
                                     scenario.simulation.gravity)
    t = np.arange(states.shape[0]) * dt
    reference = reduced.simulate(rest_state([0, 0, 0], [0, 0, 0], ALPHA0, BETA0), speeds[0],
                                 duration, t_eval=t).y.T
    uav_ref, payload_ref = reduced.to_world_positions(reference)
    layout = nullspace.layout
    uavs, payloads = layout.uav_positions(states)[:, 0], layout.payload_position(states)
    assert np.abs(uavs - uav_ref).max() < 1e-7
    assert np.abs(payloads - payload_ref).max() < 1e-7
    assert np.abs(states - baumgarte).max() < 1e-7
    assert np.abs(payloads - uavs).max() > 0.5                      # it does swing
    # energy with the thrust's work (level, constant thrust) is conserved
    thrust = nullspace.wrenches(speeds)[0, 0]
    invariant = np.array([nullspace.mechanical_energy(x) for x in states]) \
        - thrust * states[:, 2]
    swing_energy = (scenario.payload.mass * scenario.simulation.gravity * uav.cable_length
                    * (1 - math.cos(ALPHA0) * math.cos(BETA0)))
    assert np.ptp(invariant) < 1e-8 * swing_energy


def test_twin_lift_matches_the_baumgarte_dae():
    scenario = load('twin_lift')
    speeds = list(scenario_equilibrium(scenario).rotor_speeds)
    nullspace = NullSpaceModel(scenario.formation_params())
    x0 = initial_state(scenario)  # 15 deg swing release
    states = simulate(nullspace, x0, speeds, 5.0, 0.005)
    baumgarte = simulate(FormationModel(scenario.formation_params()), x0, speeds, 5.0, 0.005)
    assert np.abs(states - baumgarte).max() < 1e-6
    assert np.abs(states[-1, 12:15] - x0[12:15]).max() > 0.1          # the payload moved
    # at the projection's tolerance, 1e-14 l^2 (1e-12 m^2 for the 10.26 m cables)
    worst = max(np.abs(nullspace.constraint_residuals(x)[0]).max() for x in states)
    assert worst <= 1.01e-14 * scenario.uavs[0].cable_length ** 2


def test_static_tension_and_the_model_registry():
    scenario = load('single_lift_swing')
    params = scenario.formation_params()
    x = initial_state_single_lift([0.0, 0.0, 5.0], [0.0, 0.0, 0.3], 2.5, 0.0, 0.0)
    speeds = list(scenario_equilibrium(scenario).rotor_speeds)
    model = make_formulation('nullspace', params)
    assert isinstance(model, NullSpaceModel) and model.params is params
    assert model.cable_tension(0.0, x, speeds)[0] == pytest.approx(0.4 * 9.81, rel=1e-12)
    assert np.abs(model.accelerations(0.0, x, speeds)[0]).max() < 1e-12
    baumgarte = make_formulation('baumgarte', params)
    assert isinstance(baumgarte, FormationModel) and baumgarte.params is params
    with pytest.raises(ValueError, match='baumgarte, nullspace'):
        make_formulation('euler', params)


def test_study_main_writes_its_files(tmp_path, capsys):
    out = tmp_path / 'study'
    code = study_main(['baumgarte', '--out', str(out), '--duration', '2', '--scenario', SWING])
    printed = capsys.readouterr().out
    assert code == 0
    table = (out / 'baumgarte.md').read_text()
    assert 'dt = 10 ms' in table and table.strip() in printed
    rows = [line for line in table.splitlines() if line.startswith('| ')]
    assert len(rows) == 2 + 5                           # header, rule, one per integrator
    data = json.loads((out / 'baumgarte.json').read_text())
    by_name = {row['integrator']: row for row in data['rows']}
    assert set(by_name) == {'Baumgarte alpha_f = 0', 'Baumgarte alpha_f = 20',
                            'Baumgarte alpha_f = 100', 'null space + projection',
                            'null space, no projection'}
    assert by_name['null space + projection']['max_abs_g'] < 1e-12
    assert by_name['null space, no projection']['max_abs_g'] == pytest.approx(
        by_name['Baumgarte alpha_f = 0']['max_abs_g'], rel=1e-6)
    for row in data['rows']:
        assert 0 < row['max_payload_error'] < 1e-3                   # all track the reference
        assert row['wall_per_simulated_second'] > 0
    for name in ('baumgarte_constraint.png', 'baumgarte_position_error.png'):
        assert (out / name).read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


@pytest.mark.parametrize('argv', [['nosuch'], ['baumgarte', '--dt', '0'],
                                  ['baumgarte', '--scenario', str(SCENARIOS / 'twin_lift.yaml')],
                                  ['baumgarte', '--scenario', 'no_such_scenario']])
def test_study_main_bad_input_is_one_line_and_exit_2(tmp_path, capsys, argv):
    assert study_main(argv + ['--out', str(tmp_path / 'x')]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and err.startswith('error: ')


@pytest.mark.parametrize('name', ['twin_lift', 'circle3'])
def test_the_null_space_form_compiled_is_its_source_bit_for_bit(name):
    """physics.nullspace (written once, compiled; issue 19): the solve and the projection in
    numba and as the same source run by Python give the same bits, and the accelerations
    equal the multiplier form's without Baumgarte (Eq. 2.57 is g_ddot = 0) to rounding."""
    from multilift_sim import kernels
    from multilift_sim.physics.nullspace import nullspace_solve, project, translational_masses

    scenario = load(name)
    model = NullSpaceModel(scenario.formation_params())
    formation = model.formation
    x = initial_state(scenario)
    rng = np.random.default_rng(3)
    layout = model.layout
    layout.uav_velocities(x)[:] = rng.normal(0.0, 0.5, layout.uav_velocities(x).shape)
    layout.payload_velocity(x)[:] = rng.normal(0.0, 0.5, 3)
    wrenches = model.wrenches([np.full(u.vehicle.n_rotors, 1500.0) for u in scenario.uavs])
    results = []
    for function in (nullspace_solve, kernels.uncompiled(nullspace_solve)):
        acc, multipliers = np.empty(layout.size - layout.n_coordinates), np.empty(scenario.n_uavs)
        function(x, wrenches, formation._uavs, formation._gusts, formation._formation, acc,
                 multipliers)
        results.append((acc, multipliers))
    assert all(np.array_equal(a, b) for a, b in zip(*results))
    multiplier_form = FormationModel(dataclasses.replace(scenario.formation_params(),
                                                         baumgarte_alpha=0.0,
                                                         baumgarte_beta=0.0))
    expected_acc, expected_multipliers = multiplier_form.accelerations_from_wrenches(x, wrenches)
    acc, multipliers = results[0]
    assert np.abs(acc - expected_acc).max() < 1e-9 * np.abs(expected_acc).max()
    assert np.abs(multipliers - expected_multipliers).max() < 1e-9 * np.abs(
        expected_multipliers).max()
    # the projection: from positions 1 mm off, onto |g| <= 1e-14 l^2, the same bits both ways
    masses = translational_masses(formation._uavs, formation._formation)
    off = x.copy()
    layout.payload_position(off)[:] += 1e-3
    projected = []
    for function in (project, kernels.uncompiled(project)):
        state = off.copy()
        function(state, formation._uavs, masses, 1e-14, 4)
        projected.append(state)
    assert np.array_equal(*projected)
    g, g_dot = model.constraint_residuals(projected[0])
    assert np.abs(g).max() <= 1e-14 * model.cable_lengths.max() ** 2
    assert np.abs(g_dot).max() < 1e-12


@pytest.mark.parametrize('name', ['single_lift_swing', 'twin_lift'])
def test_a_control_period_projects_after_every_step(name):
    """The one compiled period (physics.formation_dae.integrate_period, through the actuators)
    projects after each RK4 step in the null-space form: NullSpaceModel.integrate equals its
    steps taken one by one (RK4, then physics.nullspace.project), to the bit."""
    scenario = load(name)
    model = NullSpaceModel(scenario.formation_params())
    x = initial_state(scenario)
    speeds = [np.full(u.vehicle.n_rotors, 1500.0) for u in scenario.uavs]
    period = model.integrate(x, speeds, 0.005, 4)
    state = x
    for _ in range(4):
        state = model.step(0.0, state, speeds, 0.005)
    assert np.array_equal(period.state, state)
    assert np.array_equal(period.cable_tension, model.cable_tension(0.0, x, speeds))
    g, _ = model.constraint_residuals(period.state)
    assert np.abs(g).max() <= 1e-14 * max(u.cable_length for u in scenario.uavs) ** 2
    # without the projection the same steps drift off the manifold
    free = NullSpaceModel(scenario.formation_params(), projection=False)
    assert not np.array_equal(free.integrate(x, speeds, 0.005, 4).state, period.state)


def test_the_engine_flies_the_null_space_form_as_the_simulator_does():
    """No fallback: `simulation.integrator: nullspace` flies in the engine (sweeps, learning)
    with the simulator node's bits, |g| held at rounding."""
    from multilift_control.engine import Engine
    from multilift_control.headless import run_headless
    base = load('twin_lift').with_duration(3.0)
    scenario = dataclasses.replace(base, simulation=dataclasses.replace(
        base.simulation, integrator='nullspace'))
    engine = Engine(scenario)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert engine.finished[0]
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert engine.summary(0)['sim']['max_abs_constraint'] < 1e-10
    baumgarte = Engine(base)
    baumgarte.step(10 ** 6)
    assert np.abs(baumgarte.state[0] - engine.state[0]).max() > 0.0  # another formulation
    assert np.abs(baumgarte.state[0] - engine.state[0]).max() < 1e-3  # of the same DAE
