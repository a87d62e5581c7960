"""Modal analysis (seed Sec. 2.8, Eq. 2.71-2.73): the static equilibrium really is one, the
single-lift's pendulum modes against the seed and against the independently linearised reduced
model, the choice of basis, the twin-lift's periods against a simulated swing of the full DAE,
and `multilift modal`."""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from conftest import SCENARIOS
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.coordinates import coordinate_names, seed_coordinates_of
from multilift_sim.analysis.equilibrium import scenario_equilibrium
from multilift_sim.analysis.modal import (default_dependent_coordinates, elimination_basis,
                                          modal_analysis, mode_state, scenario_modal_analysis)
from multilift_sim.analysis.reduced_model import ReducedSingleLiftModel, rest_state
from multilift_sim.constraints import constraint_jacobian
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import StateLayout
from multilift_sim.kinematics import rotation_matrix
from multilift_tools.modal_cli import modal_main

SCENARIO_NAMES = sorted(p.stem for p in SCENARIOS.glob('*.yaml')
                        if 'rigid_body' not in p.read_text()  # point (bodies: test_modal_rigid)
                        and 'cable_model: elastic' not in p.read_text()  # refused (below)
                        and 'cable_model: chain' not in p.read_text())


def load(name: str) -> scenario_io.Scenario:
    return scenario_io.load(str(SCENARIOS / f'{name}.yaml'))


@pytest.fixture(scope='module')
def single_lift():
    return scenario_modal_analysis(load('single_lift_swing'))


@pytest.fixture(scope='module')
def twin_lift():
    return scenario_modal_analysis(load('twin_lift'))


# --------------------------------------------------------------------------- Eq. 2.73
@pytest.mark.parametrize('name', SCENARIO_NAMES)
def test_the_equilibrium_of_eq_2_73_is_one(name):
    scenario = load(name)
    params = dataclasses.replace(scenario.formation_params(20.0, 20.0), gusts=())
    eq = scenario_equilibrium(scenario)
    model = FormationModel(params)
    layout = model.layout
    x = eq.state
    g, g_dot = model.constraint_residuals(x)
    assert np.abs(g).max() < 1e-12 and np.abs(g_dot).max() == 0.0
    q_ddot, multipliers = model.accelerations(0.0, x, list(eq.rotor_speeds))
    assert np.abs(q_ddot).max() < 1e-10                         # q_ddot = 0: at rest it stays
    assert np.all(eq.tensions > 0)                               # every cable taut
    assert eq.multipliers == pytest.approx(multipliers, rel=1e-9)
    assert eq.tensions == pytest.approx(2 * np.array(params.cable_lengths) * multipliers,
                                        rel=1e-9)
    # force balance per body, written out here: UAV i thrust + cable pull = weight
    offsets = layout.payload_position(x) - layout.uav_positions(x)
    for i, uav in enumerate(params.uavs):
        wrench = uav.allocator().wrench(eq.rotor_speeds[i])
        assert np.abs(wrench[1:]).max() < 1e-9                 # no torque (W^T tau = 0)
        thrust = wrench[0] * rotation_matrix(layout.uav_euler(x)[i])[:, 2]
        pull = 2.0 * multipliers[i] * offsets[i]
        balance = thrust + pull - [0.0, 0.0, uav.mass * params.gravity]
        assert np.abs(balance).max() < 1e-9 * uav.mass * params.gravity
        assert layout.uav_euler(x)[i, 2] == pytest.approx(scenario.uavs[i].yaw, abs=1e-15)
    payload = -2.0 * multipliers @ offsets - [0.0, 0.0, params.payload_mass * params.gravity]
    assert np.abs(payload).max() < 1e-9
    if scenario.n_uavs == 1:                                     # vertical cable: UAV level
        assert np.array_equal(layout.uav_euler(x)[0, :2], [0.0, 0.0])
        assert eq.tensions[0] == pytest.approx(params.payload_mass * params.gravity, rel=1e-12)


@pytest.mark.parametrize('name,steps', [('twin_lift', 400), ('box_lift', 200)])
def test_the_formation_rests_at_its_equilibrium_for_seconds(name, steps):
    """Held at its equilibrium's rotor speeds (2 s, or 1 s for the box, at 5 ms), nothing
    moves: the point payload's and the rigid body's (docs/rigid_payload.md) alike."""
    scenario = load(name)
    eq = scenario_equilibrium(scenario)
    model = FormationModel(scenario.formation_params())
    x = eq.state
    for k in range(steps):
        x = model.step(k * 0.005, x, list(eq.rotor_speeds), 0.005)
    assert np.abs(x - eq.state).max() < 1e-9


