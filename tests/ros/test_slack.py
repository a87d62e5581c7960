"""Slack cables (`cable_model: slack`, multilift_sim.slack): taut = the seed's constraint, slack
= free motion, snap = an inelastic, momentum-conserving velocity jump (issue 12 item 3)."""
from __future__ import annotations

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import hover_speeds, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator


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
    n, nq = 2, 6 * 2 + 3
    rng = np.random.default_rng(3)
    x[nq:] += rng.normal(0.0, 1.0, nq)  # random velocities, cables at their length
    masses = np.array([u.vehicle.mass for u in scenario.uavs] + [scenario.payload.mass])

    def momentum(state):
        v = np.vstack([state[nq + 6 * i:nq + 6 * i + 3] for i in range(n)]
                      + [state[nq + 6 * n:]])
        return masses @ v

    for taut in ([True, False], [True, True]):
        after = model.snap_velocities(x, np.array(taut))
        assert momentum(after) == pytest.approx(momentum(x), abs=1e-12)
        assert model.kinetic_energy(after) <= model.kinetic_energy(x) + 1e-12
        _, g_dot = model.constraint_residuals(after)
        assert np.abs(g_dot[np.array(taut)]).max() < 1e-12


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
