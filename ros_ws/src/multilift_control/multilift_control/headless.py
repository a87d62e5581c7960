"""The whole formation without ROS: the simulator core and every controller in one process.

Same physics, same control laws, same tick order as the ROS stack (state at t -> answers to t
-> integrate to the next tick), for studies, sweeps and benchmarks. Loads no rclpy.

- `fly`: through the engine (`multilift_control.engine`), many ticks per compiled call when
  nothing outside needs each one: `run --headless` without a bag, `sweep`'s rows;
- `run_headless`: tick by tick through the objects the ROS nodes use (FormationSimulator and
  the controller runtimes), for an observer of every tick (`on_tick`: the headless bag, the
  reproduction's recordings). Both give the same states and figures to the bit
  (tests/unit/test_engine.py).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from multilift_control.cascade import balancing_rotor_speed
from multilift_control.engine import Engine
from multilift_control.runtime import (ControllerAnswer, ControllerRuntime, answer_tick,
                                       formation_runtimes, uav_states)
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import FormationSimulator, SimulationStopped, Snapshot
from multilift_sim.schedules import run_seeds

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
                   scenario=self.scenario.name, events=self.simulator.events_summary(),
                   seeds=run_seeds(self.scenario), **self.simulator.clearance_summary())
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
            if scenario.controlled:
                sim.advance([a.output.rotor_speeds for a in answers],
                            [a.output.saturated for a in answers])
            else:  # every UAV's motion prescribed: no controller answers
                sim.advance(*sim.idle_commands())
    except SimulationStopped as exc:
        run.error = str(exc)
        if raise_on_stop:
            raise
    finally:
        run.wall_time = time.monotonic() - start
    return run


@dataclass
class FlownRun:
    """A run flown by the engine (`fly`, `fly_batch`: formation `index` of `engine`); its
    summary is HeadlessRun's."""
    scenario: Scenario
    engine: Engine
    index: int = 0
    wall_time: float = 0.0          # [s]

    @property
    def error(self) -> str | None:
        """Why the simulation stopped itself, or None."""
        return self.engine.stop_reason(self.index)

    def summary(self) -> dict:
        return self.engine.summary(self.index, self.wall_time)


# ticks per compiled call between two progress reports (half a second of a 100 Hz mission)
PROGRESS_TICKS = 50


def progress_ticker(progress: Callable[[float, float], None],
                    every: int = PROGRESS_TICKS) -> TickObserver:
    """An on_tick calling `progress(t, t_max)` [s] every `every` ticks."""
    def on_tick(sim: FormationSimulator, *_) -> None:
        if sim.tick % every == 0:
            progress(sim.t, sim.tick_count * sim.period_ns * 1e-9)
    return on_tick


def fly(scenario: Scenario, progress: Callable[[float, float], None] | None = None,
        raise_on_stop: bool = True) -> FlownRun:
    """Fly `scenario` to t_max through the engine: the whole mission in one compiled call, or
    PROGRESS_TICKS at a time with `progress(t, t_max)` [s] after each. A simulation that stops
    itself raises SimulationStopped (its message the simulator's), or with raise_on_stop=False
    ends the run with `error` set."""
    start = time.monotonic()
    engine = Engine(scenario)
    run = FlownRun(scenario, engine)
    t_max = float(engine.t_max[0])
    try:
        while engine.running[0]:
            engine.step(PROGRESS_TICKS if progress is not None
                        else int(engine.arrays.tick_count[0]))
            if progress is not None:
                progress(float(engine.t[0]), t_max)
    finally:
        run.wall_time = time.monotonic() - start
    if raise_on_stop and engine.stopped[0]:
        raise SimulationStopped(run.error)
    return run


def fly_batch(scenarios: list[Scenario], fields: list | None = None) -> list[FlownRun]:
    """Fly scenarios of one shape (`engine.arrays.shape_groups`, which gives their `fields`)
    to their t_max together, one engine batch, each to the numbers it gets alone
    (tests/unit/test_engine.py); a run Algorithm 1 stops has `error` set. Each run's wall time
    is its share of the batch's."""
    start = time.monotonic()
    engine = Engine(scenarios, fields=fields)
    engine.step(int(engine.arrays.tick_count.max()))
    share = (time.monotonic() - start) / len(scenarios)
    return [FlownRun(s, engine, b, share) for b, s in enumerate(scenarios)]


def hover_speeds(scenario: Scenario) -> list[np.ndarray]:
    """Rotor speeds whose thrust carries each UAV and its share of the payload [rad/s]."""
    share = scenario.payload.mass / scenario.n_uavs
    return [np.full(u.vehicle.n_rotors,
                    balancing_rotor_speed(u.vehicle, u.vehicle.mass + share,
                                          scenario.simulation.gravity))
            for u in scenario.uavs]
