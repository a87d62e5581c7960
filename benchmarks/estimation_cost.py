"""The EKF's cost (issue 33 item 7's measure: microseconds per UAV per IMU sample): the
compiled `estimators.ekf.estimate` of one UAV called on fresh ticks of a twin_lift_realistic
flight's arrays (propagation of the delayed horizon, the output predictor over the motion
capture's latency, an update at most ticks), and the engine's whole tick with and without the
estimator (twin_lift_realistic against twin_lift), CPU time.

    python benchmarks/estimation_cost.py
"""
from __future__ import annotations

import time

import numpy as np

from multilift_sim import kernels  # noqa: F401 - NUMBA_CACHE_DIR before numba loads
from multilift_sim import scenario as scenarios
from multilift_sim.kernels import jit


def _replay(estimate, constants, sensors, memory, first, ticks, received):
    """`estimate` at ticks first .. first + ticks - 1, the sensors' last outputs made fresh
    at each (an IMU sample every tick, a motion-capture sample taken the tick before)."""
    for tick in range(first, first + ticks):
        sensors[:, 0] = tick
        sensors[:, 1] = tick - 1
        estimate(constants, sensors, memory, tick, received)


def per_call() -> tuple[float, float]:
    """[us] per `estimate` call of one UAV, over 2000 ticks replayed on one memory copy:
    (in a compiled loop, called from Python one at a time)."""
    from multilift_control.engine import Engine
    from multilift_sim.estimators import ekf
    from multilift_sim.physics.layout import MEASURED_COLUMNS
    engine = Engine(scenarios.load('twin_lift_realistic').with_duration(30.0))
    engine.step(100)
    a, m = engine.arrays, engine.memory
    constants, sensors = a.estimator_constants[0, 0], m.sensor_memory[0][:, 0].copy()
    memory, received = m.estimator_memory[0, 0, 0].copy(), np.zeros(MEASURED_COLUMNS)
    ticks = 2000
    compiled = jit(_replay)
    compiled(ekf.estimate, constants, sensors, memory.copy(), 100, 10, received)  # compiled
    started = time.process_time()
    compiled(ekf.estimate, constants, sensors, memory.copy(), 100, ticks, received)
    inside = (time.process_time() - started) / ticks * 1e6
    started = time.process_time()
    _replay(ekf.estimate, constants, sensors, memory.copy(), 100, ticks, received)
    return inside, (time.process_time() - started) / ticks * 1e6


def engine_tick(name: str) -> float:
    """[us] of CPU per control tick of the engine flying `name` (60 s, one formation)."""
    from multilift_control.engine import Engine
    engine = Engine(scenarios.load(name).with_duration(60.0))
    engine.step(10)
    started = time.process_time()
    engine.step(5990)
    return (time.process_time() - started) / 5990 * 1e6


if __name__ == '__main__':
    inside, from_python = per_call()
    print(f'ekf.estimate, one UAV, one IMU sample and update: {inside:.2f} us per call in a '
          f'compiled loop ({from_python:.1f} us called from Python)')
    for name in ('twin_lift', 'twin_lift_realistic'):
        print(f'engine tick of {name}: {engine_tick(name):.1f} us CPU')