def test_level_uavs_cannot_hold_a_slanted_cable():
    # Why the twin-lift's UAVs tilt (departure from "UAVs level"): with the thrust vertical,
    # the horizontal pull of a slanted cable accelerates each UAV towards the payload.
    scenario = load('twin_lift')
    eq = scenario_equilibrium(scenario)
    model = FormationModel(scenario.formation_params())
    layout = model.layout
    tilt = np.degrees(np.abs(layout.uav_euler(eq.state)[:, :2])).max()
    assert tilt > 1.0
    level = eq.state.copy()
    layout.set_uav_euler(level, layout.uav_euler(level) * [0.0, 0.0, 1.0])
    wrenches = eq.wrenches.copy()
    wrenches[:, 0] = [model.params.uavs[i].mass * model.gravity
                      + 2 * eq.multipliers[i] * (layout.payload_position(level)[2]
                                                 - layout.uav_positions(level)[i, 2])
                      for i in range(2)]                        # the vertical part only
    q_ddot, _ = model.accelerations_from_wrenches(level, wrenches)
    horizontal = np.linalg.norm(layout.uav_positions(q_ddot)[:, :2])
    assert horizontal > 0.01                                     # m/s^2, not an equilibrium


# ------------------------------------------------------------------------ single-lift
def test_single_lift_has_the_seeds_two_pendulum_pairs(single_lift):
    # seed Sec. 2.8.1: two identical purely imaginary pairs +-2.13j, period 2.94 s
    pendulum = single_lift.indices('pendulum')
    assert pendulum.size == 4
    values = single_lift.eigenvalues[pendulum]
    assert np.abs(values.real).max() < 1e-9
    assert np.abs(values.imag) == pytest.approx(np.full(4, 2.13), abs=0.005)
    assert sorted(np.sign(values.imag)) == [-1, -1, 1, 1]
    assert single_lift.pendulum_periods == pytest.approx([2.94, 2.94], rel=0.005)
    # the other 12 of the 16 are the free formation's rigid-body modes, nothing unstable
    assert single_lift.rigid_count == 12
    assert set(single_lift.kinds) == {'pendulum', 'rigid'}
    assert single_lift.basis.shape == (9, 8)                     # 8 independent coordinates


