"""The sensors' errors of a run (`sensors:`, issue 21 item 2), drawn once before it flies from
its seed, as `turbulence` draws the wind: the same seed, the same errors, in every path (the
engine, the simulator node, a sweep). No ROS, no numba; the compiled tick reads the arrays
(`physics.sensors.sensed_states`, docs/sensors.md).

For each UAV and each measured slot of a quantity q (SENSED_QUANTITIES: position [m], velocity
[m/s], attitude [rad] (the ZYX Euler angles), body_rate [rad/s]), sample s's error is

    e_s = b_s + sigma_q w_s,        b_s = b_{s-1} + sigma_b,q sqrt(dt) v_s,   b_0 = 0

with w_s, v_s independent standard normal draws and dt = 1 / rate the time between samples:
white noise of standard deviation sigma_q (`{q}_noise`) on a bias that walks as a Wiener
process of intensity sigma_b,q (`{q}_bias`, [unit / sqrt(s)]: after t seconds its standard
deviation is sigma_b,q sqrt(t)), the random-walk bias of IEEE Std 952's gyro model and of
rotorpy's IMU. A sample is lost with probability `dropout`, independently.
"""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.physics.layout import MEASURED_COLUMNS, SENSED_BLOCKS


def sensor_samples(tick_count: int, every: int) -> int:
    """Samples of a run of `tick_count` control periods sampled every `every` ticks: one at
    tick 0 and each `every` ticks to t_max included."""
    return tick_count // every + 1


def sensor_errors(config, n_uavs: int, tick_count: int, control_rate: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """(errors (S, n, MEASURED_COLUMNS) [the slots' units], delivered (S, n) bool) of every
    sample of a run of `tick_count` ticks at `control_rate` [Hz] under `config`
    (scenario.SensorConfig), drawn from numpy.random.default_rng(config.seed) in a fixed
    order (white noise, bias steps, dropouts), so one seed gives one series."""
    every = config.every(control_rate)
    samples = sensor_samples(tick_count, every)
    dt = every / control_rate
    noise = np.zeros(MEASURED_COLUMNS)
    walk = np.zeros(MEASURED_COLUMNS)
    for block, sigma, sigma_b in zip(SENSED_BLOCKS, config.noise, config.bias):
        noise[block:block + 3] = sigma
        walk[block:block + 3] = sigma_b * math.sqrt(dt)
    rng = np.random.default_rng(config.seed)
    white = rng.standard_normal((samples, n_uavs, MEASURED_COLUMNS)) * noise
    steps = rng.standard_normal((samples, n_uavs, MEASURED_COLUMNS)) * walk
    steps[0] = 0.0
    bias = np.cumsum(steps, axis=0)
    delivered = rng.random((samples, n_uavs)) >= config.dropout
    return np.ascontiguousarray(bias + white), delivered
