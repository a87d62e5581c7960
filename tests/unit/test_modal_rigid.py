"""Modal analysis of a rigid-body payload (issue 20 item 3: `multilift modal` lists the rigid
payload's modes; multilift_sim.analysis, docs/rigid_payload.md), held against solutions found
without it: a body whose attach points all sit at its centre of mass has the point payload's
pendulum eigenvalues and its three rotations at zero; a bifilar suspension (suspension points
held still) has the simple pendulum's swings and the yaw period 2 pi sqrt(I l / (m g d^2)), and
beam_lift's trapezoidal suspension 2 pi sqrt(I h / (m g D d)); very heavy UAVs approach the
held ones; the scenarios' equilibria are the statics of their cables and rest for seconds; the
full DAE swings at the linear periods; `multilift modal box_lift` / `beam_lift`."""
from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from conftest import SCENARIOS
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.coordinates import coordinate_names, seed_coordinates_of
from multilift_sim.analysis.equilibrium import (scenario_configuration, scenario_equilibrium,
                                                static_equilibrium)
from multilift_sim.analysis.modal import modal_analysis, mode_state, scenario_modal_analysis
from multilift_sim.analysis.modes import motion_shares
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_tools.modal_cli import _label_groups, modal_main

G = 9.81


def load(name: str) -> scenario_io.Scenario:
    return scenario_io.load(str(SCENARIOS / f'{name}.yaml'))


def _rotation_vector(quaternion: np.ndarray) -> np.ndarray:
    """theta [rad] of a unit quaternion (w, x, y, z) near the identity: q = Exp(theta)."""
    w, v = quaternion[0], np.asarray(quaternion[1:])
    norm = np.linalg.norm(v)
    return np.zeros(3) if norm == 0.0 else 2.0 * math.atan2(norm, w) * v / norm


def _minimal(layout: StateLayout, x: np.ndarray) -> np.ndarray:
    """q_f and the payload's rotation vector from the identity, (6n + 6,)."""
    return np.concatenate((seed_coordinates_of(layout, x),
                           _rotation_vector(layout.payload_quaternion(x))))


def _dominant(analysis, motion: str) -> int:
    """The pendulum mode (positive imaginary part) with the largest share of `motion`."""
    return max(analysis.pendulum_modes, key=lambda k: motion_shares(analysis, k)[motion])


def _bifilar(half_uavs: float, half_attach: float, length: float, mass: float,
             inertia: tuple[float, float, float], uav_mass: float | None = None,
             speed_max: float | None = None):
    """Two UAVs at (+-half_uavs, 0, z) holding a beam level at its centre (0, 0, 0) by
    (+-half_attach, 0, 0) on cables of `length`: (params, equilibrium)."""
    vehicle = load('twin_lift').uavs[0].vehicle
    if uav_mass is not None:
        vehicle = dataclasses.replace(vehicle, mass=uav_mass, rotor_speed_max=speed_max)
    params = FormationParams(uavs=(vehicle, vehicle), cable_lengths=(length, length),
                             payload_mass=mass, payload_drag_coefficient=0.0,
                             baumgarte_alpha=0.0, baumgarte_beta=0.0, gravity=G,
                             payload_inertia=inertia,
                             payload_attach_points=((half_attach, 0.0, 0.0),
                                                    (-half_attach, 0.0, 0.0)))
    drop = math.sqrt(length ** 2 - (half_uavs - half_attach) ** 2)
    uavs = [[half_uavs, 0.0, drop], [-half_uavs, 0.0, drop]]
    return params, static_equilibrium(params, uavs, [0.0, 0.0, 0.0])


# ------------------------------------------------------------ a body held at its centre
@pytest.mark.parametrize('name', ['twin_lift', 'v5'])
def test_a_body_held_at_its_centre_of_mass_has_the_point_payload_s_modes(name):
    """Every b_i = 0: the body's rotation has no stiffness and no coupling, so its modes are
    the point payload's (the twin-lift; the V of five, whose multipliers are the least-norm
    split of the statically indeterminate rows) plus three double zeros for the rotation."""
    scenario = load(name)
    point_params = scenario.formation_params(0.0, 0.0)
    params = dataclasses.replace(point_params, payload_inertia=(0.02, 0.03, 0.04),
                                 payload_attach_points=((0.0, 0.0, 0.0),) * scenario.n_uavs)
    uavs, payload = scenario_configuration(scenario)
    yaws = [u.yaw for u in scenario.uavs]
    point = modal_analysis(point_params, static_equilibrium(point_params, uavs, payload, yaws))
    body = modal_analysis(params, static_equilibrium(params, uavs, payload, yaws))
    size = StateLayout(scenario.n_uavs).size
    assert np.abs(body.equilibrium.state[:size] - point.equilibrium.state).max() < 1e-12
    assert body.equilibrium.multipliers == pytest.approx(point.equilibrium.multipliers,
                                                         rel=1e-12)
    assert body.rigid_count == point.rigid_count + 6
    kept = [k for k, kind in enumerate(body.kinds) if kind != 'rigid']
    assert [body.kinds[k] for k in kept] == [k for k in point.kinds if k != 'rigid']
    values = body.eigenvalues[kept]
    reference = point.eigenvalues[:len(kept)]
    assert np.abs(values - reference).max() < 1e-9 * np.abs(reference).max()
    assert body.pendulum_periods == pytest.approx(point.pendulum_periods, rel=1e-9)
    for k in kept:     # the rotation stays out of every mode that moves
        assert np.abs(body.shapes[k][-3:]).max() < 1e-9
        assert motion_shares(body, k)['yaw'] < 1e-12
    zeros = body.eigenvalues[body.indices('rigid')]
    assert np.abs(zeros).max() < body.zero_tolerance


