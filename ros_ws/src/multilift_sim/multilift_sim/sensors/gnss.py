"""`gnss`: a GNSS receiver on every UAV (issue 33 item 1; docs/estimation.md): its position [m]
and velocity [m/s] (world) at its own rate, `latency` late, with white noise and dropouts.

Sample s, taken at tick s * every, carries p + (sigma_h w_x, sigma_h w_y, sigma_v w_z) and
v + sigma_v' w', w standard normal, and arrives `latency` [s] later (to the nearest control
tick) unless lost (probability `dropout`). The first sample (tick 0) arrives at once. Errors
drawn before the run (`draws`). A real receiver's error wanders slowly (multipath, the
atmosphere); white noise is the datasheets' figure, not that correlation: not modelled.

Preset `gnss_outdoor` (docs/estimation.md cites each value): a u-blox M8 receiver (MAX-M8Q):
10 Hz, 2.5 m CEP horizontal (sigma = CEP / 1.1774 = 2.12 m per axis), vertical assumed twice
that, velocity 0.05 m/s, 110 ms latency (PX4 EKF2's default EKF2_GPS_DELAY), none lost.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import MEASURED_POSITION, MEASURED_VELOCITY
from multilift_sim.sensors.outputs import (DelayedSettings, delayed_protocol, delayed_sample,
                                          deliver, keep_truth, read_dropout)

NAME = 'gnss'
UNITS = {'horizontal_position_noise': 'm', 'vertical_position_noise': 'm',
         'velocity_noise': 'm/s', 'latency': 's', 'dropout': '', 'preset': ''}
CEP_SIGMA = 1.1774  # CEP / sigma of a circular normal distribution (sqrt(2 ln 2))
PRESETS = {'gnss_outdoor': {'rate': 10.0, 'latency': 0.11,
                            'horizontal_position_noise': 2.5 / CEP_SIGMA,
                            'vertical_position_noise': 2.0 * 2.5 / CEP_SIGMA,
                            'velocity_noise': 0.05, 'dropout': 0.0}}

# -- its output (after outputs.OUTPUT) ---------------------------------------------------------
OUTPUT_POSITION = 0         # p [m], world (3)
OUTPUT_VELOCITY = 3         # v [m/s], world (3)
OUTPUT_COLUMNS = 6
# -- a sample's draws --------------------------------------------------------------------------
DRAW_ERROR = 0              # its position and velocity errors [m, m/s] (6)
DRAW_DELIVERED = 6          # 1.0: it arrives, 0.0: lost
DRAW_COLUMNS = 7


@dataclass(frozen=True, kw_only=True)
class GnssSettings(DelayedSettings):
    horizontal_position_noise: float  # [m], standard deviation per horizontal axis
    vertical_position_noise: float    # [m]
    velocity_noise: float             # [m/s], per axis


# its preset_values, with_simulation, constants and memory: a delayed sensor's (outputs)
preset_values, with_simulation, constants, memory = delayed_protocol(OUTPUT_COLUMNS,
                                                                    PRESETS)


def parse(d) -> GnssSettings:
    """Its keys from `d` (the `gnss:` section), defaults its `preset`'s (else 0)."""
    preset = preset_values(d)
    return GnssSettings(
        **{key: d.non_negative(key, preset.get(key, 0.0)) for key in (
            'horizontal_position_noise', 'vertical_position_noise', 'velocity_noise',
            'latency')},
        dropout=read_dropout(d, preset))


def draws(settings: GnssSettings, n_uavs: int, samples: int, dt: float,
          rng: np.random.Generator) -> np.ndarray:
    """Every sample's draws (n_uavs, samples, DRAW_COLUMNS) in a fixed order from `rng`
    (position and velocity noise, dropouts)."""
    sigma = np.array([settings.horizontal_position_noise] * 2
                     + [settings.vertical_position_noise] + [settings.velocity_noise] * 3)
    rows = np.empty((n_uavs, samples, DRAW_COLUMNS))
    rows[:, :, DRAW_ERROR:DRAW_ERROR + 6] = rng.standard_normal((n_uavs, samples, 6)) * sigma
    rows[:, :, DRAW_DELIVERED] = rng.random((n_uavs, samples)) >= settings.dropout
    return rows


@jit
def measure(constants, draws, memory, tick, truth, received):
    """UAV truth's position and velocity at `tick` into the delay line and, when a sample
    arrives now (`outputs.delayed_sample`: latency, dropouts, one call a tick), that sample
    plus its errors into the output; received is left alone."""
    line, source, sample = delayed_sample(constants, draws[:, DRAW_DELIVERED], memory, tick,
                                          OUTPUT_COLUMNS)
    if line < 0:
        return
    keep_truth(memory, line, OUTPUT_POSITION, truth, MEASURED_POSITION, 3)
    keep_truth(memory, line, OUTPUT_VELOCITY, truth, MEASURED_VELOCITY, 3)
    if sample >= 0:
        deliver(memory, source, 0, draws, sample, DRAW_ERROR, OUTPUT_COLUMNS)
