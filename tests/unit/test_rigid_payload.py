"""A rigid-body payload on the formation's cables (issue 20 item 3; physics.rigid_payload), held
against what mechanics says independently of it: a free system's energy and momentum kept, a
body whose attach points all sit at its centre of mass flying as the point mass, the static
tensions of an off-centre plate on vertical cables (the statics of three forces), and a bifilar
suspension's yaw period 2 pi sqrt(I l / (m g d^2)); the compiled functions equal their source
to the bit."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams
from multilift_sim.physics.formation_dae import integrate_period, rk4_step, solve
from multilift_sim.physics.layout import CABLE_COLUMNS, WORK_ROWS
from multilift_sim.start import initial_state


def _vehicle(mass: float | None = None):
    vehicle = scenario_io.load('twin_lift').uavs[0].vehicle
    return vehicle if mass is None else dataclasses.replace(vehicle, mass=mass)


def _params(uav_positions, attach, payload_mass=2.0, inertia=(0.1, 0.2, 0.25), lengths=None,
            uav_mass=None, gravity=9.81, alpha=20.0, beta=20.0, rigid=True) -> FormationParams:
    n = len(uav_positions)
    return FormationParams(
        uavs=tuple(_vehicle(uav_mass) for _ in range(n)),
        cable_lengths=tuple(lengths if lengths is not None else [2.0] * n),
        payload_mass=payload_mass, payload_drag_coefficient=0.0, baumgarte_alpha=alpha,
        baumgarte_beta=beta, gravity=gravity,
        payload_inertia=tuple(inertia) if rigid else None,
        payload_attach_points=tuple(tuple(a) for a in attach) if rigid else None)


def _hanging(model: FormationModel, uav_xy, attach, length: float, height: float = 10.0):
    """A state with the payload's centre at (0, 0, 0) level (identity attitude) and UAV i at
    (uav_xy[i], z) with its cable exactly `length` long to attach point i, at rest."""
    uavs = []
    for (x, y), (ax, ay, az) in zip(uav_xy, attach):
        horizontal = math.hypot(x - ax, y - ay)
        uavs.append((x, y, az + math.sqrt(length ** 2 - horizontal ** 2)))
    n = len(uav_xy)
    return model.layout.pack(np.array(uavs) + [0.0, 0.0, height], np.zeros((n, 3)),
                             [0.0, 0.0, height])


def _period(model, x, wrenches, dt, steps):
    """`steps` RK4 steps of dt from x under body wrenches (n, 4) held: the end state."""
    out = np.array(x)
    work = np.empty((WORK_ROWS, out.size))
    cables = np.empty((model.params.n_uavs, CABLE_COLUMNS))
    taut = np.ones(model.params.n_uavs, dtype=bool)
    multipliers = np.empty(model.params.n_uavs)
    for _ in range(steps):
        rk4_step(out, wrenches, model._uavs, model._gusts, model._formation, taut, dt, out,
                 multipliers, work, cables)
    return out


BOX_CORNERS = [(0.5, 0.3, 0.2), (-0.5, 0.3, 0.2), (-0.5, -0.3, 0.2), (0.5, -0.3, 0.2)]
BOX_INERTIA = (2.0 / 12 * (0.6 ** 2 + 0.4 ** 2), 2.0 / 12 * (1.0 ** 2 + 0.4 ** 2),
               2.0 / 12 * (1.0 ** 2 + 0.6 ** 2))       # a 1.0 x 0.6 x 0.4 m box of 2 kg


def test_a_free_formation_keeps_its_energy_and_momentum():
    """No gravity, no rotors, no drag: four UAVs and a spinning, drifting box (every cable
    at rest relative to its ends at the start, g_dot = 0) for 10 s: the energy (with the box's
    spin) to 1e-9 relative, the momentum to 1e-12."""
    uav_xy = [(1.2, 0.8), (-1.2, 0.8), (-1.2, -0.8), (1.2, -0.8)]
    model = FormationModel(_params(uav_xy, BOX_CORNERS, inertia=BOX_INERTIA, gravity=0.0,
                                   uav_mass=2.5))
    layout = model.layout
    x = _hanging(model, uav_xy, BOX_CORNERS, 2.0)
    drift, omega = np.array([0.4, -0.2, 0.1]), np.array([0.05, -0.03, 0.3])
    layout.payload_velocity(x)[:] = drift
    layout.payload_body_rates(x)[:] = omega
    for i, attach in enumerate(BOX_CORNERS):  # the UAVs move with the body: g_dot = 0
        offset = layout.uav_positions(x)[i] - layout.payload_position(x)
        layout.uav_velocities(x)[i] = drift + np.cross(omega, offset)
    g, g_dot = model.constraint_residuals(x)
    assert np.abs(g).max() < 1e-12 and np.abs(g_dot).max() < 1e-12
    energy = model.kinetic_energy(x)

    def momentum(state):
        return (model.uav_masses @ layout.uav_velocities(state)
                + model.payload_mass * layout.payload_velocity(state))
    start = momentum(x)
    end = _period(model, x, np.zeros((4, 4)), 1e-3, 10_000)
    assert abs(model.kinetic_energy(end) / energy - 1.0) < 1e-9
    assert np.abs(momentum(end) - start).max() < 1e-12
    g, _ = model.constraint_residuals(end)
    assert np.abs(g).max() < 1e-9
    assert abs(np.linalg.norm(layout.payload_quaternion(end)) - 1.0) < 1e-15
    assert np.abs(layout.payload_quaternion(end) - layout.payload_quaternion(x)).max() > 0.1


def test_a_body_held_at_its_centre_of_mass_flies_as_the_point_mass():
    """Every attach point at the centre of mass: the twin-lift's positions those of the
    seed's point payload to 1e-9 m over 5 s of hovering rotors, and its spin untouched."""
    scenario = scenario_io.load('twin_lift')
    point = FormationModel(scenario.formation_params())
    rigid = FormationModel(dataclasses.replace(
        scenario.formation_params(), payload_inertia=(0.02, 0.03, 0.04),
        payload_attach_points=((0.0, 0.0, 0.0),) * 2))
    x_point = initial_state(scenario)
    x_rigid = np.concatenate((x_point, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.2]))
    wrenches = point.wrenches([np.full(4, 1980.0), np.full(4, 1975.0)])
    end_point = _period(point, x_point, wrenches, 5e-3, 1000)
    end_rigid = _period(rigid, x_rigid, wrenches, 5e-3, 1000)
    size = x_point.size
    assert np.abs(end_rigid[:size] - end_point).max() < 1e-9
    assert np.abs(end_point[:size] - x_point).max() > 1.0  # it moved
    assert end_rigid[size + 6] == pytest.approx(0.2, abs=1e-12)  # a free spin about z


