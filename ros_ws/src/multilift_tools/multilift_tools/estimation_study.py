"""The EKF's consistency over a Monte Carlo of runs (issue 33 item 2; docs/estimation.md):
`monte_carlo` flies N copies of a scenario with an estimator, each with its own sensor seeds,
in one Engine and keeps at every control tick the NEES of each UAV's position and attitude
averaged over the runs, and at its updates the NIS; benchmarks/estimation_consistency.py
prints and plots it, tests/unit/test_estimation.py runs a small one."""
from __future__ import annotations

import dataclasses

import numpy as np

from multilift_sim import scenario as scenarios
from multilift_sim.estimators.consistency import UPDATE_DOF, ekf_nees, ekf_nis, mean_bounds


def seeded(base, seed: int):
    """`base` with every sensor of its own section seeded `seed`."""
    suite = tuple(dataclasses.replace(c, seed=seed) for c in base.sensor_suite)
    return dataclasses.replace(base, sensor_suite=suite)


def monte_carlo(name: str, runs: int, duration: float, tune=None) -> dict:
    """Per tick and UAV the mean NEES of position and attitude over `runs` runs of scenario
    `name` (a name or a file) cut to `duration` [s], run k's sensors seeded k + 1, the mean NIS
    of the runs that updated (NaN: none) and how many did. `tune(engine)` may change the
    engine's arrays before the runs (a test's mistuned filter)."""
    from multilift_control.engine import Engine
    base = scenarios.load(name).with_duration(duration)
    engine = Engine([seeded(base, k + 1) for k in range(runs)])
    if tune is not None:
        tune(engine)
    ticks = base.simulation.tick_count
    n = base.n_uavs
    position, attitude = np.empty((ticks, n)), np.empty((ticks, n))
    nis, updated = np.full((ticks, n), np.nan), np.zeros((ticks, n), dtype=int)
    for tick in range(ticks):
        engine.measured()  # the estimate at this tick (the tick's measure, once)
        memory = engine.memory.estimator_memory[:, 0]  # (runs, n, M)
        values = [ekf_nees(engine.state[b], memory[b]) for b in range(runs)]
        position[tick] = np.mean([v[0] for v in values], axis=0)
        attitude[tick] = np.mean([v[1] for v in values], axis=0)
        fused = np.array([ekf_nis(memory[b], tick) for b in range(runs)])
        updated[tick] = np.sum(np.isfinite(fused), axis=0)
        for i in np.flatnonzero(updated[tick]):
            nis[tick, i] = np.nanmean(fused[:, i])
        engine.step(1)
    if not engine.finished.all():
        raise RuntimeError(f'a run stopped: status {engine.memory.status}')
    return {'t': np.arange(ticks) / base.simulation.control_rate, 'position': position,
            'attitude': attitude, 'nis': nis, 'updated': updated}


def nis_inside(result: dict, runs: int) -> np.ndarray:
    """Per UAV the share of update ticks whose mean NIS lies inside the interval for the
    count of runs that updated then."""
    shares = []
    for i in range(result['nis'].shape[1]):
        inside = []
        for value, count in zip(result['nis'][:, i], result['updated'][:, i]):
            if count and np.isfinite(value):
                low, high = mean_bounds(UPDATE_DOF, int(count))
                inside.append(low <= value <= high)
        shares.append(np.mean(inside))
    return np.array(shares)
