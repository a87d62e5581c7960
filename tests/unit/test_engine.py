"""The engine (multilift_control.engine): a formation's whole tick in one compiled call.

Held against the per-object path the ROS nodes take (FormationSimulator and the controller
runtimes, `run_headless`): the same states to the bit, tick by tick and over whole missions;
a batch of B formations equal to B single runs; compiled equal to its uncompiled run."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from multilift_control.engine import Engine
from multilift_control.engine.arrays import FINISHED, OFF_CONSTRAINT
from multilift_control.engine.tick import run_ticks
from multilift_control.headless import run_headless
from multilift_control.runtime import answer_tick, formation_runtimes, uav_states
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator


def _short(name: str, duration: float, **changes) -> scenario_io.Scenario:
    base = scenario_io.load(name)
    return dataclasses.replace(base, simulation=dataclasses.replace(
        base.simulation, duration=duration), **changes)


@pytest.mark.parametrize('name,duration,cables', [
    ('twin_lift', 120.0, 'rigid'), ('circle3', 10.0, 'rigid'), ('v5', 10.0, 'rigid'),
    ('single_lift_swing', 5.0, 'rigid'), ('twin_lift', 10.0, 'slack')])
def test_a_mission_equals_the_per_object_run_to_the_bit(name, duration, cables):
    scenario = _short(name, duration, cable_model=cables)
    engine = Engine(scenario)
    flown = engine.step(10 ** 6)
    run = run_headless(scenario)
    assert flown[0] == scenario.simulation.tick_count and engine.finished[0]
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert np.array_equal(engine.memory.taut[0], run.simulator.taut)
    expected = run.summary()
    del expected['sim']['wall_time']
    assert engine.summary(0) == expected  # every run figure, to the bit
    assert np.abs(engine.state[0] - engine._initial.state[0]).max() > 1e-3  # it flew


def test_each_tick_s_answers_and_tension_are_the_runtimes():
    scenario = _short('circle3', 0.3)
    engine = Engine(scenario)
    record = engine.new_record(1)
    sim, runtimes = FormationSimulator(scenario), formation_runtimes(scenario)
    for _ in range(30):
        states = uav_states(sim.snapshot())
        answers = answer_tick(runtimes, sim.t_ns, states)
        engine.step(1, record)
        assert np.array_equal(record.measured[0, 0], states.array)
        for i, answer in enumerate(answers):
            assert np.array_equal(record.speeds[0, 0, i], answer.output.rotor_speeds)
            assert np.array_equal(record.saturated[0, 0, i], answer.output.saturated)
            if i:
                rows = len(answer.formation_error)
                assert np.array_equal(record.errors[0, 0, i, :rows], answer.formation_error)
        sim.advance([a.output.rotor_speeds for a in answers],
                    [a.output.saturated for a in answers])
        assert np.array_equal(record.tension[0, 0], sim.last_tension)
        assert np.array_equal(engine.state[0], sim.state)


def test_a_batch_equals_its_formations_flown_one_by_one():
    masses = (0.6, 0.8, 1.1)
    scenarios = [_short('twin_lift', 5.0, payload=dataclasses.replace(
        scenario_io.load('twin_lift').payload, mass=m)) for m in masses]
    batch = Engine(scenarios)
    batch.step(200)
    batch.step(10 ** 6)
    for b, scenario in enumerate(scenarios):
        single = Engine(scenario)
        single.step(10 ** 6)
        assert np.array_equal(batch.state[b], single.state[0])
    assert len({batch.state[b].tobytes() for b in range(3)}) == 3  # they differ
    assert batch.finished.all()


def test_compiled_equals_its_uncompiled_run():
    scenario = _short('twin_lift', 0.2)
    compiled, python = Engine(scenario), Engine(scenario)
    compiled.step(20)
    kernels.uncompiled(run_ticks)(python.arrays, python.memory, 20, python._no_record)
    assert np.array_equal(compiled.state, python.state)
    assert np.array_equal(compiled.memory.follower_memory, python.memory.follower_memory)


def test_a_stopped_formation_stops_alone_and_says_why():
    ok = _short('twin_lift', 2.0)
    tight = dataclasses.replace(ok, simulation=dataclasses.replace(
        ok.simulation, constraint_tolerance=1e-30))
    engine = Engine([ok, tight])
    engine.step(10 ** 6)
    assert engine.memory.status.tolist() == [FINISHED, OFF_CONSTRAINT]
    assert engine.stopped.tolist() == [False, True]
    assert engine.stop_reason(0) is None
    assert 'cable ' in engine.stop_reason(1) and 'exceeds the tolerance' in engine.stop_reason(1)


def test_formations_of_different_shapes_are_refused():
    with pytest.raises(ValueError, match='differ in the shape'):
        Engine([scenario_io.load('twin_lift'), scenario_io.load('circle3')])


def test_answers_from_outside_fly_the_engine_s_own_tick_to_the_bit():
    """answer() then step_commanded() (a learning environment's step) is the tick step() runs;
    reset(which) starts those formations again and leaves the others."""
    scenarios = [_short('circle3', 1.0), _short('circle3', 1.0, cable_model='slack')]
    own, commanded = Engine(scenarios), Engine(scenarios)
    own.step(40)
    for _ in range(40):
        speeds, saturated = commanded.answer()  # once per tick: the controllers advance
        commanded.step_commanded(speeds, saturated)
    assert np.array_equal(own.state, commanded.state)
    assert np.array_equal(own.memory.run, commanded.memory.run)
    assert np.array_equal(own.memory.follower_memory, commanded.memory.follower_memory)
    later = commanded.state[1].copy()
    commanded.reset(np.array([True, False]))
    assert commanded.memory.tick.tolist() == [0, 40]
    assert np.array_equal(commanded.state[0], Engine(scenarios[0]).state[0])
    assert np.array_equal(commanded.state[1], later)
    commanded.step_commanded(np.full((2, 3, 4), 1500.0), which=np.array([False, True]))
    assert commanded.memory.tick.tolist() == [0, 41]
    with pytest.raises(ValueError, match='speeds must be'):
        commanded.step_commanded(np.zeros((2, 3, 3)))


def _hexa_beside_quads(name: str, duration: float, hexa: int) -> scenario_io.Scenario:
    """Scenario `name` with UAV `hexa` (from 0) a hexa_x, the others its quads."""
    import yaml
    data = yaml.safe_load(scenario_io.resolve(name).read_text())
    data['simulation']['duration'] = duration
    data['uavs'][hexa] = dict(data['uavs'][hexa] or {}, frame_type='hexa_x')
    return scenario_io.loads(yaml.safe_dump(data))


@pytest.mark.parametrize('hexa', [0, 1])
def test_mixed_rotor_counts_fly_in_the_engine_as_the_per_object_run(hexa):
    """A hexa beside quads: each UAV's rotors padded to the formation's most, the padding
    never answered (0, not saturated): the engine flies it to the per-object run's bits."""
    scenario = _hexa_beside_quads('twin_lift', 6.0, hexa)
    assert sorted({u.vehicle.n_rotors for u in scenario.uavs}) == [4, 6]
    engine = Engine(scenario)
    record = engine.new_record(50)
    engine.step(50, record)
    quad = 1 - hexa  # its padding: 0, not saturated
    assert not record.speeds[:, 0, quad, 4:].any() and not record.saturated[:, 0, quad, 4:].any()
    assert record.speeds[:, 0, hexa, 4:].min() > 0  # the hexa's last two rotors answered
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert engine.finished[0]
    assert np.array_equal(engine.state[0], run.simulator.state)
    expected = run.summary()
    del expected['sim']['wall_time']
    assert engine.summary(0) == expected


def test_a_batch_of_mixed_rotor_counts_equals_its_formations_alone():
    """hexa + quad beside quad + hexa: one batch (the same shapes), each formation's padding
    its own."""
    scenarios = [_hexa_beside_quads('twin_lift', 3.0, hexa) for hexa in (0, 1)]
    batch = Engine(scenarios)
    batch.step(10 ** 6)
    for b, scenario in enumerate(scenarios):
        single = Engine(scenario)
        single.step(10 ** 6)
        assert np.array_equal(batch.state[b], single.state[0])