def test_an_off_centre_plate_on_vertical_cables_carries_the_statics_tensions():
    """Three cables straight up from a plate whose centre of mass is off their centroid: the
    statics (sum T_i = m g, sum b_i x T_i e_z = 0) gives three different tensions; with each
    UAV's thrust its weight plus that tension the DAE's multipliers are those tensions
    (T_i = 2 l lambda_i, to 1e-9 relative) and nothing accelerates: the hover is the statics."""
    attach = [(0.6, 0.1, 0.0), (-0.4, 0.5, 0.0), (-0.3, -0.6, 0.0)]
    model = FormationModel(_params([a[:2] for a in attach], attach, payload_mass=3.0,
                                   uav_mass=2.5))
    x = _hanging(model, [a[:2] for a in attach], attach, 2.0)
    a = np.array([[1.0, 1.0, 1.0], [b[1] for b in attach], [-b[0] for b in attach]])
    expected = np.linalg.solve(a, [3.0 * 9.81, 0.0, 0.0])
    assert len(set(np.round(expected, 6))) == 3  # off centre: three different tensions
    wrenches = np.zeros((3, 4))
    wrenches[:, 0] = 2.5 * 9.81 + expected
    acc, multipliers = model.accelerations_from_wrenches(x, wrenches)
    assert np.abs(2.0 * 2.0 * multipliers / expected - 1.0).max() < 1e-9
    assert np.abs(acc).max() < 1e-9


