"""The controller runtime: one process's shared ThrustBook answers as a book per follower
(the nodes' way) does."""
import dataclasses

import numpy as np
import pytest

from multilift_control.headless import uav_states
from multilift_control.runtime import ControllerRuntime, answer_tick, formation_runtimes
from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator


def _fly(scenario, runtimes, ticks):
    sim = FormationSimulator(scenario)
    speeds = []
    for _ in range(ticks):
        answers = answer_tick(runtimes, sim.t_ns, uav_states(sim.snapshot()))
        speeds.append(np.concatenate([a.output.rotor_speeds for a in answers]))
        sim.advance([a.output.rotor_speeds for a in answers],
                    [a.output.saturated for a in answers])
    return np.array(speeds), [r.summary() for r in runtimes]


@pytest.mark.parametrize('name', ['multi_lift', 'v5', 'circle3'])
def test_shared_thrust_book_answers_as_one_book_per_follower(name):
    scenario = scenario_io.load(name)
    scenario = dataclasses.replace(scenario, simulation=dataclasses.replace(
        scenario.simulation, duration=2.0))
    shared = formation_runtimes(scenario)
    assert len({id(r.thrusts) for r in shared[1:]}) == 1
    own = [ControllerRuntime(scenario, i) for i in range(scenario.n_uavs)]
    assert len({id(r.thrusts) for r in own[1:]}) == scenario.n_uavs - 1
    speeds_shared, summaries_shared = _fly(scenario, shared, 200)
    speeds_own, summaries_own = _fly(scenario, own, 200)
    np.testing.assert_array_equal(speeds_shared, speeds_own)
    assert summaries_shared == summaries_own
    # the followers did move the rotors apart from hover (the comparison is not of constants)
    assert np.ptp(speeds_shared[:, -1]) > 1.0


def test_thrust_vectors_need_the_leader_and_are_formed_once_per_state():
    scenario = scenario_io.load('multi_lift')
    runtimes = formation_runtimes(scenario)
    book = runtimes[1].thrusts
    states = uav_states(FormationSimulator(scenario).snapshot())
    with pytest.raises(KeyError):
        book.vectors(0, states)
    runtimes[1].note_command(0, 0, np.full(4, 500.0))
    first = book.vectors(0, states)
    assert book.vectors(0, states) is first
    assert first.shape == (3, 3) and first[0, 2] == pytest.approx(
        scenario.uavs[0].vehicle.collective_thrust(np.full(4, 500.0)))
