"""Steady wind on the UAVs and the payload (issue 21 item 3): each body's quadratic drag against
the air, `vehicle.drag_coefficient` and the payload's c_pd (seed Eq. 2.53), with `wind.velocity`
everywhere. Held against the momentum balance (the cables' pulls are internal: the formation's
momentum changes by gravity, thrust and the two drags alone), the engine against the per-object
(ROS) path to the bit, a formation trailing its payload downwind, and the keys' validation."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.engine import Engine
from multilift_control.headless import run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import StateLayout
from multilift_sim.start import initial_state

WIND = (3.0, -1.0, 0.5)  # [m/s], world


def _windy(name: str, wind=WIND, uav_drag: float = 0.08, **top) -> scenario_io.Scenario:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['wind'] = {'velocity': list(wind)}
    data['vehicle']['drag_coefficient'] = uav_drag
    data.update(top)
    return scenario_io.loads(yaml.safe_dump(data))


def test_the_formation_s_momentum_changes_by_the_external_forces_alone():
    """At any state: sum m_i a_i + m_p a_p = thrusts + gravity + every body's drag
    -c |v - w| (v - w); the cable multipliers cancel (the slack twin with some cables taut,
    some moving bodies)."""
    scenario = _windy('twin_lift')
    model = FormationModel(scenario.formation_params())
    x = initial_state(scenario)
    rng = np.random.default_rng(5)
    layout = model.layout
    layout.uav_velocities(x)[:] = rng.normal(size=(2, 3))
    layout.payload_velocity(x)[:] = rng.normal(size=3)
    speeds = [np.full(4, 1500.0), np.array([1400.0, 1550.0, 1500.0, 1450.0])]
    acc, _ = model.accelerations(0.0, x, speeds)
    masses = model.uav_masses
    uav_acc = layout.uav_positions(acc)
    rate = masses @ uav_acc + model.payload_mass * layout.payload_position(acc)
    wrenches = model.wrenches(speeds)
    wind = np.array(WIND)
    expected = -(masses.sum() + model.payload_mass) * np.array([0.0, 0.0, 9.81])
    for i in range(2):
        phi, theta, psi = layout.uav_euler(x)[i]
        # R e_z of ZYX Euler angles: the body z axis in the world
        body_z = np.array([np.cos(psi) * np.sin(theta) * np.cos(phi) + np.sin(psi) * np.sin(phi),
                           np.sin(psi) * np.sin(theta) * np.cos(phi) - np.cos(psi) * np.sin(phi),
                           np.cos(theta) * np.cos(phi)])
        relative = layout.uav_velocities(x)[i] - wind
        expected += wrenches[i, 0] * body_z - 0.08 * np.linalg.norm(relative) * relative
    relative = layout.payload_velocity(x) - wind  # the payload (no gust at the start place)
    expected -= scenario.payload.drag_coefficient * np.linalg.norm(relative) * relative
    assert rate == pytest.approx(expected, rel=1e-12, abs=1e-12)
    calm = FormationModel(scenario_io.load('twin_lift').formation_params())
    calm_acc, _ = calm.accelerations(0.0, x, speeds)
    assert np.abs(calm_acc - acc).max() > 0.01  # the wind did something


@pytest.mark.parametrize('cables', ['rigid', 'slack'])
def test_the_engine_flies_the_wind_as_the_ros_path_does(cables):
    scenario = dataclasses.replace(_windy('multi_lift'), cable_model=cables).with_duration(10.0)
    engine = Engine(scenario)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert engine.finished[0]
    assert np.array_equal(engine.state[0], run.simulator.state)


def test_a_twin_lift_in_the_wind_trails_its_payload_downwind():
    """30 s of the twin's mission in a 3 m/s wind along +x: the formation holds (max |g| under
    the tolerance) and the payload hangs downwind of where it hangs in still air."""
    windy = _windy('twin_lift', wind=(3.0, 0.0, 0.0)).with_duration(30.0)
    still = scenario_io.load('twin_lift').with_duration(30.0)
    places = []
    for scenario in (windy, still):
        engine = Engine(scenario)
        record = engine.new_record(3000)
        engine.step(3000, record)
        assert engine.summary(0)['sim']['max_abs_constraint'] < \
            scenario.simulation.constraint_tolerance
        states = record.states[:, 0]
        layout = StateLayout(2)
        places.append(layout.payload_position(states)
                      - layout.uav_positions(states).mean(axis=1))
    trail = places[0][1000:, 0] - places[1][1000:, 0]  # from 10 s on, along the wind
    assert trail.mean() > 0.05


@pytest.mark.parametrize('edit,message', [
    (lambda d: d.update(wind={'velocity': [1.0, 2.0]}), 'wind.velocity'),
    (lambda d: d.update(wind={'speed': 3.0}), 'wind.speed: unknown key'),
    (lambda d: d['vehicle'].update(drag_coefficient=-0.1), 'vehicle.drag_coefficient'),
    (lambda d: (d.update(wind={'velocity': [1.0, 0.0, 0.0]}),
                d['simulation'].update(integrator='nullspace')),
     'need simulation.integrator: baumgarte')])
def test_wind_keys_are_validated(edit, message):
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    edit(data)
    with pytest.raises(scenario_io.ScenarioError, match=message):
        scenario_io.loads(yaml.safe_dump(data), 'x.yaml')
    assert scenario_io.load('twin_lift').wind == (0.0, 0.0, 0.0)


def test_dryden_turbulence_flies_alike_in_both_paths_and_bags():
    """`wind.turbulence`: the engine and the per-object path to the bit; the two headless bags
    (engine-flown and per-object) alike to the byte; a seed makes the series, another seed
    another flight."""
    import tempfile
    from pathlib import Path

    from multilift_sim.schedules import wind_series
    from multilift_tools.headless_bag import _record_per_object, record_headless

    def gusty(seed: int) -> scenario_io.Scenario:
        data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
        data['simulation']['duration'] = 3.0
        data['wind'] = {'velocity': [2.0, 0.0, 0.0], 'turbulence': {
            'intensity': [1.0, 1.0, 0.5], 'length_scale': [20.0, 10.0, 5.0], 'airspeed': 5.0,
            'seed': seed}}
        data['vehicle']['drag_coefficient'] = 0.08
        return scenario_io.loads(yaml.safe_dump(data))
    scenario = gusty(1)
    series = wind_series(scenario)
    assert series.shape == (301, 3) and series.std() > 0.1
    engine = Engine(scenario)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert np.array_equal(engine.state[0], run.simulator.state)
    other = Engine(gusty(2))
    other.step(10 ** 6)
    assert not np.array_equal(other.state[0], engine.state[0])
    with tempfile.TemporaryDirectory() as tmp:
        record_headless(scenario, Path(tmp) / 'engine' / 'bag')
        _record_per_object(scenario, Path(tmp) / 'objects' / 'bag')
        assert (Path(tmp) / 'engine' / 'bag' / 'bag_0.mcap').read_bytes() == \
            (Path(tmp) / 'objects' / 'bag' / 'bag_0.mcap').read_bytes()


def test_a_gust_s_period_means_carry_its_whole_impulse():
    """gust_profile_mean: 0 outside the gust, the 1-cosine's peak 1 at its middle, and over any
    periods covering it the means sum to D / 2 per period (the profile's integral, in closed
    form: the wind's impulse over the gust is exact however the periods cut it)."""
    from multilift_sim.events.gust import profile_mean as gust_profile_mean

    period, onset, duration = 0.01, 1.234, 2.5
    starts = np.arange(0, 500) * period
    means = gust_profile_mean(starts, period, onset, duration)
    assert np.abs(means.sum() * period - duration / 2).max() < 1e-12
    assert means[:123].tolist() == [0.0] * 123 and means[374:].tolist() == [0.0] * 126
    middle = int((onset + duration / 2) / period)
    assert abs(means[middle] - 1.0) < 1e-3
    # a coarse grid (periods longer than the gust) still carries all of it
    coarse = gust_profile_mean(np.arange(0, 5) * 1.0, 1.0, onset, duration)
    assert abs(coarse.sum() - duration / 2) < 1e-12


def test_a_gust_event_blows_through_the_formation_alike_in_both_paths():
    """`events: [{type: gust, ...}]`: nothing changes before its onset; the payload and the
    UAVs (with drag) are pushed downwind; the engine and the per-object path to the bit; the
    event is named in the summary; validation names a zero gust."""
    def gusty(**gust) -> scenario_io.Scenario:
        data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
        data['simulation']['duration'] = 6.0
        data['vehicle']['drag_coefficient'] = 0.08
        data['events'] = [{'time': 2.0, 'type': 'gust', 'velocity': [0.0, 6.0, 0.0],
                           'duration': 2.0, **gust}]
        return scenario_io.loads(yaml.safe_dump(data))
    scenario = gusty()
    calm = dataclasses.replace(scenario, events=())
    engine, still = Engine(scenario), Engine(calm)
    record, still_record = engine.new_record(600), still.new_record(600)
    engine.step(600, record)
    still.step(600, still_record)
    assert np.array_equal(record.states[:201], still_record.states[:201])
    layout = StateLayout(2)
    payload_y = (layout.payload_position(record.states[:, 0])[:, 1]
                 - layout.payload_position(still_record.states[:, 0])[:, 1])
    assert payload_y[400] > 0.05  # pushed along +y by the end of the gust
    run = run_headless(scenario)
    assert np.array_equal(engine.state[0], run.simulator.state)
    events = run.summary()['sim']['events']
    assert events == engine.summary(0)['sim']['events']
    assert events[0]['type'] == 'gust' and events[0]['uav'] == 0
    assert events[0]['description'] == 'gust of 6 m/s (0, 6, 0) for 2 s (1-cosine)'
    with pytest.raises(scenario_io.ScenarioError, match='velocity.*must not be zero'):
        gusty(velocity=[0.0, 0.0, 0.0])
    with pytest.raises(scenario_io.ScenarioError, match='uav: unknown key'):
        gusty(uav=1)


def test_the_wind_is_on_a_topic_where_the_air_moves_everywhere(tmp_path):
    """/formation/wind (geometry_msgs/Vector3Stamped) in a run with a steady wind and a gust
    event: at every tick the steady wind plus the gust's mean over the period from it; the
    engine's bag and the per-object path's alike to the byte; none in a still-air run."""
    from rosbags.highlevel import AnyReader

    from multilift_sim.events.gust import profile_mean as gust_profile_mean
    from multilift_sim.topics import WIND, scenario_topics
    from multilift_tools.headless_bag import _record_per_object, record_headless

    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    data['simulation']['duration'] = 2.0
    data['wind'] = {'velocity': [1.0, 0.0, 0.0]}
    data['events'] = [{'time': 0.5, 'type': 'gust', 'velocity': [0.0, 3.0, 0.0],
                       'duration': 1.0}]
    scenario = scenario_io.loads(yaml.safe_dump(data))
    assert scenario.has_wind and (WIND, 'geometry_msgs/msg/Vector3Stamped') in \
        scenario_topics(scenario)
    assert WIND not in dict(scenario_topics(scenario_io.load('twin_lift')))
    record_headless(scenario, tmp_path / 'engine' / 'bag')
    _record_per_object(scenario, tmp_path / 'objects' / 'bag')
    assert (tmp_path / 'engine' / 'bag' / 'bag_0.mcap').read_bytes() == \
        (tmp_path / 'objects' / 'bag' / 'bag_0.mcap').read_bytes()
    with AnyReader([tmp_path / 'engine' / 'bag']) as reader:
        wanted = [c for c in reader.connections if c.topic == WIND]
        winds = np.array([[m.vector.x, m.vector.y, m.vector.z] for m in (
            reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(wanted))])
    assert winds.shape == (201, 3)
    expected_y = 3.0 * gust_profile_mean(np.arange(201) * 0.01, 0.01, 0.5, 1.0)
    assert np.array_equal(winds[:, 0], np.ones(201)) and np.array_equal(winds[:, 2],
                                                                        np.zeros(201))
    assert np.abs(winds[:, 1] - expected_y).max() < 1e-12 and winds[:, 1].max() > 2.99


def test_the_wind_of_a_period_is_composed_in_one_place():
    """physics.tick.period_wind (what the physics, FormationSimulator.wind and the bags'
    /formation/wind read): the steady wind plus the tick's unsteady wind, compiled and not to
    the bit; the steady wind as it is where the air is steady; `period_winds` every tick's."""
    from multilift_sim import kernels
    from multilift_sim.physics.layout import FORMATION_SCALARS, FORMATION_WIND
    from multilift_sim.physics.tick import period_wind, period_winds

    formation = np.zeros(FORMATION_SCALARS)
    formation[FORMATION_WIND:FORMATION_WIND + 3] = WIND
    series = np.random.default_rng(3).normal(size=(6, 3))
    for function in (period_wind, kernels.uncompiled(period_wind)):
        out = np.empty(3)
        for tick in range(6):
            function(formation, series, tick, out)
            assert np.array_equal(out, np.array(WIND) + series[tick])
        function(formation, np.zeros((0, 3)), 4, out)
        assert tuple(out) == WIND
    table = np.empty((6, 3))
    period_winds(formation, series, table)
    assert np.array_equal(table, np.array(WIND) + series)
