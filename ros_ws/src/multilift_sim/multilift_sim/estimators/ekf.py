"""`ekf`: an error-state extended Kalman filter on every UAV (issue 33 item 2;
docs/estimation.md): IMU propagation of position, velocity, attitude and the IMU's biases
(`error_state.propagate`, at the IMU's rate), motion-capture updates of position and attitude
(`error_state.fuse`, each sample when it arrives), the way PX4's EKF2 is built. Needs the
scenario's `imu:` and `mocap:`. The filter assumes the sensors' own noise model (their keys:
densities, random walks, noise deviations), so its consistency can be checked (NEES, NIS).

Delayed samples: a motion-capture sample taken `latency` ticks before it arrives is compared
with the filter's nominal state at the tick it was taken (kept in a ring of the last latency
+ 1 ticks, shifted by every correction since), and the correction applied now; the cross
terms of the propagation between (PX4 fuses on a delayed horizon instead) are not modelled.
With no latency the update is the exact EKF's.

What the controllers receive: the estimate's position [m] and velocity [m/s] (world), the ZYX
Euler angles of its quaternion [rad] and the gyro's last rate less its estimated bias [rad/s]
(body FLU). The filter starts at tick 0 from the first motion-capture sample (position and
attitude, covariance that sample's noise), at rest (velocity 0 with `initial_velocity_noise`
[m/s] of deviation), biases 0 (their variance grows from 0 by their random walks: the IMU's
biases start at 0).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.estimators.error_state import (
    ERROR_ATTITUDE, ERROR_POSITION, ERROR_SIZE, ERROR_VELOCITY, NOISE_ACCEL, NOISE_ACCEL_WALK,
    NOISE_GYRO, NOISE_GYRO_WALK, NOMINAL_GYRO_BIAS, NOMINAL_POSITION, NOMINAL_QUATERNION,
    NOMINAL_SIZE, NOMINAL_VELOCITY, fuse, inject, propagate)
from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import attitude_difference, turn
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_EULER,
                                          MEASURED_POSITION, MEASURED_VELOCITY)
from multilift_sim.physics.measurement import quaternion_euler
from multilift_sim.sensors import imu, mocap
from multilift_sim.sensors.outputs import ARRIVED, OUTPUT, TAKEN

NAME = 'ekf'
UNITS = {'initial_velocity_noise': 'm/s'}
NEEDS = (imu.NAME, mocap.NAME)  # the sensors it reads

# -- its constants row -------------------------------------------------------------------------
IMU_ROW = 0                 # the IMU's row in the run's sensor arrays
AID_ROW = 1                 # the motion capture's
IMU_PERIOD = 2              # the IMU's dt [s]
GRAVITY = 3                 # g [m/s^2]
NOISE = 4                   # the IMU's noise (4: error_state.NOISE_*)
POSITION_VARIANCE = 8       # the motion capture's position noise variance [m^2]
ATTITUDE_VARIANCE = 9       # its attitude noise variance [rad^2]
INITIAL_VELOCITY_VARIANCE = 10  # [m^2/s^2]
HISTORY_SLOTS = 11          # the ring's length: the motion capture's latency + 1 [ticks]
CONSTANT_COLUMNS = 12
# -- one UAV's memory --------------------------------------------------------------------------
LAST_TICK = 0               # the tick estimated last (-1: none)
NIS = 1                     # the normalised innovation squared of the last update
NIS_TICK = 2                # the tick of that update (-1: none yet)
RATE = 3                    # the gyro's last rate less the bias estimate [rad/s], body (3)
NOMINAL = 6                 # the nominal state (error_state.NOMINAL_SIZE)
COVARIANCE = NOMINAL + NOMINAL_SIZE  # P, row by row (ERROR_SIZE^2)
HISTORY = COVARIANCE + ERROR_SIZE * ERROR_SIZE  # the ring: (p, q) of the last ticks (7 each)
POSE = 7                    # a ring entry's length: p (3), q (w, x, y, z) (4)
UPDATE_DOF = 6              # the NIS's degrees of freedom: position and attitude


@dataclass(frozen=True)
class EkfSettings:
    initial_velocity_noise: float    # [m/s], per axis


def parse(d) -> EkfSettings:
    return EkfSettings(initial_velocity_noise=d.non_negative('initial_velocity_noise', 0.1))


def needs(sensor_names) -> str:
    """'' when the scenario has the sensors it reads, else what is missing."""
    missing = [name for name in NEEDS if name not in sensor_names]
    return f'needs the sensors {", ".join(missing)} (sections {missing[0]}: ...)' if missing \
        else ''


def _config(scenario, name):
    return next(c for c in scenario.sensor_suite if c.model == name)


def constants(settings: EkfSettings, scenario, rows: dict) -> np.ndarray:
    """Its row from the scenario's IMU and motion capture (their settings: the filter assumes
    the sensors' own noise)."""
    unit, aid = _config(scenario, imu.NAME).settings, _config(scenario, mocap.NAME).settings
    row = np.zeros(CONSTANT_COLUMNS)
    row[IMU_ROW], row[AID_ROW] = rows[imu.NAME], rows[mocap.NAME]
    row[IMU_PERIOD], row[GRAVITY] = unit.period, unit.gravity
    row[NOISE + NOISE_ACCEL], row[NOISE + NOISE_GYRO] = unit.noise_density
    row[NOISE + NOISE_ACCEL_WALK], row[NOISE + NOISE_GYRO_WALK] = unit.random_walk
    row[POSITION_VARIANCE] = aid.position_noise ** 2
    row[ATTITUDE_VARIANCE] = aid.attitude_noise ** 2
    row[INITIAL_VELOCITY_VARIANCE] = settings.initial_velocity_noise ** 2
    row[HISTORY_SLOTS] = aid.latency_ticks + 1
    return row


