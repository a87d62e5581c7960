"""Slack cables (`cable_model: slack`, multilift_sim.slack): taut = the seed's constraint, slack
= free motion, snap = an inelastic, momentum-conserving velocity jump (issue 12 item 3) located
within the RK4 step, so that a cable never stretches past its length ("One engine" item 6)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import hover_speeds, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator
from multilift_sim.slack import SlackCableModel


def _edited(name: str, **top) -> scenario_io.Scenario:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    for key, value in top.items():
        section, _, leaf = key.rpartition('.')
        (data[section] if section else data)[leaf] = value
    return scenario_io.loads(yaml.safe_dump(data), f'{name}.yaml')


def test_payload_released_above_its_uav_falls_freely_then_snaps_taut():
    scenario = _edited('single_lift_swing', cable_model='slack', **{
        'payload.alpha_deg': 150.0, 'payload.drag_coefficient': 0.0,
        'simulation.duration': 3.0})
    sim = FormationSimulator(scenario)
    speeds = hover_speeds(scenario)
    g = scenario.simulation.gravity
    velocities, slack_ticks = [], 0
    while not sim.finished:
        taut = sim.taut
        velocities.append(sim.snapshot().payload_velocity)
        sim.advance(speeds, [np.zeros(4, bool)])
        if not taut[0] and not sim.taut[0]:  # slack over the whole tick: free fall
            dv = sim.snapshot().payload_velocity - velocities[-1]
            assert dv / scenario.simulation.control_period == pytest.approx([0, 0, -g],
                                                                          abs=1e-9)
            slack_ticks += 1
    assert slack_ticks > 10
    # the run statistics count the slack time (at least the whole-tick free fall seen here)
    period = scenario.simulation.control_period
    assert sim.stats.slack_time[0] >= slack_ticks * period - 1e-9
    assert sim.stats.slack_time[0] < scenario.simulation.duration
    assert sim.taut[0]  # it fell below the UAV and snapped taut
    g_now, _ = sim.model.constraint_residuals(sim.state)
    assert abs(g_now[0]) < scenario.simulation.constraint_tolerance


def test_snap_keeps_momentum_and_does_not_add_energy():
    scenario = _edited('twin_lift', cable_model='slack')
    sim = FormationSimulator(scenario)
    model = sim.model
    x = sim.state.copy()
    layout = model.layout
    rng = np.random.default_rng(3)
    layout.rates(x)[:] += rng.normal(0.0, 1.0, layout.n_coordinates)  # cables at their length
    layout.uav_body_rates(x)[:] += rng.normal(0.0, 1.0, (2, 3))
    masses = np.array([u.vehicle.mass for u in scenario.uavs] + [scenario.payload.mass])

    def momentum(state):
        v = np.vstack([layout.uav_velocities(state), layout.payload_velocity(state)])
        return masses @ v

    for taut in ([True, False], [True, True]):
        after = model.snap_velocities(x, np.array(taut))
        assert momentum(after) == pytest.approx(momentum(x), abs=1e-12)
        assert model.kinetic_energy(after) <= model.kinetic_energy(x) + 1e-12
        _, g_dot = model.constraint_residuals(after)
        assert np.abs(g_dot[np.array(taut)]).max() < 1e-12


def _stretch(model, x) -> np.ndarray:
    """|r_p - r_i| - l_i [m] per cable, from the positions (not from the model's g)."""
    offsets = model.layout.payload_position(x) - model.layout.uav_positions(x)
    return np.linalg.norm(offsets, axis=1) - model.cable_lengths


def test_a_falling_payload_stops_at_its_cable_length():
    # the situation that stretched the cable 3.7 mm past l = 2.5 m when the snap was only
    # looked for at the ends of the RK4 steps: the payload released above its UAV falls, the
    # UAV climbs, the cable snaps taut at t = 0.8305 s, inside the step ending at 0.831 s
    scenario = _edited('single_lift_swing', cable_model='slack', **{
        'payload.alpha_deg': 150.0, 'payload.drag_coefficient': 0.0,
        'simulation.duration': 3.0})
    sim = FormationSimulator(scenario)
    model, x, dt = sim.model, sim.state.copy(), sim.dt
    speeds = hover_speeds(scenario)
    stretch, snapped_at = [], None
    for k in range(round(scenario.simulation.duration / dt)):  # every physics step
        was_taut = model.taut[0]
        x = model.integrate(x, speeds, dt, 1).state
        stretch.append(_stretch(model, x)[0])
        if snapped_at is None and k and not was_taut and model.taut[0]:
            snapped_at = (k + 1) * dt
    print(f'max stretch {max(stretch):.2e} m, snapped in the step ending at {snapped_at:.3f} s')
    assert snapped_at == pytest.approx(0.831)
    assert model.taut[0] and max(stretch) < 1e-6


def test_a_snap_in_free_space_is_the_inelastic_collision_at_the_cable_length():
    # no gravity, rotors off: UAV and payload fly apart in straight lines until the cable is
    # at its length, then (a perfectly inelastic collision along the cable) the pair turns as
    # a rigid dumbbell about its centre of mass; all of it in closed form
    scenario = _edited('single_lift_swing', cable_model='slack')
    model = SlackCableModel(dataclasses.replace(scenario.formation_params(), gravity=0.0))
    length, m_uav, m_p = model.cable_lengths[0], model.uav_masses[0], model.payload_mass
    total, reduced = m_uav + m_p, m_uav * m_p / (m_uav + m_p)
    r_uav, v_uav = np.array([0.2, -0.1, 3.0]), np.array([-0.4, 0.3, 0.1])
    r_p, v_p = r_uav + np.array([0.3, -0.2, -0.5]), np.array([2.0, 0.7, -1.5])
    x = model.layout.pack([r_uav], [np.zeros(3)], r_p, [v_uav], None, v_p)
    d0, w0 = r_p - r_uav, v_p - v_uav
    # |d0 + w0 t| = l
    a, b, c = w0 @ w0, 2.0 * d0 @ w0, d0 @ d0 - length ** 2
    t_snap = (-b + np.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)
    e = (d0 + w0 * t_snap) / length
    tangential = w0 - (w0 @ e) * e
    rate = np.linalg.norm(tangential) / length
    centre_r, centre_v = (m_uav * r_uav + m_p * r_p) / total, (m_uav * v_uav + m_p * v_p) / total

    def velocities(state):
        return model.layout.uav_velocities(state)[0], model.layout.payload_velocity(state)

    def momentum(state):
        v_uav, v_p = velocities(state)
        return m_uav * v_uav + m_p * v_p

    def kinetic_energy(state):  # translational only: the UAV does not turn (no torque)
        v_uav, v_p = velocities(state)
        return 0.5 * (m_uav * v_uav @ v_uav + m_p * v_p @ v_p)

    model.taut[:] = False  # shorter than its length: slack
    dt, speeds = 1e-3, [np.zeros(4)]
    p0, e0 = momentum(x), kinetic_energy(x)
    assert 0.3 < t_snap < 1.0 and (t_snap / dt) % 1.0 > 0.1  # within a step, not at its end
    position_error, stretch = 0.0, []
    for k in range(2000):
        x = model.integrate(x, speeds, dt, 1).state
        t = (k + 1) * dt
        stretch.append(_stretch(model, x)[0])
        assert momentum(x) == pytest.approx(p0, abs=1e-12)
        if t < t_snap:
            assert not model.taut[0]
            assert kinetic_energy(x) == pytest.approx(e0, abs=1e-12)
            continue
        assert model.taut[0]
        s = t - t_snap
        d = length * (np.cos(rate * s) * e + np.sin(rate * s) * tangential / (rate * length))
        centre = centre_r + centre_v * t
        position_error = max(position_error,
                             np.abs(model.layout.payload_position(x) - centre
                                    - m_uav / total * d).max(),
                             np.abs(model.layout.uav_positions(x)[0] - centre
                                    + m_p / total * d).max())
    loss = e0 - kinetic_energy(x)
    print(f'snap at {t_snap:.6f} s; after it, max distance from the closed form '
          f'{position_error:.1e} m; kinetic energy lost {loss:.9f} J; max stretch '
          f'{max(stretch):.1e} m')
    # the energy the collision takes: the relative velocity along the cable, 1/2 mu (w.e)^2
    assert loss == pytest.approx(0.5 * reduced * (w0 @ e) ** 2, rel=1e-9)
    assert position_error < 1e-8
    assert max(stretch) < 1e-6


def test_a_cable_at_its_length_for_an_instant_within_a_step_snaps_there():
    # no gravity; the payload 0.1 um inside the cable's length right above its UAV, rising away
    # at 3 mm/s, while the UAV's thrust brings it up at a: the cable reaches l at t_snap =
    # 36 us and would be back inside it before the step ends (1 ms), so neither end of the step
    # sees it; located, the snap takes the relative velocity, and the UAV then closes in
    scenario = _edited('single_lift_swing', cable_model='slack')
    model = SlackCableModel(dataclasses.replace(scenario.formation_params(), gravity=0.0))
    length, m_uav, m_p = model.cable_lengths[0], model.uav_masses[0], model.payload_mass
    speeds = [np.full(4, 2000.0)]
    a = model.wrenches(speeds)[0, 0] / m_uav  # the UAV's acceleration, up (level, no torque)
    gap, v, dt = 1e-7, 3e-3, 1e-3
    x = model.layout.pack([np.zeros(3)], [np.zeros(3)], (0.0, 0.0, length - gap), None, None,
                          (0.0, 0.0, v))
    model.taut[:] = False
    # the separation l - gap + v t - a t^2 / 2 reaches l at
    t_snap = (v - np.sqrt(v * v - 2.0 * a * gap)) / a
    assert 0.0 < t_snap < v / a < dt and v * dt - 0.5 * a * dt * dt < gap  # out and back
    x = model.integrate(x, speeds, dt, 1).state
    # the snap leaves both at their common velocity (momentum kept); then the UAV accelerates
    common = (m_uav * a * t_snap + m_p * v) / (m_uav + m_p)
    left = dt - t_snap
    # (to the event's location: |g| <= 1e-12 l^2, a few ns at this separation rate)
    assert model.layout.payload_velocity(x) == pytest.approx([0, 0, common], abs=1e-9)
    assert model.layout.uav_velocities(x)[0] == pytest.approx([0, 0, common + a * left],
                                                              abs=1e-9)
    assert _stretch(model, x)[0] == pytest.approx(-0.5 * a * left ** 2, abs=1e-11)
    assert not model.taut[0]  # taut for an instant: the UAV closing in slackens it again


def test_snaps_of_a_twin_lift_keep_momentum_and_lose_energy():
    # no gravity, no drag, rotors off, both cables 0.5 m slack, the UAVs flying apart: one
    # cable snaps taut, then the other while the first is taut (1.275 s, 1.307 s)
    scenario = _edited('twin_lift', cable_model='slack')
    model = SlackCableModel(dataclasses.replace(scenario.formation_params(), gravity=0.0,
                                                payload_drag_coefficient=0.0))
    layout = model.layout
    x = FormationSimulator(scenario).state.copy()
    rng = np.random.default_rng(1)
    uavs = layout.uav_positions(x)
    apart = (uavs[1] - uavs[0]) / np.linalg.norm(uavs[1] - uavs[0])
    layout.payload_position(x)[:] += (0.0, 0.0, 0.5)
    layout.uav_velocities(x)[:] = np.outer((-1.5, 1.5), apart) + rng.normal(0.0, 0.5, (2, 3))
    layout.payload_velocity(x)[:] = rng.normal(0.0, 1.0, 3)
    masses = np.append(model.uav_masses, model.payload_mass)

    def momentum(state):
        return masses @ np.vstack([layout.uav_velocities(state), layout.payload_velocity(state)])

    def kinetic_energy(state):  # translational only: the UAVs do not turn (no torque)
        v = np.vstack([layout.uav_velocities(state), layout.payload_velocity(state)])
        return 0.5 * masses @ np.einsum('ij,ij->i', v, v)

    assert (_stretch(model, x) < -0.2).all()
    model.taut[:] = False  # shorter than their lengths: slack
    dt, speeds = 1e-3, [np.zeros(4)] * 2
    p0, e0 = momentum(x), kinetic_energy(x)
    energy, stretch, snaps, taut = e0, [], [], model.taut.copy()
    for k in range(1500):
        x = model.integrate(x, speeds, dt, 1).state
        if (model.taut & ~taut).any():
            snaps.append(((k + 1) * dt, energy - kinetic_energy(x)))
        taut = model.taut.copy()
        stretch.append(_stretch(model, x).max())
        assert momentum(x) == pytest.approx(p0, abs=1e-12)
        assert kinetic_energy(x) <= energy + 1e-12
        energy = kinetic_energy(x)
    print('snaps (end of the step [s], kinetic energy lost in it [J]): '
          + ', '.join(f'({t:.3f}, {loss:.2e})' for t, loss in snaps)
          + f'; max stretch {max(stretch):.1e} m')
    assert [t for t, _ in snaps] == pytest.approx([1.275, 1.307])
    assert all(loss > 1e-6 for _, loss in snaps) and model.taut.all()
    assert max(stretch) < 1e-6


@pytest.fixture(scope='module')
def twin_runs():
    runs = {}
    for model in ('rigid', 'slack'):
        scenario = _edited('twin_lift', cable_model=model)
        taut = []
        run = run_headless(scenario, lambda sim, snap, answers: taut.append(sim.taut))
        runs[model] = (run, np.array(taut))
    return runs


def test_twin_lift_flies_with_slack_cables(twin_runs):
    run, taut = twin_runs['slack']
    stats = run.simulator.stats
    print(f'twin_lift, slack cables: taut {100 * taut.mean():.1f} % of the ticks, tension '
          f'{stats.min_tension:.2f} .. {stats.max_tension:.2f} N')
    assert run.error is None and run.simulator.finished
    assert stats.min_tension >= 0.0


def test_a_mission_that_stays_taut_is_the_rigid_one(twin_runs):
    rigid, _ = twin_runs['rigid']
    slack, taut = twin_runs['slack']
    assert taut.all()  # the seed's mission never slackens a cable (min tension > 0)
    assert np.abs(rigid.simulator.state - slack.simulator.state).max() < 1e-6


def test_rigid_is_the_default_and_slack_needs_baumgarte():
    assert scenario_io.load('twin_lift').cable_model == 'rigid'
    with pytest.raises(scenario_io.ScenarioError, match='cable_model'):
        _edited('twin_lift', cable_model='rope')
    with pytest.raises(scenario_io.ScenarioError, match='needs simulation.integrator'):
        _edited('twin_lift', cable_model='slack', **{'simulation.integrator': 'nullspace'})
    with pytest.raises(scenario_io.ScenarioError, match='needs cable_model: slack'):
        _edited('single_lift_swing', **{'payload.alpha_deg': 120.0})
