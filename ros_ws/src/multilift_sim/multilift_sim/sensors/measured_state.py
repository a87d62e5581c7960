"""`measured_state`: every UAV's measured state (seed Eq. 2.7) with white noise, a bias random
walk, latency and dropouts (issue 21 item 2; docs/sensors.md), the default model of `sensors:`.

Errors. For each UAV and each slot of a quantity q (QUANTITIES: position [m], velocity [m/s],
attitude [rad] (the ZYX Euler angles), body_rate [rad/s]), sample s carries

    e_s = b_s + sigma_q w_s,        b_s = b_{s-1} + sigma_b,q sqrt(dt) v_s,   b_0 = 0

with w_s, v_s independent standard normal draws and dt the time between samples: white noise
of standard deviation sigma_q (`{q}_noise`) on a bias that walks as a Wiener process of
intensity sigma_b,q (`{q}_bias`, [unit / sqrt(s)]: after t seconds its standard deviation is
sigma_b,q sqrt(t)), the random-walk bias of IEEE Std 952's gyro model and of rotorpy's IMU. A
sample is lost with probability `dropout`, independently. All drawn before the run (`draws`).

Delivery (`measure`, compiled). Sample s, taken at tick s * every, arrives `latency_ticks`
ticks later unless it is lost; between arrivals the controllers hold the last measurement that
arrived (a zero-order hold). The first sample (tick 0) always arrives, at once: the autopilot's
estimate is initialised before the run starts.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_COLUMNS,
                                          MEASURED_EULER, MEASURED_POSITION, MEASURED_VELOCITY)

NAME = 'measured_state'
# the measured quantities: each a block of 3 slots of the measured state, with its unit
QUANTITIES = ('position', 'velocity', 'attitude', 'body_rate')
BLOCKS = (MEASURED_POSITION, MEASURED_VELOCITY, MEASURED_EULER, MEASURED_BODY_RATES)
QUANTITY_UNITS = ('m', 'm/s', 'rad', 'rad/s')
UNITS = {**{f'{q}_noise': u for q, u in zip(QUANTITIES, QUANTITY_UNITS)},  # its keys' units
         **{f'{q}_bias': f'{u}/sqrt(s)' for q, u in zip(QUANTITIES, QUANTITY_UNITS)},
         'latency_ticks': '', 'dropout': ''}

# -- its constants row (`constants`) ----------------------------------------------------------
EVERY = 0               # control ticks between two samples
LATENCY = 1             # control ticks from a sample to its arrival
CONSTANT_COLUMNS = 2
# -- a sample's draws (`draws`, one row per sample) -------------------------------------------
DRAW_ERROR = 0          # its error e_s [the slots' units] (MEASURED_COLUMNS slots)
DRAW_DELIVERED = MEASURED_COLUMNS  # 1.0: it arrives, 0.0: lost
DRAW_COLUMNS = MEASURED_COLUMNS + 1
# -- one UAV's memory (`memory`) ---------------------------------------------------------------
HELD = 0                # the measurement its controllers hold (MEASURED_COLUMNS; NaN: none yet)
DELAY_LINE = MEASURED_COLUMNS  # the true states of the last latency + 1 ticks, by tick %
#                               (latency + 1) (rows of MEASURED_COLUMNS)


@dataclass(frozen=True)
class MeasuredStateSettings:
    """Its keys: per quantity of QUANTITIES its white noise and bias random walk."""
    noise: tuple[float, ...]         # standard deviation of the white noise [unit]
    bias: tuple[float, ...]          # intensity of the bias random walk [unit / sqrt(s)]
    latency_ticks: int               # control ticks from a sample to its arrival
    dropout: float                   # probability a sample is lost, in [0, 1)


def parse(d) -> MeasuredStateSettings:
    """Its keys read from `d` (the `sensors:` section): per quantity `{name}_noise` and
    `{name}_bias` (default 0), the latency in ticks (0) and the dropout probability (0)."""
    return MeasuredStateSettings(
        noise=tuple(d.non_negative(f'{q}_noise', 0.0) for q in QUANTITIES),
        bias=tuple(d.non_negative(f'{q}_bias', 0.0) for q in QUANTITIES),
        latency_ticks=d.count('latency_ticks', 0),
        dropout=d.number('dropout', 0.0, lambda v: 0 <= v < 1, 'must be within [0, 1)'))


def constants(settings: MeasuredStateSettings, every: int) -> np.ndarray:
    """Its constants row (EVERY, LATENCY)."""
    row = np.zeros(CONSTANT_COLUMNS)
    row[EVERY], row[LATENCY] = every, settings.latency_ticks
    return row


def memory(settings: MeasuredStateSettings) -> np.ndarray:
    """One UAV's memory at the start: nothing held (NaN), the delay line zero."""
    row = np.zeros(DELAY_LINE + (settings.latency_ticks + 1) * MEASURED_COLUMNS)
    row[HELD:HELD + MEASURED_COLUMNS] = math.nan
    return row


