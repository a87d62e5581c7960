"""A run's payload estimator as the compiled tick reads it (`estimators.estimation.estimated`):
its index, constants row and memory at the start, built once before the run from the
scenario's `payload_estimator:`. No numba, no ROS. Without one, none (P = 0)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.payload_estimators import PAYLOAD_ESTIMATORS, payload_estimator_index
from multilift_sim.sensors.arrays import sensor_configs


@dataclass(frozen=True)
class PayloadEstimatorArrays:
    models: np.ndarray       # (P,) int: its index in PAYLOAD_ESTIMATORS
    constants: np.ndarray    # (P, C)
    memory: np.ndarray       # (P, M)


def payload_estimator_arrays(scenario) -> PayloadEstimatorArrays:
    config = scenario.payload_estimator
    if config is None:
        return PayloadEstimatorArrays(np.zeros(0, dtype=np.int64), np.zeros((0, 0)),
                                      np.zeros((0, 0)))
    part = PAYLOAD_ESTIMATORS[config.model]
    rows = {c.model: k for k, c in enumerate(sensor_configs(scenario))}
    return PayloadEstimatorArrays(
        models=np.array([payload_estimator_index(config.model)], dtype=np.int64),
        constants=np.asarray(part.constants(config.settings, scenario, rows),
                             dtype=float)[np.newaxis],
        memory=np.asarray(part.memory(config.settings, scenario), dtype=float)[np.newaxis])
