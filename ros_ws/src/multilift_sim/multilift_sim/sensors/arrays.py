"""A run's sensors as the compiled tick reads them (`sensing.sensed_states`), built once before
the run from its scenario's `sensors:` (scenario.SensorConfig): each sensor's model index, its
constants row, every sample's draws from its seeded stream and its memory at the start. No
numba, no ROS. Without `sensors:`, no sensors (K = 0)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.sensors import SENSOR_MODELS, model_index


def sensor_samples(tick_count: int, every: int) -> int:
    """Samples of a run of `tick_count` control periods sampled every `every` ticks: one at
    tick 0 and each `every` ticks to t_max included."""
    return tick_count // every + 1


@dataclass(frozen=True)
class SensorArrays:
    """K sensors of a formation of n UAVs (K = 0: none), rows padded with zeros to the widest
    sensor's."""
    models: np.ndarray       # (K,) int: each sensor's model, its index in SENSOR_MODELS
    constants: np.ndarray    # (K, C): each one's constants row (its model's slots)
    draws: np.ndarray        # (K, n, S, D): every sample's draws, by UAV
    memory: np.ndarray       # (K, n, M): each UAV's memory at the run's start


def _padded(rows: list[np.ndarray], empty: tuple[int, ...]) -> np.ndarray:
    """`rows` stacked along a new first axis, each padded with zeros at the end of every axis
    to the largest; (0, *empty) for none."""
    if not rows:
        return np.zeros((0, *empty))
    out = np.zeros((len(rows), *np.max([row.shape for row in rows], axis=0)))
    for k, row in enumerate(rows):
        out[(k, *(slice(0, size) for size in row.shape))] = row
    return out


def sensor_configs(scenario) -> tuple:
    """The run's sensors in the order the tick runs them: `sensors:` (what the controllers
    receive), then the sensors of their own sections (`imu:`, `mocap:`: `sensor_suite`)."""
    return (() if scenario.sensors is None else (scenario.sensors,)) + scenario.sensor_suite


def sensor_rng(scenario, config) -> np.random.Generator:
    """The stream of a sensor's draws: numpy.random.default_rng of its `seed` for `sensors:`;
    of (seed, its model's index) for a sensor of its own section, so that two with one seed
    draw apart."""
    if config is scenario.sensors:
        return np.random.default_rng(config.seed)
    return np.random.default_rng((config.seed, model_index(config.model)))


def sensor_arrays(scenario) -> SensorArrays:
    """The scenario's sensors (`sensor_configs`) as arrays: each one's draws from its stream
    (`sensor_rng`), the model's `draws` in its fixed order."""
    configs = sensor_configs(scenario)
    sim, n = scenario.simulation, scenario.n_uavs
    constants, draws, memory = [], [], []
    for config in configs:
        model = SENSOR_MODELS[config.model]
        every = config.every(sim.control_rate)
        samples = sensor_samples(sim.tick_count, every)
        rng = sensor_rng(scenario, config)
        constants.append(np.asarray(model.constants(config.settings, every), dtype=float))
        draws.append(np.asarray(model.draws(config.settings, n, samples,
                                            every / sim.control_rate, rng), dtype=float))
        row = np.asarray(model.memory(config.settings), dtype=float)
        memory.append(np.repeat(row[np.newaxis], n, axis=0))
    return SensorArrays(
        models=np.array([model_index(c.model) for c in configs], dtype=np.int64),
        constants=_padded(constants, (0,)), draws=_padded(draws, (n, 0, 0)),
        memory=_padded(memory, (n, 0)))
