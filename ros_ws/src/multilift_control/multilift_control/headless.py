"""The whole formation without ROS: the simulator core and every controller in one process.

Same physics, same controller runtime, same tick order as the ROS stack (state at t ->
answers to t -> integrate to the next tick), for studies, sweeps and benchmarks. Loads no
rclpy.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from multilift_control.cascade import balancing_rotor_speed
from multilift_control.runtime import (ControllerAnswer, ControllerRuntime, answer_tick,
                                       formation_runtimes, uav_states)
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import FormationSimulator, SimulationStopped, Snapshot

# on_tick(simulator, snapshot at t, every controller's answer to it: none at the last tick)
TickObserver = Callable[[FormationSimulator, Snapshot, list[ControllerAnswer]], None]


@dataclass
class HeadlessRun:
    """A finished (or stopped) headless run: the simulator and every controller runtime."""
    scenario: Scenario
    simulator: FormationSimulator
    runtimes: list[ControllerRuntime]
    wall_time: float = 0.0          # [s]
    error: str | None = None        # why the simulation stopped itself, or None

    def summary(self) -> dict:
        """The run's statistics as `run` reports them: {'sim': ..., 'leader': ...,
        'follower2': ...} (the same keys and definitions the nodes leave)."""
        sim = dict(self.simulator.stats.as_dict(), wall_time=self.wall_time, error=self.error,
                   scenario=self.scenario.name)
        return {'sim': sim, **{r.name: r.summary() for r in self.runtimes}}


def run_headless(scenario: Scenario, on_tick: TickObserver | None = None,
                 raise_on_stop: bool = True) -> HeadlessRun:
    """Fly `scenario` to t_max; `on_tick` sees every tick's state and answers. A simulation
    that stops itself (a cable out of tolerance, a non-finite state) raises SimulationStopped
    as the node would, or with raise_on_stop=False ends the run with `error` set."""
    start = time.monotonic()
    sim = FormationSimulator(scenario)
    runtimes = formation_runtimes(scenario)
    run = HeadlessRun(scenario, sim, runtimes)
    try:
        while True:
            snapshot = sim.snapshot()
            # as through ROS, the controllers answer the states before t_max only
            answers = [] if sim.finished else answer_tick(runtimes, sim.t_ns,
                                                          uav_states(snapshot))
            if on_tick is not None:
                on_tick(sim, snapshot, answers)
            if sim.finished:
                break
            sim.advance([a.output.rotor_speeds for a in answers],
                        [a.output.saturated for a in answers])
    except SimulationStopped as exc:
        run.error = str(exc)
        if raise_on_stop:
            raise
    finally:
        run.wall_time = time.monotonic() - start
    return run


def hover_speeds(scenario: Scenario) -> list[np.ndarray]:
    """Rotor speeds whose thrust carries each UAV and its share of the payload [rad/s]."""
    share = scenario.payload.mass / scenario.n_uavs
    return [np.full(u.vehicle.n_rotors,
                    balancing_rotor_speed(u.vehicle, u.vehicle.mass + share,
                                          scenario.simulation.gravity))
            for u in scenario.uavs]
