"""`cable_sensor`: a sensor at each UAV's attach point on its cable (issue 33 item 1;
docs/estimation.md): a two-axis gimbal whose encoders read the cable's direction as two angles
(physics.cable_sensing.gimbal_angles: body frame, zero hanging straight down), and a load cell
reading its tension, at one rate, `latency` late, with white noise and dropouts.

Sample s, taken at tick s * every, carries the true angles plus `encoder_noise` w [rad] each
and the tension plus `load_cell_noise` w' [N] (w, w' standard normal), and arrives `latency`
[s] later (to the nearest control tick) unless lost (probability `dropout`); the first
sample (tick 0) arrives at once. The
tension is the one of the last tick flown (physics.tick.advance's; NaN at tick 0, before any:
the load cell's first reading is then NaN). Errors drawn before the run (`draws`). Not
modelled: an encoder's non-linearity (a slowly varying error over the angle), the cable's
own bending at the gimbal, a load cell's creep and temperature drift.

Preset `cable_gimbal` (docs/estimation.md cites each value): AS5048A magnetic encoders (sensor
output noise 0.06 deg rms = 1.05e-3 rad; sampled at 10-12 kHz: no latency at the control
rate), a load cell of 5 kg (49 N) capacity with 0.013 % of full scale non-repeatability
(0.0064 N), at the control rate (100 Hz).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.cable_sensing import gimbal_angles
from multilift_sim.physics.layout import (MEASURED_EULER, SENSED_CABLE_DIRECTION,
                                          SENSED_CABLE_TENSION)
from multilift_sim.physics.measurement import euler_rotation
from multilift_sim.sensors.outputs import (DelayedSettings, delayed_protocol, delayed_sample,
                                          deliver, read_dropout)

NAME = 'cable_sensor'
UNITS = {'encoder_noise': 'rad', 'load_cell_noise': 'N', 'latency': 's', 'dropout': '',
         'preset': ''}
PRESETS = {'cable_gimbal': {'rate': 100.0, 'latency': 0.0,
                            'encoder_noise': math.radians(0.06),
                            'load_cell_noise': 0.013e-2 * 5.0 * 9.80665, 'dropout': 0.0}}

# -- its output (after outputs.OUTPUT) ---------------------------------------------------------
OUTPUT_ANGLES = 0           # the gimbal's angles (alpha, beta) [rad] (2)
OUTPUT_TENSION = 2          # T [N]
OUTPUT_COLUMNS = 3
# -- a sample's draws: its errors, in the output's order ([rad, rad, N]), then --------------------
DRAW_DELIVERED = OUTPUT_COLUMNS  # 1.0: it arrives, 0.0: lost
DRAW_COLUMNS = OUTPUT_COLUMNS + 1


@dataclass(frozen=True, kw_only=True)
class CableSensorSettings(DelayedSettings):
    """Its keys (and a delayed sensor's: latency [s], dropout)."""
    encoder_noise: float             # [rad], standard deviation of each gimbal angle
    load_cell_noise: float           # [N], standard deviation of the tension


# its preset_values, with_simulation, constants and memory: a delayed sensor's (outputs)
preset_values, with_simulation, constants, memory = delayed_protocol(OUTPUT_COLUMNS,
                                                                    PRESETS)


def parse(d) -> CableSensorSettings:
    """Its keys from `d` (the `cable_sensor:` section), each >= 0, defaults its `preset`'s
    (else 0)."""
    preset = preset_values(d)
    return CableSensorSettings(
        **{key: d.non_negative(key, preset.get(key, 0.0)) for key in (
            'encoder_noise', 'load_cell_noise', 'latency')},
        dropout=read_dropout(d, preset))


def draws(settings: CableSensorSettings, n_uavs: int, samples: int, dt: float,
          rng: np.random.Generator) -> np.ndarray:
    """Every sample's draws (n_uavs, samples, DRAW_COLUMNS) in a fixed order from `rng`
    (the angles' and the tension's noise, dropouts)."""
    sigma = np.array([settings.encoder_noise] * 2 + [settings.load_cell_noise])
    rows = np.empty((n_uavs, samples, DRAW_COLUMNS))
    rows[:, :, :OUTPUT_COLUMNS] = rng.standard_normal((n_uavs, samples, OUTPUT_COLUMNS)) * sigma
    rows[:, :, DRAW_DELIVERED] = rng.random((n_uavs, samples)) >= settings.dropout
    return rows


@jit
def measure(constants, draws, memory, tick, truth, received):
    """At control tick `tick`: the true gimbal angles (the cable's direction truth[
    SENSED_CABLE_DIRECTION:] in the body frame R^T d, R of the UAV's true ZYX angles) and
    tension into the delay line; the sample taken `latency` ticks ago, if one was, into the
    output with its errors (ARRIVED this tick, TAKEN its tick); received left alone. A second
    call at one tick changes nothing."""
    line, source, sample = delayed_sample(constants, draws[:, DRAW_DELIVERED], memory, tick,
                                          OUTPUT_COLUMNS)
    if line < 0:
        return
    r = euler_rotation(truth[MEASURED_EULER], truth[MEASURED_EULER + 1],
                       truth[MEASURED_EULER + 2])  # row by row
    d = SENSED_CABLE_DIRECTION
    body = np.empty(3)
    for j in range(3):  # column j of R . d
        body[j] = r[j] * truth[d] + r[3 + j] * truth[d + 1] + r[6 + j] * truth[d + 2]
    memory[line + OUTPUT_ANGLES], memory[line + OUTPUT_ANGLES + 1] = gimbal_angles(
        body[0], body[1], body[2])
    memory[line + OUTPUT_TENSION] = truth[SENSED_CABLE_TENSION]
    if sample < 0:
        return
    deliver(memory, source, 0, draws, sample, 0, OUTPUT_COLUMNS)
