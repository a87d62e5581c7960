"""A UAV pitching towards 90 degrees stops the run with a named reason (issue 31 item 6), in the
simulator and the engine alike: the state's ZYX Euler angles (seed Eq. 2.6) cannot carry it
through, and their rates (1/cos(pitch) in W(eta)^-1) reached 1e152 rad/s in a learning run
whose numbers stayed finite, so no other check fired."""
from __future__ import annotations

import math

import numpy as np
import pytest

from multilift_control.engine import Engine
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.simulation import FormationSimulator, SimulationStopped
from multilift_sim.statistics.layout import PITCH_LIMIT

PITCH_RATE = 8.0  # [rad/s]: a UAV tumbling nose-up, reaching 90 deg within 0.2 s


def _tumbling(sim_state: np.ndarray, n: int) -> np.ndarray:
    x = sim_state.copy()
    StateLayout(n).uav_euler_rates(x)[0, 1] = PITCH_RATE
    return x


def test_a_tumbling_uav_stops_the_run_naming_it_before_its_angles_blow_up():
    scenario = scenario_io.load('single_lift_swing')
    sim = FormationSimulator(scenario)
    sim.state = _tumbling(sim.state, 1)
    hover = [np.full(4, 1500.0)]
    idle = [np.zeros(4, bool)]
    pitches = []
    with pytest.raises(SimulationStopped) as stop:
        for _ in range(100):
            pitches.append(float(StateLayout(1).uav_euler(sim.state)[0, 1]))
            sim.advance(hover, idle)
    message = str(stop.value)
    assert message.startswith('uav1: pitch ') and 'Euler angles' in message, message
    last = StateLayout(1).uav_euler(sim.state)[0, 1]
    assert math.cos(last) < math.cos(PITCH_LIMIT)      # it stopped at the limit ...
    assert all(abs(p) < PITCH_LIMIT for p in pitches)   # ... and not before
    assert np.isfinite(sim.state).all() and np.abs(sim.state).max() < 1e3  # nothing blew up
    assert f'pitch {last:.4f} rad' in message


def test_the_engine_stops_the_same_formation_with_the_same_words():
    scenario = scenario_io.load('twin_lift').with_duration(2.0)
    sim = FormationSimulator(scenario)
    engine = Engine(scenario)
    x = _tumbling(sim.state, 2)
    sim.state = x
    engine.memory.state[0, :] = x
    speeds = engine.answer()[0][0].copy()  # the controllers' first answer, held
    flags = np.zeros(speeds.shape, bool)
    with pytest.raises(SimulationStopped) as stop:
        for _ in range(200):
            sim.advance(list(speeds), list(flags))
            engine.step_commanded(speeds[None], flags[None])
    engine.step_commanded(speeds[None], flags[None])
    assert engine.stopped[0] and engine.stop_reason(0) == str(stop.value)
    assert np.array_equal(engine.state[0], sim.state)
