"""`mocap`: motion capture (issue 33 item 1; docs/estimation.md): every UAV's position [m]
(world) and attitude (the quaternion body -> world) at its own rate, `latency` late, with white
noise and dropouts, as a Vicon or OptiTrack system streams a rigid body's pose.

Sample s, taken at tick s * every, carries position p + sigma_p w_p and attitude q (x)
Exp(sigma_theta w_theta) (a body-frame rotation of sigma_theta [rad] per axis), w
standard normal; it arrives `latency` [s] later (rounded to the nearest control tick) unless
lost (probability `dropout`, each sample independently). The first sample (tick 0) arrives
at once: the estimator starts from it. Errors drawn before the run (`draws`).

Preset `mocap_indoor` (docs/estimation.md cites each value): 100 Hz, 7 ms latency (a
Qualisys system measured end to end at ETH Zurich: 6-7 ms), 1 mm of position noise (a Vicon
system's dynamic error below 2 mm: Merriaux et al., Sensors 17(7) 1591, 2017), 5 mrad of
attitude noise (1 mm across a 0.2 m marker base) and 1 % of samples lost (assumed).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import rotation_quaternion, quaternion_product
from multilift_sim.physics.layout import MEASURED_EULER, MEASURED_POSITION
from multilift_sim.physics.measurement import euler_quaternion
from multilift_sim.sensors.outputs import (OUTPUT, DelayedSettings, delayed_protocol,
                                          delayed_sample, deliver, keep_truth, read_dropout)

NAME = 'mocap'
UNITS = {'position_noise': 'm', 'attitude_noise': 'rad', 'latency': 's', 'dropout': '',
         'preset': ''}
PRESETS = {'mocap_indoor': {'rate': 100.0, 'latency': 0.007, 'position_noise': 0.001,
                            'attitude_noise': 0.005, 'dropout': 0.01}}

# -- its output (after outputs.OUTPUT) ---------------------------------------------------------
OUTPUT_POSITION = 0         # p [m], world (3)
OUTPUT_QUATERNION = 3       # q (w, x, y, z), body -> world (4)
OUTPUT_COLUMNS = 7
# -- a sample's draws --------------------------------------------------------------------------
DRAW_POSITION = 0           # its position error [m] (3)
DRAW_ATTITUDE = 3           # its attitude error [rad], body rotation vector (3)
DRAW_DELIVERED = 6          # 1.0: it arrives, 0.0: lost
DRAW_COLUMNS = 7


@dataclass(frozen=True, kw_only=True)
class MocapSettings(DelayedSettings):
    """Its keys."""
    position_noise: float            # [m], standard deviation per axis
    attitude_noise: float            # [rad], standard deviation per body axis


# its preset_values, with_simulation, constants and memory: a delayed sensor's (outputs)
preset_values, with_simulation, constants, memory = delayed_protocol(OUTPUT_COLUMNS,
                                                                    PRESETS)


def parse(d) -> MocapSettings:
    """Its keys from `d` (the `mocap:` section), defaults its `preset`'s (else 0)."""
    preset = preset_values(d)
    return MocapSettings(
        position_noise=d.non_negative('position_noise', preset.get('position_noise', 0.0)),
        attitude_noise=d.non_negative('attitude_noise', preset.get('attitude_noise', 0.0)),
        latency=d.non_negative('latency', preset.get('latency', 0.0)),
        dropout=read_dropout(d, preset))


def draws(settings: MocapSettings, n_uavs: int, samples: int, dt: float,
          rng: np.random.Generator) -> np.ndarray:
    """Every sample's draws (n_uavs, samples, DRAW_COLUMNS) in a fixed order from `rng`
    (position noise, attitude noise, dropouts)."""
    rows = np.empty((n_uavs, samples, DRAW_COLUMNS))
    rows[:, :, DRAW_POSITION:DRAW_POSITION + 3] = (
        rng.standard_normal((n_uavs, samples, 3)) * settings.position_noise)
    rows[:, :, DRAW_ATTITUDE:DRAW_ATTITUDE + 3] = (
        rng.standard_normal((n_uavs, samples, 3)) * settings.attitude_noise)
    rows[:, :, DRAW_DELIVERED] = rng.random((n_uavs, samples)) >= settings.dropout
    return rows


@jit
def measure(constants, draws, memory, tick, truth, received):
    """The pose of `truth` (MEASURED_COLUMNS,) at `tick`, its quaternion from the Euler
    angles, into the delay line; a sample that arrives now (`outputs.delayed_sample`), its
    position error added and its attitude turned by its error, into the output."""
    line, source, sample = delayed_sample(constants, draws[:, DRAW_DELIVERED], memory, tick,
                                          OUTPUT_COLUMNS)
    if line < 0:
        return
    keep_truth(memory, line, OUTPUT_POSITION, truth, MEASURED_POSITION, 3)
    x, y, z, w = euler_quaternion(truth[MEASURED_EULER], truth[MEASURED_EULER + 1],
                                  truth[MEASURED_EULER + 2])
    q = line + OUTPUT_QUATERNION
    memory[q], memory[q + 1], memory[q + 2], memory[q + 3] = w, x, y, z
    if sample < 0:
        return
    deliver(memory, source, OUTPUT_POSITION, draws, sample, DRAW_POSITION, 3)
    e0, e1, e2, e3 = rotation_quaternion(draws[sample, DRAW_ATTITUDE],
                                         draws[sample, DRAW_ATTITUDE + 1],
                                         draws[sample, DRAW_ATTITUDE + 2])
    s = source + OUTPUT_QUATERNION
    o = OUTPUT + OUTPUT_QUATERNION
    memory[o], memory[o + 1], memory[o + 2], memory[o + 3] = quaternion_product(
        memory[s], memory[s + 1], memory[s + 2], memory[s + 3], e0, e1, e2, e3)