def test_a_bifilar_suspension_swings_in_yaw_with_its_period():
    """A beam held by two vertical cables of l = 2 m at d = 0.6 m either side of its centre,
    the suspension points fixed: a small yaw swing's period 2 pi sqrt(I l / (m g d^2)) to 1 %."""
    d, length, mass, inertia_z = 0.6, 2.0, 1.5, 0.3
    attach = [(d, 0.0, 0.0), (-d, 0.0, 0.0)]
    model = FormationModel(_params([(d, 0.0), (-d, 0.0)], attach, payload_mass=mass,
                                   inertia=(0.01, inertia_z, inertia_z), lengths=[length] * 2,
                                   uav_mass=1e9))
    x = _hanging(model, [(d, 0.0), (-d, 0.0)], attach, length)
    model.layout.payload_body_rates(x)[:] = (0.0, 0.0, 0.02)
    wrenches = np.zeros((2, 4))
    wrenches[:, 0] = 1e9 * 9.81
    dt, rates = 2e-3, []
    state = x
    for _ in range(6000):
        state = _period(model, state, wrenches, dt, 1)
        rates.append(model.layout.payload_body_rates(state)[2])
    rates = np.array(rates)
    crossings = np.flatnonzero((rates[:-1] > 0) & (rates[1:] <= 0))
    periods = np.diff(crossings) * dt
    expected = 2 * math.pi * math.sqrt(inertia_z * length / (mass * 9.81 * d * d))
    assert len(periods) >= 3
    assert abs(periods.mean() / expected - 1.0) < 0.01


def test_the_rigid_solve_compiled_is_its_source_bit_for_bit():
    uav_xy = [(1.2, 0.8), (-1.2, 0.8), (-1.2, -0.8), (1.2, -0.8)]
    model = FormationModel(_params(uav_xy, BOX_CORNERS, inertia=BOX_INERTIA, uav_mass=2.5))
    x = _hanging(model, uav_xy, BOX_CORNERS, 2.0)
    rng = np.random.default_rng(4)
    x[model.layout.n_coordinates:] += rng.normal(0.0, 0.1, x.size - model.layout.n_coordinates)
    wrenches = model.wrenches([np.full(4, 1900.0)] * 4)
    taut = np.ones(4, dtype=bool)
    results = []
    for function in (solve, kernels.uncompiled(solve)):
        acc, multipliers = np.empty(x.size - model.layout.n_coordinates), np.empty(4)
        function(x, wrenches, model._uavs, model._gusts, model._formation, taut, acc,
                 multipliers, np.empty((4, CABLE_COLUMNS)))
        results.append((acc, multipliers))
    assert all(np.array_equal(a, b) for a, b in zip(*results))
    periods = [function(x, wrenches, model._uavs, model._gusts, model._formation, taut, 5e-3,
                        2) for function in (integrate_period, kernels.uncompiled(integrate_period))]
    assert all(np.array_equal(a, b) for a, b in zip(*periods))


def _free_with_offsets(rigid: bool):
    """A free formation (no gravity, rotors or drag) whose cables hold the UAVs 0.15 m below
    and off their centres, tumbling: UAVs turning, the payload (a box, or the point) drifting,
    every cable at rest relative to its ends (g_dot = 0)."""
    offsets = [(0.1, 0.05, -0.15), (-0.08, 0.02, -0.15), (0.0, -0.1, -0.15),
               (0.05, 0.05, -0.12)]
    uav_xy = [(1.2, 0.8), (-1.2, 0.8), (-1.2, -0.8), (1.2, -0.8)]
    params = dataclasses.replace(
        _params(uav_xy, BOX_CORNERS if rigid else [(0.0, 0.0, 0.0)] * 4,
                inertia=BOX_INERTIA, gravity=0.0, uav_mass=2.5, rigid=rigid),
        uav_attach_points=tuple(offsets))
    model = FormationModel(params)
    layout = model.layout
    x = _hanging(model, uav_xy, BOX_CORNERS if rigid else [(0.0, 0.0, 0.0)] * 4, 2.0)
    layout.uav_positions(x)[:] -= np.array(offsets)  # each cable's upper end where it was
    rng = np.random.default_rng(8)
    layout.uav_body_rates(x)[:] = rng.normal(0.0, 0.3, (4, 3))
    g, g_dot = model.constraint_residuals(x)
    assert np.abs(g).max() < 1e-12
    # velocities making every g_dot zero: the payload drifts, each UAV's centre compensates
    # its attach point's turning (v_i = v_p + w_p x e_i - w_i x R_i a_i)
    from multilift_sim.physics.free_motion import uav_attach_motion
    drift = np.array([0.3, -0.1, 0.05])
    layout.payload_velocity(x)[:] = drift
    if rigid:
        layout.payload_body_rates(x)[:] = (0.05, -0.03, 0.2)
    for i in range(4):
        attach = np.empty((3, 3))
        uav_attach_motion(x, i, np.zeros((4, 4)), model._uavs, attach)
        end_velocity = drift.copy()
        if rigid:
            e = np.array(BOX_CORNERS[i])  # identity attitude: e_i = b_i
            end_velocity += np.cross(layout.payload_body_rates(x), e)
        layout.uav_velocities(x)[i] = end_velocity - attach[1]
    g, g_dot = model.constraint_residuals(x)
    assert np.abs(g_dot).max() < 1e-12
    return model, x


