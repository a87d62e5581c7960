"""`imu`: an inertial measurement unit on every UAV (issue 33 item 1; docs/estimation.md): an
accelerometer measuring the specific force f = R^T (a - g_w) [m/s^2] and a gyro the angular
rate [rad/s], both in the body frame FLU, each with white noise given by its noise density and
a bias that walks (Kalibr's and rotorpy's IMU model; IEEE Std 952's rate random walk).

A sample is the mean over its interval dt = 1 / rate (an integrated IMU's delta velocity and
delta angle divided by dt, what PX4's EKF2 fuses): from the true velocity v and attitude q at
the interval's ends,

    f = R(q_0)^T ((v_1 - v_0) / dt - g_w),     w = Log(q_0^-1 (x) q_1) / dt,

g_w = (0, 0, -g) (world z up), so that `estimators.error_state.propagate` run on exact samples
from the true state at the interval's start gives the true state at its end (to the position's
second order term). Errors, drawn before the run (`draws`), sample s:

    e_s = b_s + N / sqrt(dt) w_s,      b_s = b_(s-1) + sigma_b sqrt(dt) v_s,      b_0 = 0

with N the noise density [unit/sqrt(Hz)] (`*_noise_density`) and sigma_b the bias random walk
[unit sqrt(Hz)] (`*_random_walk`). The rate divides the control rate (so the physics rate):
one sample per `every` control ticks, the first at tick `every` (tick 0 starts the interval).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from multilift_sim.physics.attitude import attitude_difference, quaternion_rotation
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import MEASURED_EULER, MEASURED_VELOCITY
from multilift_sim.physics.measurement import euler_quaternion
from multilift_sim.sensors.outputs import ARRIVED, OUTPUT, TAKEN

NAME = 'imu'
UNITS = {'accelerometer_noise_density': 'm/s^2/sqrt(Hz)',
         'accelerometer_random_walk': 'm/s^3/sqrt(Hz)',
         'gyroscope_noise_density': 'rad/s/sqrt(Hz)',
         'gyroscope_random_walk': 'rad/s^2/sqrt(Hz)'}
# the Bosch BMI088 (the IMU of Pixhawk-class autopilots; docs/estimation.md cites each):
# noise densities from its datasheet (175 ug/sqrt(Hz), 0.014 deg/s/sqrt(Hz)), bias walks PX4
# EKF2's defaults (EKF2_ACC_B_NOISE 3e-3 m/s^3, EKF2_GYR_B_NOISE 1e-3 rad/s^2)
DEFAULTS = {'accelerometer_noise_density': 175e-6 * 9.80665,
            'accelerometer_random_walk': 3.0e-3,
            'gyroscope_noise_density': math.radians(0.014),
            'gyroscope_random_walk': 1.0e-3}

# -- its output (after outputs.OUTPUT) ---------------------------------------------------------
OUTPUT_SPECIFIC_FORCE = 0   # f [m/s^2], body FLU, mean over the interval (3)
OUTPUT_RATE = 3             # w [rad/s], body FLU, mean over the interval (3)
OUTPUT_COLUMNS = 6
# -- its constants row -------------------------------------------------------------------------
EVERY = 0                   # control ticks between two samples
PERIOD = 1                  # dt [s]
GRAVITY = 2                 # g [m/s^2]
CONSTANT_COLUMNS = 3
# -- one UAV's memory (after outputs.OUTPUT's block) ------------------------------------------
LAST_TICK = OUTPUT + OUTPUT_COLUMNS        # the tick measured last (-1: none)
START_VELOCITY = LAST_TICK + 1             # v at the interval's start [m/s], world (3)
START_QUATERNION = START_VELOCITY + 3      # q at the interval's start (w, x, y, z) (4)
MEMORY_COLUMNS = START_QUATERNION + 4


@dataclass(frozen=True)
class ImuSettings:
    """Its keys, and what the simulation fixes (`with_simulation`)."""
    noise_density: tuple[float, float]   # accelerometer, gyroscope [unit/sqrt(Hz)]
    random_walk: tuple[float, float]     # their bias random walks [unit sqrt(Hz)]
    period: float = math.nan             # dt [s]
    gravity: float = math.nan            # g [m/s^2]


def parse(d) -> ImuSettings:
    """Its keys from `d` (the `imu:` section), each >= 0, default the BMI088's (DEFAULTS)."""
    value = {key: d.non_negative(key, default) for key, default in DEFAULTS.items()}
    return ImuSettings(
        noise_density=(value['accelerometer_noise_density'], value['gyroscope_noise_density']),
        random_walk=(value['accelerometer_random_walk'], value['gyroscope_random_walk']))