def memory(settings: EkfSettings, scenario) -> np.ndarray:
    slots = _config(scenario, mocap.NAME).settings.latency_ticks + 1
    row = np.zeros(HISTORY + slots * POSE)
    row[LAST_TICK] = row[NIS_TICK] = -1.0
    return row


@jit
def keep_pose(x, memory, slot):
    """The nominal state x's position and quaternion into ring entry `slot`."""
    base = HISTORY + slot * POSE
    for j in range(3):
        memory[base + j] = x[NOMINAL_POSITION + j]
    for j in range(4):
        memory[base + 3 + j] = x[NOMINAL_QUATERNION + j]


@jit
def start(constants, aid, x, covariance):
    """The nominal state and covariance at the first motion-capture sample (aid: its memory)."""
    x[:] = 0.0
    for j in range(3):
        x[NOMINAL_POSITION + j] = aid[OUTPUT + mocap.OUTPUT_POSITION + j]
    for j in range(4):
        x[NOMINAL_QUATERNION + j] = aid[OUTPUT + mocap.OUTPUT_QUATERNION + j]
    covariance[:, :] = 0.0
    for j in range(3):
        covariance[ERROR_POSITION + j, ERROR_POSITION + j] = constants[POSITION_VARIANCE]
        covariance[ERROR_VELOCITY + j, ERROR_VELOCITY + j] = constants[
            INITIAL_VELOCITY_VARIANCE]
        covariance[ERROR_ATTITUDE + j, ERROR_ATTITUDE + j] = constants[ATTITUDE_VARIANCE]


@jit
def update(constants, aid, x, covariance, memory, tick):
    """The motion-capture sample that arrived at `tick` fused (against the ring's pose at the
    tick it was taken); its NIS kept."""
    slots = int(constants[HISTORY_SLOTS])
    base = HISTORY + (int(aid[TAKEN]) % slots) * POSE
    correction = np.zeros(ERROR_SIZE)
    nis = 0.0
    for j in range(3):
        nis += fuse(covariance, correction, ERROR_POSITION + j,
                    aid[OUTPUT + mocap.OUTPUT_POSITION + j] - memory[base + j],
                    constants[POSITION_VARIANCE])
    q = OUTPUT + mocap.OUTPUT_QUATERNION
    seen = attitude_difference(memory, base + 3, aid[q], aid[q + 1], aid[q + 2], aid[q + 3])
    for j in range(3):
        nis += fuse(covariance, correction, ERROR_ATTITUDE + j, seen[j],
                    constants[ATTITUDE_VARIANCE])
    inject(x, covariance, correction)
    for slot in range(slots):  # the ring shifted as the state was
        entry = HISTORY + slot * POSE
        for j in range(3):
            memory[entry + j] += correction[ERROR_POSITION + j]
        turn(memory, entry + 3, correction[ERROR_ATTITUDE], correction[ERROR_ATTITUDE + 1],
             correction[ERROR_ATTITUDE + 2])
    memory[NIS] = nis
    memory[NIS_TICK] = tick


@jit
def estimate(constants, sensors, memory, tick, received):
    """At control tick `tick`: the IMU's sample of this tick propagated, the motion capture's
    fused, the estimate into received (MEASURED_COLUMNS,). A second call at one tick writes
    the same."""
    x = memory[NOMINAL:NOMINAL + NOMINAL_SIZE]
    if memory[LAST_TICK] != tick:
        memory[LAST_TICK] = tick
        unit, aid = sensors[int(constants[IMU_ROW])], sensors[int(constants[AID_ROW])]
        covariance = memory[COVARIANCE:HISTORY].copy().reshape((ERROR_SIZE, ERROR_SIZE))
        slots = int(constants[HISTORY_SLOTS])
        if tick == 0:
            start(constants, aid, x, covariance)
            for slot in range(slots):
                keep_pose(x, memory, slot)
        else:
            if unit[ARRIVED] == tick:
                propagate(x, covariance, unit[OUTPUT + imu.OUTPUT_SPECIFIC_FORCE:],
                          unit[OUTPUT + imu.OUTPUT_RATE:], constants[IMU_PERIOD],
                          constants[GRAVITY], constants[NOISE:NOISE + 4])
                for j in range(3):
                    memory[RATE + j] = (unit[OUTPUT + imu.OUTPUT_RATE + j]
                                        - x[NOMINAL_GYRO_BIAS + j])
            keep_pose(x, memory, tick % slots)
            if aid[ARRIVED] == tick:
                update(constants, aid, x, covariance, memory, tick)
        memory[COVARIANCE:HISTORY] = covariance.reshape(ERROR_SIZE * ERROR_SIZE)
    for j in range(3):
        received[MEASURED_POSITION + j] = x[NOMINAL_POSITION + j]
        received[MEASURED_VELOCITY + j] = x[NOMINAL_VELOCITY + j]
        received[MEASURED_BODY_RATES + j] = memory[RATE + j]
    q = NOMINAL_QUATERNION
    (received[MEASURED_EULER], received[MEASURED_EULER + 1],
     received[MEASURED_EULER + 2]) = quaternion_euler(x[q], x[q + 1], x[q + 2], x[q + 3])