# ------------------------------------------------------------------ bifilar suspensions
def test_a_bifilar_suspension_held_still_has_the_textbook_periods():
    """A beam on two vertical cables (l = 2 m, d = 0.6 m either side of its centre), the
    suspension points held still (hold_uavs): yaw 2 pi sqrt(I l / (m g d^2)), the swings
    along and across the beam a simple pendulum's 2 pi sqrt(l / g) (a parallelogram: the
    beam translates), the roll about its own axis (which the attach points lie on) free."""
    d, length, mass, inertia_z = 0.6, 2.0, 1.5, 0.3
    params, eq = _bifilar(d, d, length, mass, (0.01, inertia_z, inertia_z))
    assert eq.tensions == pytest.approx([mass * G / 2] * 2, rel=1e-12)
    held = modal_analysis(params, eq, hold_uavs=True)
    assert held.rigid_count == 2 and held.indices('unstable').size == 0
    assert len(held.pendulum_modes) == 3
    yaw = _dominant(held, 'yaw')
    assert motion_shares(held, yaw)['yaw'] > 0.999
    expected = 2 * math.pi * math.sqrt(inertia_z * length / (mass * G * d * d))
    assert 2 * math.pi / held.eigenvalues[yaw].imag == pytest.approx(expected, rel=1e-9)
    swings = sorted(2 * math.pi / held.eigenvalues[k].imag for k in held.pendulum_modes
                    if k != yaw)
    assert swings == pytest.approx([2 * math.pi * math.sqrt(length / G)] * 2, rel=1e-9)
    assert np.abs(held.basis[:12]).max() == 0.0          # the UAVs' rows: clamped
    # the same with an orthonormal null-space basis of the free coordinates
    nullspace = modal_analysis(params, eq, hold_uavs=True, basis='nullspace')
    assert nullspace.pendulum_periods == pytest.approx(held.pendulum_periods, rel=1e-7)


def test_beam_lift_s_yaw_held_still_is_the_trapezoidal_bifilar_s():
    """beam_lift's cables lean in (UAVs 2D = 5 m apart, attach points 2d = 3 m): yawing by
    theta lifts the beam by D d theta^2 / (2 h) (h the cables' vertical drop, from
    (D - d cos)^2 + (d sin)^2 + (h - z)^2 = l^2), so I theta_ddot = -m g D d / h theta and the
    period is 2 pi sqrt(I h / (m g D d)), the bifilar formula when D = d (h = l). It holds
    with the UAVs held still; with them free (open loop, held rotor speeds) they give way and
    the twist is faster."""
    scenario = load('beam_lift')
    held = scenario_modal_analysis(scenario, hold_uavs=True)
    layout = StateLayout(2, True)
    x = held.equilibrium.state
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    big_d = abs(uavs[0, 0] - uavs[1, 0]) / 2
    small_d = abs(scenario.payload.attach_points[0][0])
    drop = uavs[0, 2] - payload[2]
    assert (big_d, small_d) == pytest.approx((2.5, 1.5), abs=1e-12)
    assert drop == pytest.approx(math.sqrt(15.0), rel=1e-12)
    inertia_z, mass = scenario.payload.inertia[2], scenario.payload.mass
    expected = 2 * math.pi * math.sqrt(inertia_z * drop / (mass * G * big_d * small_d))
    yaw = _dominant(held, 'yaw')
    assert 2 * math.pi / held.eigenvalues[yaw].imag == pytest.approx(expected, rel=1e-9)
    free = scenario_modal_analysis(scenario)
    free_yaw = 2 * math.pi / free.eigenvalues[_dominant(free, 'yaw')].imag
    assert free_yaw < expected * 0.99                    # 1.734 s against 1.766 s


