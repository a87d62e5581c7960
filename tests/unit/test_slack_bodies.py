"""Slack cables (`cable_model: slack`) on a rigid-body payload and off the UAVs' centres of mass
(issue 20 item 1, "the slack model too"; physics.slack_cables on docs/rigid_payload.md's
matrix A): held against mechanics written out here in numpy, not against the kernels: the snap
is the inelastic impulse of the mass metric (the generalized mass matrix with the bodies'
rotations, and each cable's g_dot, built from rotation matrices), it keeps the linear and
angular momentum (the impulse is internal) and never adds energy; a free formation whose cables
go slack and snap taut keeps its energy between the snaps and loses some at each; with every
cable taut the slack model flies as the rigid one; compiled equals source to the bit."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from test_rigid_payload import BOX_CORNERS, BOX_INERTIA, _hanging, _params
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.dynamics import FormationModel
from multilift_sim.physics.layout import CABLE_COLUMNS, SLACK_CABLE_ROWS
from multilift_sim.physics.slack_cables import integrate_period as slack_period
from multilift_sim.physics.slack_cables import snap
from multilift_sim.slack import SlackCableModel

UAV_XY = [(1.2, 0.8), (-1.2, 0.8), (-1.2, -0.8), (1.2, -0.8)]
OFFSETS = [(0.1, 0.05, -0.15), (-0.08, 0.02, -0.15), (0.0, -0.1, -0.15), (0.05, 0.05, -0.12)]
# (payload, cables held off the UAVs' centres)
CASES = {'box': ('box', False), 'box_off_centre': ('box', True),
         'point_off_centre': ('point', True)}


def _model(case: str, model_class=SlackCableModel, gravity: float = 0.0):
    """Four 2.5 kg UAVs on 2 m cables to a 2 kg box at its top corners (or the point mass),
    no drag, held at their centres or 0.12-0.15 m below and off them; and the state with every
    cable at its length, the box level, all at rest."""
    payload, off_centre = CASES[case]
    rigid = payload == 'box'
    attach = BOX_CORNERS if rigid else [(0.0, 0.0, 0.0)] * 4
    params = _params(UAV_XY, attach, inertia=BOX_INERTIA, gravity=gravity, uav_mass=2.5,
                     rigid=rigid)
    if off_centre:
        params = dataclasses.replace(params, uav_attach_points=tuple(OFFSETS))
    model = model_class(params)
    x = _hanging(model, UAV_XY, attach, 2.0)
    if off_centre:
        model.layout.uav_positions(x)[:] -= np.array(OFFSETS)  # the cables' upper ends kept
    return model, x


# ------------------------------------------------------- mechanics written out, in numpy
def _payload_rotation(q) -> np.ndarray:
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _velocities(model, x) -> np.ndarray:
    """The generalized velocities u: q_dot (each UAV's v_i, then v_p), each UAV's body rates
    omega_i, then a rigid payload's omega_p."""
    layout = model.layout
    parts = [layout.rates(x), layout.uav_body_rates(x).ravel()]
    if layout.rigid_payload:
        parts.append(layout.payload_body_rates(x))
    return np.concatenate(parts)


def _with_velocities(model, x, u) -> np.ndarray:
    layout = model.layout
    nq, n = layout.n_coordinates, layout.n_uavs
    out = np.array(x)
    layout.rates(out)[:] = u[:nq]
    layout.uav_body_rates(out)[:] = u[nq:nq + 3 * n].reshape(n, 3)
    if layout.rigid_payload:
        layout.payload_body_rates(out)[:] = u[nq + 3 * n:]
    return out


def _mass_matrix(model, x) -> np.ndarray:
    """M of the kinetic energy 1/2 u^T M u: m_i I per UAV, m_p I, J_i per UAV's body rates,
    and J_p for a rigid payload's."""
    layout = model.layout
    blocks = [model.uav_masses[i] * np.eye(3) for i in range(len(model.uav_masses))]
    blocks.append(model.payload_mass * np.eye(3))
    blocks += [np.diag(model.uav_inertia[i]) for i in range(len(model.uav_masses))]
    if layout.rigid_payload:
        blocks.append(np.diag(model.params.payload_inertia))
    size = sum(len(b) for b in blocks)
    m, k = np.zeros((size, size)), 0
    for b in blocks:
        m[k:k + len(b), k:k + len(b)] = b
        k += len(b)
    return m


def _g_dot(model, x, u) -> np.ndarray:
    """g_dot_i = 2 d_i . d_i_dot with d_i = r_p + R_p b_i - r_i - R_i a_i at the positions of x
    and the velocities u (linear in u)."""
    layout, params = model.layout, model.params
    x = _with_velocities(model, x, u)
    rotation_p, spin = np.eye(3), np.zeros(3)
    if layout.rigid_payload:
        rotation_p = _payload_rotation(layout.payload_quaternion(x))
        spin = layout.payload_body_rates(x)
    out = []
    for i in range(len(model.uav_masses)):
        rotation_i = _payload_rotation(layout.uav_quaternions(x)[i])   # the same R of a q
        omega_i = layout.uav_body_rates(x)[i]
        a = np.array(params.uav_attach_points[i]) if params.uav_attach_points else np.zeros(3)
        b = np.array(params.payload_attach_points[i]) if layout.rigid_payload else np.zeros(3)
        d = (layout.payload_position(x) + rotation_p @ b - layout.uav_positions(x)[i]
             - rotation_i @ a)
        d_dot = (layout.payload_velocity(x) + rotation_p @ np.cross(spin, b)
                 - layout.uav_velocities(x)[i] - rotation_i @ np.cross(omega_i, a))
        out.append(2.0 * d @ d_dot)
    return np.array(out)


def _inelastic_impulse(model, x, taut) -> np.ndarray:
    """u+ = u - M^-1 G^T (G M^-1 G^T)^-1 G u over the taut cables' rows G of g_dot (the
    velocities that keep those cables' lengths nearest to u in the kinetic-energy metric)."""
    u = _velocities(model, x)
    g = np.array([_g_dot(model, x, e) for e in np.eye(u.size)]).T[taut]  # g_dot is linear
    m_inv = np.linalg.inv(_mass_matrix(model, x))
    impulse = np.linalg.solve(g @ m_inv @ g.T, g @ u)
    return u - m_inv @ g.T @ impulse


def _momenta(model, x) -> tuple[np.ndarray, np.ndarray]:
    """Linear [kg m/s] and angular momentum about the origin [kg m^2/s], world: every body's
    translation, each UAV's spin R_i J_i omega_i and a rigid payload's R_p J_p omega_p."""
    layout = model.layout
    linear = (model.uav_masses @ layout.uav_velocities(x)
              + model.payload_mass * layout.payload_velocity(x))
    angular = model.payload_mass * np.cross(layout.payload_position(x), layout.payload_velocity(x))
    if layout.rigid_payload:
        angular = angular + _payload_rotation(layout.payload_quaternion(x)) @ (
            np.array(model.params.payload_inertia) * layout.payload_body_rates(x))
    for i in range(len(model.uav_masses)):
        omega = layout.uav_body_rates(x)[i]
        angular = angular + model.uav_masses[i] * np.cross(layout.uav_positions(x)[i],
                                                           layout.uav_velocities(x)[i])
        angular = angular + _payload_rotation(layout.uav_quaternions(x)[i]) @ (
            model.uav_inertia[i] * omega)
    return linear, angular


def _tumbling(model, x, seed: int) -> np.ndarray:
    """x with random velocities: every body moving and turning."""
    rng = np.random.default_rng(seed)
    layout = model.layout
    x = np.array(x)
    layout.rates(x)[:] = rng.normal(0.0, 0.5, layout.n_coordinates)
    layout.uav_body_rates(x)[:] = rng.normal(0.0, 0.5, (layout.n_uavs, 3))
    if model.layout.rigid_payload:
        model.layout.payload_body_rates(x)[:] = rng.normal(0.0, 0.5, 3)
    return x


# ------------------------------------------------------------------------------ the snap
@pytest.mark.parametrize('case', list(CASES))
def test_the_snap_is_the_inelastic_impulse_of_the_mass_metric(case):
    """At cables on their lengths and random velocities, the snap's velocity jump (for one
    cable taut, two, all four) is the projection written out above (numpy's dense M and G) to
    1e-12; it keeps the linear and angular momentum to 1e-12 (an internal impulse along each
    cable), adds no energy, and leaves every taut cable's g_dot at 0 (1e-12)."""
    model, x = _model(case)
    x = _tumbling(model, x, seed=11)
    energy = model.kinetic_energy(x)
    linear, angular = _momenta(model, x)
    for taut in ([True, False, False, False], [False, True, False, True], [True] * 4):
        taut = np.array(taut)
        after = model.snap_velocities(x, taut)
        assert np.abs(after[:model.layout.n_coordinates]
                      - x[:model.layout.n_coordinates]).max() == 0.0  # positions untouched
        expected = _inelastic_impulse(model, x, taut)
        assert np.abs(_velocities(model, after) - expected).max() < 1e-12
        linear_after, angular_after = _momenta(model, after)
        assert np.abs(linear_after - linear).max() < 1e-12
        assert np.abs(angular_after - angular).max() < 1e-12
        assert model.kinetic_energy(after) < energy
        _, g_dot = model.constraint_residuals(after)
        assert np.abs(g_dot[taut]).max() < 1e-12
        assert np.abs(g_dot[~taut]).min(initial=np.inf) > 1e-3  # the others keep their motion


@pytest.mark.parametrize('case', list(CASES))
def test_a_snap_projects_the_stretched_cable_onto_its_length(case):
    """`snap` at a cable about 1e-6 m^2 past its length (g) while another is taut: the
    positions moved in the mass metric (the bodies' attitudes too) put it on its length and
    keep the other's (|g| under 1e-12 m^2), the velocities give both g_dot = 0 (1e-12); the
    centre of mass stays; compiled and uncompiled give the same bits."""
    model, x = _model(case)
    x = _tumbling(model, x, seed=12)
    layout = model.layout
    layout.payload_position(x)[2] -= 1e-6 / (2 * 2.0)  # every cable ~1e-6 m^2 too long
    g0, _ = model.constraint_residuals(x)
    assert (g0 > 5e-7).all() and (g0 < 2e-6).all()
    results = []
    for function in (snap, kernels.uncompiled(snap)):
        state = x.copy()
        taut = np.array([False, True, False, False])
        snapping = np.array([True, False, False, False])
        # the other taut cable is held at its current g (the target of the projection)
        function(state, model._uavs, model._formation, taut, snapping,
                 np.empty((SLACK_CABLE_ROWS, 4)), np.empty((4, CABLE_COLUMNS)))
        results.append((state, taut))
    (state, taut), (state_python, taut_python) = results
    assert np.array_equal(state, state_python) and np.array_equal(taut, taut_python)
    assert taut.tolist() == [True, True, False, False]
    g, g_dot = model.constraint_residuals(state)
    assert abs(g[0]) < 1e-12 and abs(g[1] - g0[1]) < 1e-12
    assert np.abs(g_dot[:2]).max() < 1e-12
    masses = np.append(model.uav_masses, model.payload_mass)

    def centre(s):
        return masses @ np.vstack((layout.uav_positions(s), layout.payload_position(s)))
    assert np.abs(centre(state) - centre(x)).max() < 1e-12
    if layout.rigid_payload:
        assert abs(np.linalg.norm(layout.payload_quaternion(state)) - 1.0) < 1e-15


# ------------------------------------------------------- a free formation, slack and taut
def _flying_apart(model, x) -> np.ndarray:
    """Every cable slack (the UAVs 0.4 m lower, inside their cables' reach) and flying up and
    apart, the payload drifting and turning: the cables snap taut one after another."""
    rng = np.random.default_rng(5)
    layout = model.layout
    x = np.array(x)
    layout.uav_positions(x)[:, 2] -= 0.4
    layout.uav_velocities(x)[:] = rng.normal(0.0, 0.5, (4, 3)) + [0.0, 0.0, 0.6]
    layout.payload_velocity(x)[:] = [0.1, -0.2, 0.0]
    if layout.rigid_payload:
        layout.payload_body_rates(x)[:] = [0.3, -0.2, 0.5]
    if model.params.uav_attach_points:
        layout.uav_body_rates(x)[:] = rng.normal(0.0, 0.5, (4, 3))
    model.taut = False
    g, _ = model.constraint_residuals(x)
    assert g.max() < -0.5
    return x


@pytest.mark.parametrize('case', list(CASES))
def test_a_free_formation_on_slack_cables_loses_energy_only_at_the_snaps(case):
    """No gravity, rotors or drag; the cables start slack and the bodies fly apart (4 s in
    steps of 0.5 ms): the cables snap taut (at least 5 snaps) and go slack again (at least 2).
    Each step either keeps the energy (1e-11 relative: RK4's) or is a snap, which loses at
    least 1e-5 of it; between two snaps it stays within 1e-9 relative. The linear momentum
    is kept to 1e-12 throughout and the angular momentum to 1e-12 across each snap's step
    (to 1e-9 over the run: RK4 keeps it only to its order); each taut cable's |g| under 1e-9
    m^2 at every step's end."""
    model, x = _model(case)
    state = _flying_apart(model, x)
    start_linear, start_angular = _momenta(model, state)
    speeds = [np.zeros(4)] * 4
    energy = segment_start = model.kinetic_energy(state)
    snaps = slackened = 0
    for _ in range(8000):
        before, angular_before = model.taut.copy(), _momenta(model, state)[1]
        state = model.integrate(state, speeds, 5e-4, 1).state
        now = model.kinetic_energy(state)
        linear, angular = _momenta(model, state)
        slackened += int((before & ~model.taut).sum())
        assert now <= energy * (1.0 + 1e-11)
        if now < energy * (1.0 - 1e-11):  # a snap
            assert now < energy * (1.0 - 1e-5)
            assert np.abs(angular - angular_before).max() < 1e-12
            snaps += 1
            segment_start = now
        assert abs(now / segment_start - 1.0) < 1e-9
        assert np.abs(linear - start_linear).max() < 1e-12
        g, _ = model.constraint_residuals(state)
        assert np.abs(g[model.taut]).max(initial=0.0) < 1e-9
        assert (g[~model.taut] < 1e-9).all()  # a slack cable is not longer than its length
        energy = now
    print(f'{case}: {snaps} snaps, {slackened} slackenings, energy {energy:.4f} J, angular '
          f'momentum moved {np.abs(angular - start_angular).max():.1e}')
    assert snaps >= 5 and slackened >= 2
    assert np.abs(angular - start_angular).max() < 1e-9


@pytest.mark.parametrize('case', ['box', 'point_off_centre'])
def test_the_slack_period_with_a_snap_compiled_is_its_source_bit_for_bit(case):
    """The step in which the first cable snaps taut, through the slack period compiled and
    run by Python."""
    model, x = _model(case)
    state = _flying_apart(model, x)
    speeds = [np.zeros(4)] * 4
    while not model.taut.any():
        previous, taut = state, model.taut.copy()
        state = model.integrate(state, speeds, 5e-4, 1).state
    wrenches = np.zeros((4, 4))
    results = []
    for function in (slack_period, kernels.uncompiled(slack_period)):
        flags = taut.copy()
        out = function(previous, wrenches, model._uavs, model._gusts, model._formation, flags,
                       np.zeros(4, dtype=bool), 5e-4, 1)
        results.append((flags,) + tuple(out))
    assert results[0][0].any()
    assert all(np.array_equal(a, b) for a, b in zip(*results))
    assert np.array_equal(results[0][1], state)


def test_a_hanging_body_on_taut_slack_cables_flies_as_on_rigid_cables():
    """box_lift's box under its four UAVs, each rotor at the speed that carries its UAV and a
    quarter of the box, for 5 s: every cable stays taut, and the slack model's states are
    the rigid model's to 1e-9 m (the same arithmetic: they are equal to the bit)."""
    from multilift_control.headless import hover_speeds
    from multilift_sim.start import initial_state

    scenario = scenario_io.load('box_lift')
    slack, rigid = SlackCableModel(scenario.formation_params()), FormationModel(
        scenario.formation_params())
    x_slack = x_rigid = initial_state(scenario)
    speeds = hover_speeds(scenario)
    speeds[0] = speeds[0] * 1.002  # a little unbalanced: the formation moves and the box swings
    sim = scenario.simulation
    steps = sim.physics_steps_per_tick
    dt = 1.0 / sim.physics_rate
    for _ in range(round(5.0 / sim.control_period)):
        x_slack = slack.integrate(x_slack, speeds, dt, steps).state
        x_rigid = rigid.integrate(x_rigid, speeds, dt, steps).state
        assert slack.taut.all()
    assert np.abs(x_slack - x_rigid).max() < 1e-9
    assert np.array_equal(x_slack, x_rigid)
    assert np.abs(x_rigid - initial_state(scenario)).max() > 0.1  # it moved


# --------------------------------------------------------------------------- the scenario
def test_box_lift_flies_its_mission_on_slack_cables():
    """box_lift with `cable_model: slack` loads (and with cables off the UAVs' centres); the
    engine flies 40 s of the mission with |g| far inside eps_g, its cables taut throughout
    and the rigid cables' run to the bit; the engine and the per-object path (the ROS
    simulator's) to the bit."""
    from multilift_control.engine import Engine
    from multilift_control.headless import run_headless

    data = yaml.safe_load((SCENARIOS / 'box_lift.yaml').read_text())
    data['cable_model'] = 'slack'
    data['simulation']['duration'] = 40.0
    scenario = scenario_io.loads(yaml.safe_dump(data), 'box_lift_slack.yaml')
    assert scenario.cable_model == 'slack'
    rigid = scenario_io.load('box_lift').with_duration(40.0)
    engine = Engine([scenario, rigid])
    engine.step(10 ** 6)
    assert engine.finished.all() and not engine.stopped.any()
    summary = engine.summary(0)
    assert summary['sim']['max_abs_constraint'] < 1e-6
    assert max(summary['sim']['slack_time']) == 0.0
    assert np.array_equal(engine.state[0], engine.state[1])
    short = scenario.with_duration(1.5)
    engine = Engine(short)
    engine.step(10 ** 6)
    assert np.array_equal(engine.state[0], run_headless(short).simulator.state)
    data['uavs'][0]['attach_point'] = [0.0, 0.0, -0.1]
    assert scenario_io.loads(yaml.safe_dump(data)).uavs[0].attach_point == (0.0, 0.0, -0.1)