@pytest.mark.parametrize('rigid', [False, True], ids=['point', 'box'])
def test_cables_off_the_uavs_centres_keep_a_free_formation_s_energy(rigid):
    """Issue 20 item 2: cables held off the UAVs' centres of mass (`uavs[i].attach_point`),
    the tension's moment on each UAV's attitude: a free, tumbling formation keeps its energy
    (translation and every body's rotation) to 1e-9 relative over 5 s and its momentum to
    1e-12, the cables on their lengths; the UAVs' attitudes move (the moments act)."""
    model, x = _free_with_offsets(rigid)
    layout = model.layout
    energy = model.kinetic_energy(x)

    def momentum(state):
        return (model.uav_masses @ layout.uav_velocities(state)
                + model.payload_mass * layout.payload_velocity(state))
    end = _period(model, x, np.zeros((4, 4)), 5e-4, 10_000)
    assert abs(model.kinetic_energy(end) / energy - 1.0) < 1e-9
    assert np.abs(momentum(end) - momentum(x)).max() < 1e-12
    g, _ = model.constraint_residuals(end)
    assert np.abs(g).max() < 1e-9
    assert np.abs(layout.uav_euler(end) - layout.uav_euler(x)).max() > 0.1


def test_a_cable_s_moment_turns_its_uav_as_euler_s_equation_says():
    """At rest, rotors silent: the pull 2 lambda_i d_i at a_i gives UAV i the angular
    acceleration J^-1 (a_i x R_i^T 2 lambda_i d_i), written out here, its omega_dot;
    and the compiled solve equals its source to the bit."""
    model, x = _free_with_offsets(rigid=False)
    layout = model.layout
    layout.uav_body_rates(x)[:] = 0.0
    layout.uav_velocities(x)[:] = 0.0
    layout.payload_velocity(x)[:] = 0.0
    layout.payload_position(x)[2] -= 1e-6  # a little stretch: the cables pull (Baumgarte)
    acc, multipliers = model.accelerations_from_wrenches(x, np.zeros((4, 4)))
    assert np.abs(multipliers).max() > 0
    for i in range(4):
        phi, theta, psi = layout.uav_euler(x)[i]
        from multilift_sim.kinematics import rotation_matrix
        rotation = rotation_matrix(np.array([phi, theta, psi]))
        a = np.array(model.params.uav_attach_points[i])
        d = layout.payload_position(x) - (layout.uav_positions(x)[i] + rotation @ a)
        omega_dot = np.cross(a, rotation.T @ (2.0 * multipliers[i] * d)) / model.uav_inertia[i]
        rates = layout.uav_body_rates(np.concatenate((layout.rates(x), acc)))[i]  # x_dot's
        assert np.abs(rates - omega_dot).max() < 1e-12 * max(1.0, np.abs(omega_dot).max())
    taut = np.ones(4, dtype=bool)
    results = []
    for function in (solve, kernels.uncompiled(solve)):
        out, lam = np.empty(layout.size - layout.n_coordinates), np.empty(4)
        function(x, np.zeros((4, 4)), model._uavs, model._gusts, model._formation, taut, out,
                 lam, np.empty((4, CABLE_COLUMNS)))
        results.append((out, lam))
    assert all(np.array_equal(a, b) for a, b in zip(*results))