def test_very_heavy_uavs_approach_the_held_suspension():
    """The other way to hold the suspension points: heavy UAVs (rotors allowed the speed),
    free. The bifilar's yaw period approaches the clamped analysis's as the UAVs give way by
    about m_p / m_i: 10^3 kg within 3e-4, 10^4 kg within 3e-5, the gap ten times smaller (so
    the clamp is the limit, not a coincidence)."""
    d, length, mass, inertia = 0.6, 2.0, 1.5, (0.01, 0.3, 0.3)
    params, eq = _bifilar(d, d, length, mass, inertia)
    held = modal_analysis(params, eq, hold_uavs=True)
    period = 2 * math.pi / held.eigenvalues[_dominant(held, 'yaw')].imag
    gaps = []
    for uav_mass in (1e3, 1e4):
        heavy_params, heavy_eq = _bifilar(d, d, length, mass, inertia, uav_mass=uav_mass,
                                          speed_max=2e5)
        heavy = modal_analysis(heavy_params, heavy_eq)
        gaps.append(abs(2 * math.pi / heavy.eigenvalues[_dominant(heavy, 'yaw')].imag
                        / period - 1.0))
    assert gaps[0] < 3e-4 and gaps[1] < 3e-5
    assert gaps[0] / gaps[1] == pytest.approx(10.0, rel=0.05)


# ------------------------------------------------------------------ the scenarios' bodies
@pytest.mark.parametrize('name', ['box_lift', 'beam_lift'])
def test_the_rigid_scenarios_equilibrium_is_their_statics(name):
    """At the hanging rest (the simulator's start, the body level) the DAE accelerates
    nothing under the equilibrium's rotors; the multipliers balance the body's weight and
    moment (written out here: sum 2 lambda_i d_i = -m_p g e_z, sum b_i x 2 lambda_i d_i = 0
    with R_p = I); by symmetry each cable's vertical pull is m_p g / n, so T_i = m_p g l_i /
    (n h_i) with h_i its vertical drop."""
    scenario = load(name)
    eq = scenario_equilibrium(scenario)
    model = FormationModel(dataclasses.replace(scenario.formation_params(), gusts=()))
    layout = model.layout
    x = eq.state
    assert np.array_equal(layout.payload_quaternion(x), [1.0, 0.0, 0.0, 0.0])
    g, g_dot = model.constraint_residuals(x)
    assert np.abs(g).max() < 1e-12 and np.abs(g_dot).max() == 0.0
    acc, multipliers = model.accelerations(0.0, x, list(eq.rotor_speeds))
    assert np.abs(acc).max() < 1e-10
    assert eq.multipliers == pytest.approx(multipliers, rel=1e-9)
    attach = np.array(scenario.payload.attach_points)
    offsets = layout.payload_position(x) + attach - layout.uav_positions(x)
    pull = 2.0 * eq.multipliers[:, None] * offsets
    weight = scenario.payload.mass * G
    assert np.abs(pull.sum(axis=0) + [0.0, 0.0, weight]).max() < 1e-12 * weight
    assert np.abs(np.cross(attach, pull).sum(axis=0)).max() < 1e-12 * weight
    lengths = np.array([u.cable_length for u in scenario.uavs])
    expected = weight * lengths / (scenario.n_uavs * -offsets[:, 2])
    assert eq.tensions == pytest.approx(expected, rel=1e-12)


@pytest.fixture(scope='module')
def box_lift():
    return scenario_modal_analysis(load('box_lift'))


@pytest.fixture(scope='module')
def beam_lift():
    return scenario_modal_analysis(load('beam_lift'))


def test_box_lift_modes_are_named_by_the_body_s_motion(box_lift):
    """Open loop, rotor speeds held: nothing unstable; 30 zeros (the formation's 3
    translations and the 12 UAV attitude angles, each a double zero); the fastest mode the
    box's yaw (its energy 0.99 in the rotation about z), the box's roll and pitch in the next
    two, each with its swing (the attach points sit 0.2 m above its centre)."""
    assert box_lift.rigid_count == 30 and box_lift.indices('unstable').size == 0
    modes = box_lift.pendulum_modes
    assert len(modes) == 11
    shares = [motion_shares(box_lift, k) for k in modes]
    assert shares[0]['yaw'] > 0.98
    assert box_lift.motion(modes[0]).startswith('yaw 0.99')
    assert shares[1]['roll'] > 0.1 and shares[1]['swing y'] > 0.2
    assert shares[2]['pitch'] > 0.1 and shares[2]['swing x'] > 0.5
    for share in shares:
        assert sum(share.values()) == pytest.approx(1.0, abs=1e-12)
    names = coordinate_names(4, True)
    assert names[-3:] == ('rx_p', 'ry_p', 'rz_p') and len(names) == box_lift.shapes.shape[1]
    assert names[int(np.argmax(np.abs(box_lift.shapes[modes[0]])))] == 'rz_p'