def test_single_lift_modes_equal_the_reduced_models_linearisation(single_lift):
    # Independent check: the reduced model (seed frame, Eq. 2.33-2.40, its own coordinates)
    # linearised by finite differences at the same rest and rotor speeds.
    scenario = load('single_lift_swing')
    uav = scenario.uavs[0]
    reduced = ReducedSingleLiftModel(uav.vehicle, scenario.payload.mass, uav.cable_length,
                                     scenario.simulation.gravity)
    speeds = single_lift.equilibrium.rotor_speeds[0]
    matrix = reduced.linearise(rest_state([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0, 0.0), speeds)
    reference = np.linalg.eigvals(matrix)
    oscillating = np.sort(reference[np.abs(reference) > 1e-4].imag)
    ours = np.sort(single_lift.eigenvalues[single_lift.indices('pendulum')].imag)
    assert ours == pytest.approx(oscillating, rel=1e-7)
    assert np.sum(np.abs(reference) <= 1e-4) == single_lift.rigid_count


def test_single_lift_pendulum_shapes_keep_the_centre_of_mass(single_lift):
    # No horizontal external force: in a swing the UAV moves -m_p/m of the payload's motion,
    # and the swings are along x and along y.
    scenario = load('single_lift_swing')
    m, m_p = scenario.uavs[0].vehicle.mass, scenario.payload.mass
    names = coordinate_names(1)
    directions = []
    for k in single_lift.pendulum_modes:
        shape = single_lift.shapes[k]
        assert np.abs(shape.imag).max() < 1e-9
        uav, payload = shape.real[0:3], shape.real[6:9]
        assert m * uav + m_p * payload == pytest.approx(np.zeros(3), abs=1e-7)
        directions.append(names[int(np.argmax(np.abs(shape)))])
    assert sorted(directions) == ['x_p', 'y_p']


# --------------------------------------------------------------------------- twin-lift
def test_the_basis_does_not_change_the_eigenvalues(twin_lift):
    # Eq. 2.71-2.72 with an orthonormal null-space basis, and elimination with another set of
    # dependent coordinates (z1 and the payload height z_p), give the same modes.
    scenario = load('twin_lift')
    params, eq = scenario.formation_params(), twin_lift.equilibrium
    nullspace = modal_analysis(params, eq, basis='nullspace')
    other = modal_analysis(params, eq, dependent=(2, 14))
    assert twin_lift.dependent == (2, 8)                         # z1, z2 as in the seed
    for analysis in (nullspace, other):
        assert analysis.kinds == twin_lift.kinds
        assert analysis.pendulum_periods == pytest.approx(twin_lift.pendulum_periods, rel=1e-7)


def test_dependent_coordinates_avoid_a_horizontal_cable():
    # UAV 2's cable lies flat: its altitude cannot be solved for, another coordinate is taken
    uavs = np.array([[0.0, 0.0, 3.0], [-3.0, 0.0, -1.0]])
    payload = np.array([0.0, 0.0, -1.0])
    jacobian = constraint_jacobian(uavs, payload)
    assert default_dependent_coordinates(constraint_jacobian(uavs + [0, 0, 1], payload)) \
        == (2, 8)
    dependent = default_dependent_coordinates(jacobian)
    assert dependent != (2, 8) and len(dependent) == 2
    basis, independent = elimination_basis(jacobian, dependent)
    assert basis.shape == (15, 13) and len(independent) == 13
    assert np.abs(jacobian @ basis).max() < 1e-12                  # G T = 0 (Eq. 2.71)
    with pytest.raises(ValueError, match='singular'):
        elimination_basis(jacobian, (2, 8))


def test_twin_lift_modes(twin_lift):
    # four pendulum pairs: the payload swinging across and along the UAV line, and two slow
    # formation modes (stretching along the line, twisting about the vertical); no unstable
    # mode in open loop with the rotor speeds held; 18 rigid-body eigenvalues (3 translations
    # and 6 attitude angles, each a double zero)
    assert len(twin_lift.pendulum_modes) == 4
    assert twin_lift.rigid_count == 18
    assert twin_lift.indices('unstable').size == 0
    periods = twin_lift.pendulum_periods
    assert np.all(np.diff(periods) > 0)
    names = coordinate_names(2)
    fastest = twin_lift.shapes[twin_lift.pendulum_modes[0]].real
    assert names[int(np.argmax(np.abs(fastest)))] in ('x_p', 'y_p')
    uavs = StateLayout(2).uav_positions(twin_lift.equilibrium.state)
    line = (uavs[0] - uavs[1]) / np.linalg.norm(uavs[0] - uavs[1])     # level: same height
    assert abs(fastest[12:15] @ line) < 1e-6                     # across the line


@pytest.mark.parametrize('pair', range(4))
def test_twin_lift_periods_match_a_simulated_swing(twin_lift, pair):
    # The full DAE (FormationModel, Baumgarte 20, drag and all) started 2 cm along one mode
    # shape, at rest, with the equilibrium rotor speeds: the swing keeps that mode's period.
    scenario = load('twin_lift')
    model = FormationModel(scenario.formation_params())
    mode = twin_lift.pendulum_modes[pair]
    period = twin_lift.pendulum_periods[pair]
    x = mode_state(twin_lift, mode, 0.02)
    assert np.abs(model.constraint_residuals(x)[0]).max() < 1e-12
    dt = 0.01
    steps = int(4 * period / dt)
    shape = twin_lift.shapes[mode].real
    layout = StateLayout(2)
    rest = seed_coordinates_of(layout, twin_lift.equilibrium.state)
    amplitude = np.empty(steps + 1)
    amplitude[0] = 1.0
    for k in range(steps):
        x = model.step(k * dt, x, list(twin_lift.equilibrium.rotor_speeds), dt)
        amplitude[k + 1] = (seed_coordinates_of(layout, x) - rest) @ shape / (
            0.02 * shape @ shape)
    t = np.arange(steps + 1) * dt
    k = np.nonzero(np.sign(amplitude[:-1]) != np.sign(amplitude[1:]))[0]
    crossings = t[k] - amplitude[k] * dt / (amplitude[k + 1] - amplitude[k])
    measured = 2.0 * (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    assert len(crossings) >= 7
    assert measured == pytest.approx(period, rel=1e-3)
    assert np.abs(amplitude).max() < 1.05                         # it stays in its mode


# ------------------------------------------------------------------------ command line
def test_modal_main_prints_the_table_and_writes_the_plot(tmp_path, capsys):
    code = modal_main([str(SCENARIOS / 'single_lift_swing.yaml'), '--out', str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0
    assert 'pendulum periods: 2.9450, 2.9450 s' in out
    assert '+/-2.13350' in out
    png = tmp_path / 'single_lift_swing_eigenvalues.png'
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    summary = json.loads((tmp_path / 'single_lift_swing_modal.json').read_text())
    assert summary['pendulum_periods'] == pytest.approx([2.945, 2.945], abs=1e-3)
    assert summary['rigid_count'] == 12
    assert math.isclose(summary['equilibrium']['tensions'][0], 0.4 * 9.81, rel_tol=1e-12)


def test_modal_main_bad_scenario_is_one_line_and_exit_2(tmp_path, capsys):
    assert modal_main(['no_such_scenario', '--out', str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and err.startswith('error: ')
    assert modal_main([]) == 2
    assert capsys.readouterr().err.count('\n') == 1
    assert not any(tmp_path.iterdir())


def test_modal_main_refuses_chain_cables_in_one_line(tmp_path, capsys):
    """Heavy cables' inner nodes are not linearised: one line, exit 2, nothing written."""
    assert modal_main(['twin_lift_chain', '--out', str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert err.startswith('error: cable_model: chain: the modal analysis linearises massless '
                          'cables')
    assert not any(tmp_path.iterdir())


def test_modal_main_refuses_elastic_cables_in_one_line(tmp_path, capsys):
    """The linearisation eliminates each cable's length: ropes that stretch have modes it
    cannot give (issue 32), so it says why rather than analyse the wrong system."""
    assert modal_main(['twin_lift_elastic', '--out', str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1
    assert err.startswith('error: cable_model: elastic: the modal analysis linearises cables '
                          'of fixed length')
    assert not any(tmp_path.iterdir())