def sample_errors(settings: MeasuredStateSettings, n_uavs: int, samples: int, dt: float,
                  rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(errors (samples, n, MEASURED_COLUMNS) [the slots' units], delivered (samples, n)
    bool) of every sample, `dt` [s] apart, drawn from `rng` in a fixed order (white noise,
    bias steps, dropouts), so one seed gives one series."""
    noise = np.zeros(MEASURED_COLUMNS)
    walk = np.zeros(MEASURED_COLUMNS)
    for block, sigma, sigma_b in zip(BLOCKS, settings.noise, settings.bias):
        noise[block:block + 3] = sigma
        walk[block:block + 3] = sigma_b * math.sqrt(dt)
    white = rng.standard_normal((samples, n_uavs, MEASURED_COLUMNS)) * noise
    steps = rng.standard_normal((samples, n_uavs, MEASURED_COLUMNS)) * walk
    steps[0] = 0.0
    bias = np.cumsum(steps, axis=0)
    delivered = rng.random((samples, n_uavs)) >= settings.dropout
    return bias + white, delivered


def draws(settings: MeasuredStateSettings, n_uavs: int, samples: int, dt: float,
          rng: np.random.Generator) -> np.ndarray:
    """Every sample's draws (n_uavs, samples, DRAW_COLUMNS): `sample_errors` by UAV."""
    errors, delivered = sample_errors(settings, n_uavs, samples, dt, rng)
    rows = np.empty((n_uavs, samples, DRAW_COLUMNS))
    rows[:, :, DRAW_ERROR:DRAW_ERROR + MEASURED_COLUMNS] = errors.transpose(1, 0, 2)
    rows[:, :, DRAW_DELIVERED] = delivered.T
    return rows


@jit
def measure(constants, draws, memory, tick, truth, received):
    """What one UAV's controllers receive at control tick `tick` into received
    (MEASURED_COLUMNS,): the last sample that has arrived, with its error. truth
    (MEASURED_COLUMNS,) its measured state now (kept in the delay line, written here); memory
    its HELD measurement (updated here) and DELAY_LINE. A second call at the same tick gives
    the same result (it reads no state of its own making but HELD, which it sets to the same
    value)."""
    every = int(constants[EVERY])
    slots = int(constants[LATENCY]) + 1
    line = DELAY_LINE + (tick % slots) * MEASURED_COLUMNS
    for c in range(MEASURED_COLUMNS):
        memory[line + c] = truth[c]
    taken = max(tick - slots + 1, 0)  # the tick whose sample arrives now (before: tick 0's)
    sample = taken // every
    if taken % every == 0 and sample < draws.shape[0] and (
            draws[sample, DRAW_DELIVERED] != 0.0 or math.isnan(memory[HELD])):
        source = DELAY_LINE + (taken % slots) * MEASURED_COLUMNS
        for c in range(MEASURED_COLUMNS):
            memory[HELD + c] = memory[source + c] + draws[sample, DRAW_ERROR + c]
    for c in range(MEASURED_COLUMNS):
        received[c] = memory[HELD + c]