@pytest.mark.parametrize('case', [('box_lift', 'yaw'), ('box_lift', 'pitch'),
                                  ('beam_lift', 'yaw'), ('beam_lift', 'swing y')])
def test_rigid_periods_match_a_simulated_swing(box_lift, beam_lift, case):
    """The full DAE (FormationModel, Baumgarte 20, drag and all) started 0.02 along one mode
    shape (the body turned through its quaternion), at rest, with the equilibrium rotor
    speeds: the swing keeps that mode's period to 1e-3 and stays in its mode."""
    name, motion = case
    analysis = box_lift if name == 'box_lift' else beam_lift
    model = FormationModel(load(name).formation_params())
    layout = model.layout
    mode = _dominant(analysis, motion)
    period = 2 * math.pi / analysis.eigenvalues[mode].imag
    x = mode_state(analysis, mode, 0.02)
    assert np.abs(model.constraint_residuals(x)[0]).max() < 1e-12
    assert abs(np.linalg.norm(layout.payload_quaternion(x)) - 1.0) < 1e-15
    shape = analysis.shapes[mode].real
    rest = _minimal(layout, analysis.equilibrium.state)
    dt = period / 200
    amplitude = [1.0]
    for k in range(800):                                          # four periods
        x = model.step(k * dt, x, list(analysis.equilibrium.rotor_speeds), dt)
        amplitude.append((_minimal(layout, x) - rest) @ shape / (0.02 * shape @ shape))
    amplitude = np.array(amplitude)
    t = np.arange(amplitude.size) * dt
    k = np.nonzero(np.sign(amplitude[:-1]) != np.sign(amplitude[1:]))[0]
    crossings = t[k] - amplitude[k] * dt / (amplitude[k + 1] - amplitude[k])
    assert len(crossings) >= 7
    measured = 2.0 * (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    assert measured == pytest.approx(period, rel=1e-3)
    assert np.abs(amplitude).max() < 1.05


# ------------------------------------------------------------------------ command line
@pytest.mark.parametrize('name', ['box_lift', 'beam_lift'])
def test_modal_main_lists_a_rigid_payload_s_modes(name, tmp_path, capsys):
    code = modal_main([name, '--out', str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0
    assert f'modal analysis of {name}' in out and 'a rigid body of' in out
    assert 'rx_p' in out and 'pendulum periods: ' in out
    rows = [line for line in out.splitlines() if 'pendulum' in line and '+/-' in line]
    assert rows and rows[0].split()[5:7] == ['yaw', '0.99' if name == 'box_lift' else '0.96']
    png = tmp_path / f'{name}_eigenvalues.png'
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    summary = json.loads((tmp_path / f'{name}_modal.json').read_text())
    assert summary['payload'] == 'rigid_body' and summary['held_uavs'] is False
    assert summary['coordinates'][-3:] == ['rx_p', 'ry_p', 'rz_p']
    assert summary['rigid_count'] == {'box_lift': 30, 'beam_lift': 20}[name]
    first = summary['kinds'].index('pendulum')
    assert summary['motions'][first]['yaw'] > 0.95
    periods = summary['pendulum_periods']
    assert periods[0] == pytest.approx({'box_lift': 1.2862, 'beam_lift': 1.7342}[name],
                                       abs=1e-4)
    assert f'pendulum periods: {periods[0]:.4f}' in out


def test_modal_main_holds_the_uavs(tmp_path, capsys):
    assert modal_main(['beam_lift', '--out', str(tmp_path), '--hold-uavs']) == 0
    out = capsys.readouterr().out
    assert 'held still (--hold-uavs)' in out
    summary = json.loads((tmp_path / 'beam_lift_held_modal.json').read_text())
    assert summary['held_uavs'] is True and summary['rigid_count'] == 2
    assert summary['pendulum_periods'][0] == pytest.approx(1.7658, abs=1e-4)
    assert (tmp_path / 'beam_lift_held_eigenvalues.png').exists()


def test_the_plot_labels_a_crowd_once(box_lift):
    """box_lift's five formation modes at 8.41-8.79 s share one label; the twin-lift's close
    pair keeps its two (on alternating sides)."""
    assert [len(group) for group in _label_groups(box_lift)] == [1, 1, 1, 1, 1, 5, 1]
    twin_lift = scenario_modal_analysis(load('twin_lift'))
    assert [len(group) for group in _label_groups(twin_lift)] == [1, 1, 1, 1]
