"""A run's estimator as the compiled tick reads it (`estimators.estimation.estimated`): its index,
constants row and every UAV's memory at the start, built once before the run from the
scenario's `estimator:`. No numba, no ROS. Without one, none (E = 0)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.estimators import ESTIMATORS, estimator_index
from multilift_sim.sensors.arrays import sensor_configs


@dataclass(frozen=True)
class EstimatorArrays:
    models: np.ndarray       # (E,) int: its index in ESTIMATORS
    constants: np.ndarray    # (E, C)
    memory: np.ndarray       # (E, n, M)


def estimator_arrays(scenario) -> EstimatorArrays:
    n = scenario.n_uavs
    config = scenario.estimator
    if config is None:
        return EstimatorArrays(np.zeros(0, dtype=np.int64), np.zeros((0, 0)),
                               np.zeros((0, n, 0)))
    part = ESTIMATORS[config.model]
    rows = {c.model: k for k, c in enumerate(sensor_configs(scenario))}
    row = np.asarray(part.memory(config.settings, scenario), dtype=float)
    return EstimatorArrays(
        models=np.array([estimator_index(config.model)], dtype=np.int64),
        constants=np.asarray(part.constants(config.settings, scenario, rows),
                             dtype=float)[np.newaxis],
        memory=np.repeat(row[np.newaxis, np.newaxis], n, axis=1))