def with_simulation(settings: ImuSettings, simulation, every: int) -> ImuSettings:
    """The settings with the sample interval [s] and gravity [m/s^2] of the simulation."""
    return replace(settings, period=every / simulation.control_rate,
                   gravity=simulation.gravity)


def constants(settings: ImuSettings, every: int) -> np.ndarray:
    row = np.zeros(CONSTANT_COLUMNS)
    row[EVERY], row[PERIOD], row[GRAVITY] = every, settings.period, settings.gravity
    return row


def memory(settings: ImuSettings) -> np.ndarray:
    """Nothing measured yet (ARRIVED and LAST_TICK -1)."""
    row = np.zeros(MEMORY_COLUMNS)
    row[ARRIVED] = row[TAKEN] = row[LAST_TICK] = -1.0
    return row


def draws(settings: ImuSettings, n_uavs: int, samples: int, dt: float,
          rng: np.random.Generator) -> np.ndarray:
    """Every sample's errors (n_uavs, samples, OUTPUT_COLUMNS) [m/s^2, rad/s], drawn in a fixed
    order (white noise, bias steps) from `rng`; sample 0 (tick 0) is none's."""
    white = np.repeat(np.array(settings.noise_density) / math.sqrt(dt), 3)
    walk = np.repeat(np.array(settings.random_walk) * math.sqrt(dt), 3)
    noise = rng.standard_normal((n_uavs, samples, OUTPUT_COLUMNS)) * white
    steps = rng.standard_normal((n_uavs, samples, OUTPUT_COLUMNS)) * walk
    steps[:, 0] = 0.0
    return np.cumsum(steps, axis=1) + noise


@jit
def measure(constants, draws, memory, tick, truth, received):
    """At control tick `tick`: on a sample tick after the first, the interval's mean specific
    force and rate from the true state `truth` (MEASURED_COLUMNS,) and the interval's start
    (kept in memory), plus the sample's errors, into the output (ARRIVED, TAKEN: this tick);
    received left alone. A second call at one tick changes nothing."""
    if memory[LAST_TICK] == tick:
        return
    memory[LAST_TICK] = tick
    every = int(constants[EVERY])
    if tick % every != 0:
        return
    q = np.empty(4)
    q[1], q[2], q[3], q[0] = euler_quaternion(truth[MEASURED_EULER], truth[MEASURED_EULER + 1],
                                              truth[MEASURED_EULER + 2])
    sample = tick // every
    if sample > 0 and sample < draws.shape[0]:
        dt = constants[PERIOD]
        start = quaternion_rotation(memory, START_QUATERNION)  # R(q_0), body -> world
        accel = np.empty(3)
        for j in range(3):
            accel[j] = (truth[MEASURED_VELOCITY + j] - memory[START_VELOCITY + j]) / dt
        accel[2] += constants[GRAVITY]
        rate = attitude_difference(memory, START_QUATERNION, q[0], q[1], q[2], q[3])
        out = OUTPUT
        for j in range(3):
            memory[out + OUTPUT_SPECIFIC_FORCE + j] = (
                start[0, j] * accel[0] + start[1, j] * accel[1] + start[2, j] * accel[2]
                + draws[sample, OUTPUT_SPECIFIC_FORCE + j])
            memory[out + OUTPUT_RATE + j] = rate[j] / dt + draws[sample, OUTPUT_RATE + j]
        memory[ARRIVED] = tick
        memory[TAKEN] = tick
    for j in range(3):
        memory[START_VELOCITY + j] = truth[MEASURED_VELOCITY + j]
    for j in range(4):
        memory[START_QUATERNION + j] = q[j]
