"""Compile the kernels into numba's on-disk cache (multilift_sim.kernels: how start-up stays
low), a stage per call, so scripts/setup runs them in two lanes of processes on the machine's
two cores (a kernel one stage compiled is loaded from the cache by a later one; numba
optimises each compiled function with every function it calls, so what a kernel calls should
be in the cache before it is compiled, or the two lanes compile it twice).

scripts/setup compiles what a tick of the ROS run needs (`scripts/multilift run`: the
simulator node and the controller nodes) and the rest of the object path (`run --compose`, the
tools' tick-by-tick runs):

- `advance`: the physics' tick (multilift_sim.physics.tick) as the simulator node steps it:
  its start, its advance (rigid and slack cables, a rigid payload, events, a prescribed UAV's
  start) and the tension at a tick; in one lane, beside
- `measure`: the physics' measure (sensors, estimators) as the simulator node calls it, and
- `laws`: every controller's compiled laws as the controller nodes call them (the runtimes);
- `rest`: the simulator's messages and a run of every kind, tick by tick (mostly loads).

The engine's tick over B formations (`run --headless`, sweeps, studies) and the learning
environments' calls compile on their first use into the same cache (about 40 and 20 CPU
seconds; `multilift_sim.kernels`: one process compiles a kernel while the others wait for
it), or ahead of it with these stages:

- `engine_start`: the engine's start (its physics' start from the cache `advance` filled);
- `engine`: the engine's tick over B formations (`run --headless`, sweeps);
- `learning`: the engine's calls the learning environments make (answers, commanded ticks,
  references, attitude commands, their own attitude-rate loop).

Run by scripts/setup with the workspace's environment (scripts/env.sh), MULTILIFT_KERNEL=jit:
`MULTILIFT_KERNEL=jit python scripts/compile_kernels.py engine_start engine learning` after
it compiles the rest ahead (a benchmark's or a training's first seconds).
"""
from __future__ import annotations

import dataclasses
import os
import sys

import numpy as np
import yaml

from multilift_sim import kernels, scenario  # NUMBA_CACHE_DIR: the folder of these sources


def _short(name: str, cables: str | None = None) -> scenario.Scenario:
    base = scenario.load(name)
    short = base.with_duration(0.05)
    return short if cables is None else dataclasses.replace(short, cable_model=cables)


def _every_kind() -> scenario.Scenario:
    """multi_lift with every kind of event (docs/events.md), sensors (docs/sensors.md) and the
    estimator (docs/estimation.md)."""
    data = yaml.safe_load(scenario.resolve('multi_lift').read_text())
    data['simulation']['duration'] = 0.05
    data['events'] = [
        {'time': 0.01, 'type': 'rotor_effectiveness', 'uav': 2, 'rotor': 1,
         'effectiveness': 0.5},
        {'time': 0.02, 'type': 'controller_silence', 'uav': 1, 'duration': 0.01},
        {'time': 0.03, 'type': 'cable_release', 'uav': 3}]
    data['sensors'] = {'position_noise': 0.01, 'latency_ticks': 1}
    data['imu'], data['mocap'], data['estimator'] = {}, {'preset': 'mocap_indoor'}, 'ekf'
    return scenario.loads(yaml.safe_dump(data))


def _physics_scenarios() -> tuple[scenario.Scenario, ...]:
    """The scenarios whose ticks reach every compiled path of the physics."""
    return (_short('twin_lift'), _short('twin_lift', 'slack'), _short('box_lift'),
            _every_kind(), _short('prescribed_swing'))  # its start: prescribe_state


def advance() -> None:
    from multilift_sim.simulation import FormationSimulator
    for short in _physics_scenarios():
        sim = FormationSimulator(short)  # its start (physics.tick.start), compiled
        speeds = [list(range(1400, 1400 + u.vehicle.n_rotors)) for u in short.uavs]
        flags = [[False] * u.vehicle.n_rotors for u in short.uavs]
        for _ in range(3):
            sim.advance(speeds, flags)
        sim.cable_state(speeds)


def measure() -> None:
    from multilift_sim.physics import tick
    from multilift_sim.physics.layout import MEASURED_COLUMNS
    from multilift_sim.simulation import FormationSimulator
    compiled = kernels.runnable(tick.measure, 'jit')
    for short in _physics_scenarios():
        # the simulator uncompiled (the `advance` stage compiles it), its measure compiled,
        # called as FormationSimulator.snapshot calls it
        os.environ[kernels.VARIABLE] = 'python'
        sim = FormationSimulator(short)
        os.environ[kernels.VARIABLE] = 'jit'
        compiled(sim.arrays, sim.memory, 0, np.empty((sim.n, MEASURED_COLUMNS)))


def laws() -> None:
    from multilift_control.runtime import answer_tick, formation_runtimes, uav_states
    from multilift_sim.simulation import FormationSimulator
    for short in (_short('twin_lift'), _short('circle3'), _every_kind()):
        # the simulator uncompiled (the `physics` stage compiles it), the laws compiled
        os.environ[kernels.VARIABLE] = 'python'
        snapshot = FormationSimulator(short).snapshot()
        os.environ[kernels.VARIABLE] = 'jit'
        answer_tick(formation_runtimes(short), 0, uav_states(snapshot))


def engine_start() -> None:
    from multilift_control.engine import Engine
    Engine(_short('twin_lift'))  # engine.tick.start and tell_controllers


def engine() -> None:
    from multilift_control.engine import Engine
    for short in (_short('twin_lift'), _every_kind()):
        engine = Engine(short)
        engine.step(5)
        engine.measured()


def learning() -> None:
    from multilift_control.engine import Engine
    from multilift_learning.vector_env import FormationVectorEnv
    short = _short('twin_lift')
    for task in ('hover', 'mission'):
        envs = FormationVectorEnv(2, short, task)
        envs.reset(seed=0)
        envs.step(envs.expert_actions())
    rates = FormationVectorEnv(2, short, 'hover', action_mode='thrust_body_rates')
    rates.reset(seed=0)
    rates.step(rates.action_space.sample() * 0.0)  # the attitude-rate loop (laws.body_rates)
    engine = Engine(short)
    engine.attitude_speeds(engine.measured()[:, :, :3] * 0.0, engine.measured()[:, :, 0] * 0.0)


def rest() -> None:
    from multilift_control.headless import run_headless
    from multilift_sim.wire.tick_messages import SimulatorMessages
    kernels.prune_cache()  # the folders of older sources
    for short in (_short('twin_lift'), _short('circle3'), _short('twin_lift', 'slack')):
        run_headless(short)
    events = _every_kind()
    run = run_headless(events)
    SimulatorMessages(events).state(run.simulator.snapshot(), [0.0] * 3, None)
    rigid = _short('box_lift')
    SimulatorMessages(rigid).state(run_headless(rigid).simulator.snapshot(), [0.0] * 3, None)
    run_headless(_short('window'))  # its load measures the start's clearances (world:)


STAGES = {'advance': advance, 'measure': measure, 'laws': laws, 'engine_start': engine_start,
          'engine': engine, 'learning': learning, 'rest': rest}

if __name__ == '__main__':
    for stage in sys.argv[1:]:
        STAGES[stage]()
