"""A scenario's events (`events:`, multilift_sim.physics.events, issue 21 item 4): validated
at load; applied at their tick, the same in the engine and the per-object (ROS) path to the
bit; a released cable lets go without doing work: energy and momentum of a free formation
continue through the release, the released UAV flies on as a free body and never snaps taut
again, the other cables hold."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.engine import Engine
from multilift_control.headless import run_headless
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.physics.events import apply_events
from multilift_sim.physics.layout import REEL_COLUMNS
from multilift_sim.start import initial_state
from multilift_sim.schedules import event_array
from multilift_sim.slack import SlackCableModel
from multilift_sim.dynamics import FormationModel


def _edited(name: str, edit) -> str:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    edit(data)
    return yaml.safe_dump(data)


def _with_events(name: str, duration: float, events: list[dict], **top) -> scenario_io.Scenario:
    def edit(data):
        data['simulation']['duration'] = duration
        data['events'] = events
        data.update(top)
    return scenario_io.loads(_edited(name, edit))


def test_events_load_in_time_order_at_their_ticks():
    scenario = _with_events('multi_lift', 10.0, [
        {'time': 6.005, 'type': 'cable_release', 'uav': 3},
        {'time': 2.0, 'type': 'rotor_effectiveness', 'uav': 2, 'rotor': 4,
         'effectiveness': 0.25}])
    assert [e.type for e in scenario.events] == ['rotor_effectiveness', 'cable_release']
    rows = event_array(scenario)
    # the first control tick (100 Hz) at or after each time; UAVs and rotors from 0
    assert rows[:, :7].tolist() == [[200.0, 2.0, 0.0, 1.0, 3.0, 0.25, 0.0],
                                    [601.0, 6.005, 1.0, 2.0, 0.0, 1.0, 0.0]]
    assert not rows[:, 7:].any()  # a gust's columns
    assert scenario_io.load('multi_lift').events == ()  # the shipped scenarios have none


@pytest.mark.parametrize('event,message', [
    ({'time': 10.0, 'type': 'cable_release', 'uav': 2}, r"events\[0\]\.time: 10\.0 must be"),
    ({'time': 1.0, 'type': 'cable_cut', 'uav': 2}, 'events.0..type.*must be one of'),
    ({'time': 1.0, 'type': 'cable_release', 'uav': 4}, r'uav: 4 must be a UAV from 1 to 3'),
    ({'time': 1.0, 'type': 'cable_release', 'uav': 1.0}, r'uav: 1\.0 must be a UAV'),
    ({'time': 1.0, 'type': 'rotor_effectiveness', 'uav': 1, 'rotor': 5,
      'effectiveness': 0.0}, 'rotor: 5 must be a rotor of uav1, from 1 to 4'),
    ({'time': 1.0, 'type': 'rotor_effectiveness', 'uav': 1, 'rotor': 1,
      'effectiveness': 1.5}, r'effectiveness: 1\.5 must be within \[0, 1\]'),
    ({'time': 1.0, 'type': 'cable_release', 'uav': 2, 'rotor': 1}, 'rotor: unknown key'),
    ({'time': 1.0, 'type': 'rotor_effectiveness', 'uav': 1}, 'rotor'),
    ({'time': 1.0, 'type': 'controller_silence', 'uav': 2, 'duration': 0.0},
     r'duration: 0\.0 must be > 0')])
def test_bad_events_name_key_and_rule(event, message):
    with pytest.raises(scenario_io.ScenarioError, match=message):
        _with_events('multi_lift', 10.0, [event])


def test_the_last_cable_and_a_second_release_are_refused():
    release = [{'time': 1.0, 'type': 'cable_release', 'uav': uav} for uav in (1, 2)]
    with pytest.raises(scenario_io.ScenarioError, match='the last cable holding the payload'):
        _with_events('twin_lift', 10.0, release)
    with pytest.raises(scenario_io.ScenarioError, match='has let go of its cable already'):
        _with_events('twin_lift', 10.0, release[:1] * 2)
    with pytest.raises(scenario_io.ScenarioError, match='events need simulation.integrator'):
        _with_events('twin_lift', 10.0, release[:1], simulation={
            **yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())['simulation'],
            'duration': 10.0, 'integrator': 'nullspace'})


@pytest.mark.parametrize('cables', ['rigid', 'slack'])
def test_events_fly_the_same_in_the_engine_and_the_ros_path(cables):
    events = [{'time': 1.5, 'type': 'rotor_effectiveness', 'uav': 2, 'rotor': 1,
               'effectiveness': 0.7},
              {'time': 3.0, 'type': 'cable_release', 'uav': 3}]
    scenario = _with_events('multi_lift', 6.0, events, cable_model=cables)
    quiet = dataclasses.replace(scenario, events=())
    engine, before = Engine(scenario), Engine(quiet)
    record, quiet_record = engine.new_record(600), before.new_record(600)
    engine.step(600, record)
    before.step(600, quiet_record)
    run = run_headless(scenario)
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert np.array_equal(engine.memory.taut[0], run.simulator.taut)
    assert engine.memory.released[0].tolist() == [False, False, True]
    assert engine.memory.effectiveness[0, 1].tolist() == [0.7, 1.0, 1.0, 1.0]
    # nothing changes before the first event's tick (150), everything after it
    assert np.array_equal(record.states[:151], quiet_record.states[:151])
    assert not np.array_equal(record.states[152], quiet_record.states[152])
    # the released cable is slack from the state at tick 300 on, and pulls no more
    assert record.taut[299, 0, 2] and not record.taut[300:, 0, 2].any()
    assert record.tension[299, 0, 2] > 1.0 and record.tension[300:, 0, 2].tolist() == [0.0] * 300
    assert engine.summary(0)['sim']['max_abs_constraint'] < 1e-6  # the others hold


def _free_twin_lift(model_class):
    """A twin-lift without gravity, drag or rotors, everything moving at 0.4 m/s along x and
    the payload swinging out of the UAVs-payload plane at 1.5 m/s (g_dot = 0 on both
    cables): no external force, so momentum and energy are constants."""
    base = scenario_io.load('twin_lift')
    scenario = dataclasses.replace(
        base, gusts=(), payload=dataclasses.replace(base.payload, drag_coefficient=0.0,
                                                    swing=0.0),
        simulation=dataclasses.replace(base.simulation, gravity=0.0))
    model = model_class(scenario.formation_params())
    x = initial_state(scenario)
    layout = model.layout
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    normal = np.cross(payload - uavs[0], payload - uavs[1])
    drift = np.array([0.4, 0.0, 0.0])
    layout.uav_velocities(x)[:] = drift
    layout.payload_velocity(x)[:] = drift + 1.5 * normal / np.linalg.norm(normal)
    return scenario, model, x


def _momentum(model, x):
    layout = model.layout
    return (model.uav_masses @ layout.uav_velocities(x)
            + model.payload_mass * layout.payload_velocity(x))


@pytest.mark.parametrize('model_class', [FormationModel, SlackCableModel])
def test_a_release_does_no_work_and_the_free_uav_flies_on(model_class):
    scenario, model, x = _free_twin_lift(model_class)
    events = event_array(dataclasses.replace(scenario, events=(
        scenario_io.EventConfig(time=0.5, type='cable_release', uav=2),)))
    energy, momentum = model.kinetic_energy(x), _momentum(model, x)
    idle, next_event = [np.zeros(4)] * 2, 0
    released_at = None
    for tick in range(150):
        next_event = kernels.runnable(apply_events)(events, next_event, tick,
                                                    model.effectiveness, model._taut,
                                                    model.released, np.zeros(2, np.int64),
                                                    np.zeros((2, REEL_COLUMNS)))
        if next_event and released_at is None:
            released_at = model.layout.uav_velocities(x)[1].copy()
        x = model.integrate(x, idle, 0.005, 2).state
        assert model.kinetic_energy(x) == pytest.approx(energy, rel=1e-9)
        assert np.allclose(_momentum(model, x), momentum, rtol=0.0, atol=1e-12)
    g, g_dot = model.constraint_residuals(x)
    assert abs(g[0]) < 1e-6 and abs(g_dot[0]) < 1e-6  # the other cable holds (l^2 = 105 m^2)
    # the released UAV drifts at the velocity it had when it let go, out beyond its cable
    assert np.allclose(model.layout.uav_velocities(x)[1], released_at, rtol=0.0, atol=1e-12)
    assert g[1] > 0.1 and not model.taut[1] and model.released.tolist() == [False, True]
    assert not np.allclose(released_at, [0.4, 0.0, 0.0])  # the swing had pulled it along
    assert math.isfinite(model.kinetic_energy(x))


def test_a_headless_bag_carries_the_events_to_plots_and_layout(tmp_path, monkeypatch):
    """/formation/events in the bag (one message per event at its tick), `Run.events` reads
    them back, every figure over time marks them, the Foxglove layout shows the topic."""
    import matplotlib
    matplotlib.use('Agg')

    from multilift_tools import figures
    from multilift_tools.bagdata import load_run
    from multilift_tools.figures import FIGURES, make_plots
    from multilift_tools.foxglove.layout import layout
    from multilift_tools.headless_bag import record_headless
    from multilift_tools.plot_style import EVENT_COLOR, Context, plt
    scenario = _with_events('twin_lift', 2.5, [
        {'time': 0.503, 'type': 'rotor_effectiveness', 'uav': 1, 'rotor': 2,
         'effectiveness': 0.9},
        {'time': 1.5, 'type': 'cable_release', 'uav': 2}])
    record_headless(scenario, tmp_path / 'bag')
    run = load_run(tmp_path / 'bag')
    assert run.events() == [(0.51, 'uav1 rotor 2 at 90 % of its thrust'),
                            (1.5, 'uav2 releases its cable')]
    assert run.taut()[149, 1] and not run.taut()[150:, 1].any() and run.taut()[150:, 0].all()
    assert load_run(tmp_path / 'bag').events()  # and again (no state left behind)
    drawn = []
    original = plt.Axes.axvline

    def axvline(ax, x, *args, **kwargs):
        if kwargs.get('color') == EVENT_COLOR:
            drawn.append(x)
        return original(ax, x, *args, **kwargs)
    plt.Axes.axvline = axvline
    # two figures over time and one in space are enough (the others draw alike)
    monkeypatch.setattr(figures, 'FIGURES', tuple(spec for spec in FIGURES if spec.name in (
        'cable_tensions', 'rotor_speeds', 'top_view')))
    try:
        written, _ = make_plots(Context(run, scenario), tmp_path / 'plots')
    finally:
        plt.Axes.axvline = original
    timed = [spec.name for spec in figures.FIGURES if spec.over_time
             and (tmp_path / 'plots' / f'{spec.name}.png') in written]
    # a line per event on each time axes: the tensions' one and the rotor speeds' one per UAV
    assert len(timed) == 2 and len(written) == 3
    assert drawn.count(1.5) == drawn.count(0.51) == 3
    panels = layout(scenario)['configById']
    assert panels['RawMessages!events']['topicPath'] == '/formation/events'
    assert 'RawMessages!events' not in layout(scenario_io.load('twin_lift'))['configById']


def test_a_silent_controller_s_last_command_is_held_in_both_paths():
    """uav2's controller silent from 2.0 s for 0.5 s: the simulator applies the last command
    it got (the answer to the state at 1.99 s) over ticks 200..249, the answers again from
    tick 250; the ROS path (FormationSimulator) flies the same to the bit."""
    scenario = _with_events('multi_lift', 4.0, [
        {'time': 2.0, 'type': 'controller_silence', 'uav': 2, 'duration': 0.5}])
    assert event_array(scenario)[0, :7].tolist() == [200.0, 2.0, 2.0, 1.0, 0.0, 0.5, 250.0]
    engine = Engine(scenario)
    record = engine.new_record(1)
    held = []
    for tick in range(260):
        engine.step(1, record)
        held.append((record.speeds[0, 0, 1].copy(), engine.memory.held[0, 1].copy()))
    answers, applied = (np.array(x) for x in zip(*held))
    assert np.array_equal(applied[:200], answers[:200])
    assert (applied[200:250] == answers[199]).all()          # held through the silence ...
    assert not np.array_equal(answers[200:250], np.broadcast_to(answers[199], (50, 4)))
    assert np.array_equal(applied[250:], answers[250:])      # ... then its answers again
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert engine.summary(0)['sim']['events'] == run.summary()['sim']['events'] == [{
        'type': 'controller_silence', 'uav': 2, 'rotor': 0, 'value': 0.5, 'time': 2.0,
        'description': 'uav2 controller silent for 0.5 s (the simulator holds its last '
                       'command)'}]
    quiet = Engine(dataclasses.replace(scenario, events=()))
    quiet.step(10 ** 6)
    assert not np.array_equal(quiet.state[0], engine.state[0])


def test_a_sweep_can_sample_an_event():
    """`sweep --sample events[0].time=...`: a campaign's edit reaches an event like any key,
    and a time past the scenario's end is that run's error line (issue 21 item 6; a shorter
    `--duration` leaves a later event out, as the summary's `events` shows)."""
    from multilift_tools import campaign
    source, base = campaign.load_base('v3_uav_loss')
    path = campaign.parse_key('events[0].time', '--sample')
    early = campaign.run_one(source, base, [('events[0].time', path, 20.0)], duration=25.0)
    late = campaign.run_one(source, base, [('events[0].time', path, 24.0)], duration=25.0)
    assert early['status'] == late['status'] == 'ok'
    assert early['payload_swing_max'] != late['payload_swing_max']
    past = campaign.run_one(source, base, [('events[0].time', path, 130.0)])
    assert past['status'] == 'error' and "before the run's end (120 s)" in past['message']


def test_two_headless_runs_with_events_write_byte_identical_bags(tmp_path):
    from multilift_tools.headless_bag import record_headless
    scenario = _with_events('v3_uav_loss', 1.0, [
        {'time': 0.2, 'type': 'rotor_effectiveness', 'uav': 2, 'rotor': 3, 'effectiveness': 0.5},
        {'time': 0.4, 'type': 'controller_silence', 'uav': 1, 'duration': 0.2},
        {'time': 0.6, 'type': 'cable_release', 'uav': 3}])
    for run in ('a', 'b'):
        record_headless(scenario, tmp_path / run / 'bag')
    for name in ('bag_0.mcap', 'metadata.yaml'):
        assert (tmp_path / 'a' / 'bag' / name).read_bytes() == \
            (tmp_path / 'b' / 'bag' / name).read_bytes(), name
