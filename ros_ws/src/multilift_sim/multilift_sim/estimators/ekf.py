"""`ekf`: an error-state extended Kalman filter on every UAV (issue 33 item 2;
docs/estimation.md): IMU propagation of position, velocity, attitude and the IMU's biases
(`error_state.propagate`, at the IMU's rate), motion-capture updates of position and attitude
(`error_state.fuse`, each sample when it arrives), the way PX4's EKF2 is built. Needs the
scenario's `imu:` and `mocap:`; without motion capture it fuses `gnss:` (position and
velocity; its attitude then starts from a prior, level with yaw 0, `initial_attitude_noise`,
and its yaw is seen only when the UAV accelerates). The filter assumes the sensors' own noise
model (their keys: densities, random walks, noise deviations), so its consistency can be
checked (NEES, NIS).

Delayed samples, as PX4's EKF2 fuses them: the filter itself runs on a delayed horizon, the
motion capture's latency (L ticks) behind now, where each sample is fused at the tick it was
taken (exact: the IMU's samples of the last L ticks wait in a ring); the estimate of now
(what the controllers receive, its covariance) is that filter's state propagated over those L
IMU samples, each tick (EKF2's output predictor, here with its covariance).

What the controllers receive: the estimate's position [m] and velocity [m/s] (world), the ZYX
Euler angles of its quaternion [rad] and the gyro's last rate less its estimated bias [rad/s]
(body FLU). The filter starts at tick 0 from the first motion-capture sample (position and
attitude, covariance that sample's noise), at rest (velocity 0 with `initial_velocity_noise`
[m/s] of deviation, default 0.01: every run starts at rest, and a looser prior's first
corrections jolt the seed's high-gain loops: 0.1 m/s pushed a cable in twin_lift_realistic's
first 0.1 s), biases 0 (their variance grows from 0 by their random walks: the IMU's
biases start at 0).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.estimators.error_state import (
    ERROR_ATTITUDE, ERROR_GYRO_BIAS, ERROR_POSITION, ERROR_SIZE, ERROR_VELOCITY, NOISE_ACCEL,
    NOISE_ACCEL_WALK,
    NOISE_GYRO, NOISE_GYRO_WALK, NOMINAL_GYRO_BIAS, NOMINAL_POSITION, NOMINAL_QUATERNION,
    NOMINAL_SIZE, NOMINAL_VELOCITY, fuse, inject, propagate)
from multilift_sim.kernels import jit
from multilift_sim.estimators.published import (
    COVARIANCE_SIDE, ESTIMATE_ANGULAR, ESTIMATE_COLUMNS, ESTIMATE_LINEAR, ESTIMATE_ORIENTATION,
    ESTIMATE_POSE_COVARIANCE, ESTIMATE_POSITION, ESTIMATE_TWIST_COVARIANCE)
from multilift_sim.physics.attitude import attitude_difference, quaternion_rotation
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_EULER,
                                          MEASURED_POSITION, MEASURED_VELOCITY)
from multilift_sim.physics.measurement import quaternion_euler
from multilift_sim.sensors import gnss, imu, mocap
from multilift_sim.sensors.outputs import ARRIVED, OUTPUT, TAKEN

NAME = 'ekf'
UNITS = {'initial_velocity_noise': 'm/s', 'initial_attitude_noise': 'rad'}
AIDS = (mocap.NAME, gnss.NAME)  # what it fuses: motion capture, else GNSS

# -- its constants row -------------------------------------------------------------------------
IMU_ROW = 0                 # the IMU's row in the run's sensor arrays
AID_ROW = 1                 # the motion capture's (or the GNSS receiver's)
IMU_PERIOD = 2              # the IMU's dt [s]
GRAVITY = 3                 # g [m/s^2]
NOISE = 4                   # the IMU's noise (4: error_state.NOISE_*)
AID_VARIANCE = 8            # the fused components' noise variances (6): motion capture's
#                             position [m^2] and attitude [rad^2], GNSS's position, velocity
INITIAL_VELOCITY_VARIANCE = 14  # [m^2/s^2]
HISTORY_SLOTS = 15          # the ring's length: the aid's latency + 1 [ticks]
RATE_VARIANCE = 16          # a gyro sample's white noise variance N^2 / dt [rad^2/s^2]
AID_KIND = 17               # 0: motion capture, 1: GNSS
INITIAL_ATTITUDE_VARIANCE = 18  # with GNSS: the level, yaw-0 prior's [rad^2]
CONSTANT_COLUMNS = 19
# -- one UAV's memory --------------------------------------------------------------------------
#    first the estimate as published (estimators.published, ESTIMATE_COLUMNS), then
LAST_TICK = ESTIMATE_COLUMNS  # the tick estimated last (-1: none)
NIS = LAST_TICK + 1         # the normalised innovation squared of the last update
NIS_TICK = LAST_TICK + 2    # the tick of that update (-1: none yet)
RATE = LAST_TICK + 3        # the gyro's last rate less the bias estimate [rad/s], body (3)
NOMINAL = LAST_TICK + 6     # now: the nominal state (error_state.NOMINAL_SIZE)
COVARIANCE = NOMINAL + NOMINAL_SIZE  # now: P, row by row (ERROR_SIZE^2)
DELAYED = COVARIANCE + ERROR_SIZE * ERROR_SIZE  # the delayed horizon's nominal state
DELAYED_COVARIANCE = DELAYED + NOMINAL_SIZE     # and its P
HISTORY = DELAYED_COVARIANCE + ERROR_SIZE * ERROR_SIZE  # the ring of IMU samples, by tick %
#                                             (L + 1): each its tick (-1: none), f (3), w (3)
SAMPLE = 7                  # a ring entry's length
UPDATE_DOF = 6              # the NIS's degrees of freedom: position and attitude


@dataclass(frozen=True)
class EkfSettings:
    initial_velocity_noise: float    # [m/s], per axis (with motion capture)
    initial_attitude_noise: float    # [rad], per axis (with GNSS: the prior level, yaw 0)


def parse(d) -> EkfSettings:
    return EkfSettings(initial_velocity_noise=d.non_negative('initial_velocity_noise', 0.01),
                       initial_attitude_noise=d.non_negative('initial_attitude_noise', 0.05))


def needs(sensor_names) -> str:
    """'' when the scenario has the sensors it reads (`imu`, and `mocap` or `gnss`), else
    what is missing."""
    if imu.NAME not in sensor_names:
        return 'needs the sensors imu (section imu: ...)'
    if not any(aid in sensor_names for aid in AIDS):
        return 'needs the sensors mocap or gnss (section mocap: or gnss: ...)'
    return ''


def _config(scenario, name):
    return next((c for c in scenario.sensor_suite if c.model == name), None)


def _aid(scenario):
    """The sensor it fuses: the motion capture, else the GNSS receiver."""
    return _config(scenario, mocap.NAME) or _config(scenario, gnss.NAME)


def constants(settings: EkfSettings, scenario, rows: dict) -> np.ndarray:
    """Its row from the scenario's IMU and aid (their settings: the filter assumes the
    sensors' own noise)."""
    unit, config = _config(scenario, imu.NAME).settings, _aid(scenario)
    aid = config.settings
    row = np.zeros(CONSTANT_COLUMNS)
    row[IMU_ROW], row[AID_ROW] = rows[imu.NAME], rows[config.model]
    row[IMU_PERIOD], row[GRAVITY] = unit.period, unit.gravity
    row[NOISE + NOISE_ACCEL], row[NOISE + NOISE_GYRO] = unit.noise_density
    row[NOISE + NOISE_ACCEL_WALK], row[NOISE + NOISE_GYRO_WALK] = unit.random_walk
    if config.model == mocap.NAME:
        row[AID_VARIANCE:AID_VARIANCE + 6] = np.repeat(
            [aid.position_noise ** 2, aid.attitude_noise ** 2], 3)
    else:
        row[AID_KIND] = 1.0
        row[AID_VARIANCE:AID_VARIANCE + 6] = np.array(
            [aid.horizontal_position_noise] * 2 + [aid.vertical_position_noise]
            + [aid.velocity_noise] * 3) ** 2
    row[INITIAL_VELOCITY_VARIANCE] = settings.initial_velocity_noise ** 2
    row[INITIAL_ATTITUDE_VARIANCE] = settings.initial_attitude_noise ** 2
    row[HISTORY_SLOTS] = aid.latency_ticks + 1
    row[RATE_VARIANCE] = unit.noise_density[1] ** 2 / unit.period
    return row


def memory(settings: EkfSettings, scenario) -> np.ndarray:
    slots = _aid(scenario).settings.latency_ticks + 1
    row = np.zeros(HISTORY + slots * SAMPLE)
    row[LAST_TICK] = row[NIS_TICK] = -1.0
    row[HISTORY::SAMPLE] = -1.0
    return row


@jit
def start(constants, aid, x, covariance):
    """The nominal state and covariance at the aid's first sample (aid: its memory): the
    motion capture's pose (P its noise), at rest; or the GNSS's position and velocity (P its
    noise), level with yaw 0 (the prior INITIAL_ATTITUDE_VARIANCE)."""
    x[:] = 0.0
    covariance[:, :] = 0.0
    gnss_aid = constants[AID_KIND] == 1.0
    for j in range(3):
        x[NOMINAL_POSITION + j] = aid[OUTPUT + j]  # both outputs start with the position
        covariance[ERROR_POSITION + j, ERROR_POSITION + j] = constants[AID_VARIANCE + j]
        if gnss_aid:
            x[NOMINAL_VELOCITY + j] = aid[OUTPUT + gnss.OUTPUT_VELOCITY + j]
            covariance[ERROR_VELOCITY + j, ERROR_VELOCITY + j] = constants[AID_VARIANCE + 3 + j]
            covariance[ERROR_ATTITUDE + j, ERROR_ATTITUDE + j] = constants[
                INITIAL_ATTITUDE_VARIANCE]
        else:
            covariance[ERROR_VELOCITY + j, ERROR_VELOCITY + j] = constants[
                INITIAL_VELOCITY_VARIANCE]
            covariance[ERROR_ATTITUDE + j, ERROR_ATTITUDE + j] = constants[AID_VARIANCE + 3 + j]
    if gnss_aid:
        x[NOMINAL_QUATERNION] = 1.0
    else:
        for j in range(4):
            x[NOMINAL_QUATERNION + j] = aid[OUTPUT + mocap.OUTPUT_QUATERNION + j]


@jit
def update(constants, aid, x, covariance, memory, tick):
    """The aid's sample that arrived at `tick` fused into the delayed horizon's nominal state x
    and covariance (the tick it was taken): the motion capture's position and attitude, or the
    GNSS's position and velocity; its NIS kept."""
    correction = np.zeros(ERROR_SIZE)
    nis = 0.0
    for j in range(3):
        nis += fuse(covariance, correction, ERROR_POSITION + j,
                    aid[OUTPUT + j] - x[NOMINAL_POSITION + j], constants[AID_VARIANCE + j])
    if constants[AID_KIND] == 1.0:
        for j in range(3):
            nis += fuse(covariance, correction, ERROR_VELOCITY + j,
                        aid[OUTPUT + gnss.OUTPUT_VELOCITY + j] - x[NOMINAL_VELOCITY + j],
                        constants[AID_VARIANCE + 3 + j])
    else:
        q = OUTPUT + mocap.OUTPUT_QUATERNION
        seen = attitude_difference(x, NOMINAL_QUATERNION, aid[q], aid[q + 1], aid[q + 2],
                                   aid[q + 3])
        for j in range(3):
            nis += fuse(covariance, correction, ERROR_ATTITUDE + j, seen[j],
                        constants[AID_VARIANCE + 3 + j])
    inject(x, covariance, correction)
    memory[NIS] = nis
    memory[NIS_TICK] = tick


@jit
def propagate_sample(constants, memory, tick, x, covariance):
    """x and covariance propagated by the ring's IMU sample of `tick`, if it holds one."""
    entry = HISTORY + (tick % int(constants[HISTORY_SLOTS])) * SAMPLE
    if tick >= 1 and memory[entry] == tick:
        propagate(x, covariance, memory[entry + 1:entry + 4], memory[entry + 4:entry + 7],
                  constants[IMU_PERIOD], constants[GRAVITY], constants[NOISE:NOISE + 4])


@jit
def publish(constants, x, covariance, memory):
    """The estimate as /uav{i}/estimate carries it into memory's first ESTIMATE_COLUMNS
    (estimators.published): the pose, its covariance with the attitude error turned into the
    world's axes (R P_theta R^T; the cross terms R P_p,theta), the velocity in the body frame
    R^T v with its covariance (R^T P_v R, plus [v_b]x for the attitude error: v_b = Exp(-dtheta)
    R^T v), the rate (the gyro less its bias: P_bg plus a sample's noise N^2 / dt)."""
    q = NOMINAL_QUATERNION
    rotation = quaternion_rotation(x, q)
    for j in range(3):
        memory[ESTIMATE_POSITION + j] = x[NOMINAL_POSITION + j]
        memory[ESTIMATE_ANGULAR + j] = memory[RATE + j]
    memory[ESTIMATE_ORIENTATION], memory[ESTIMATE_ORIENTATION + 1] = x[q + 1], x[q + 2]
    memory[ESTIMATE_ORIENTATION + 2], memory[ESTIMATE_ORIENTATION + 3] = x[q + 3], x[q]
    body = np.zeros(3)
    for r in range(3):
        for c in range(3):
            body[r] += rotation[c, r] * x[NOMINAL_VELOCITY + c]
        memory[ESTIMATE_LINEAR + r] = body[r]
    pose = np.zeros((6, ERROR_SIZE))  # d(pose) / d(error state)
    twist = np.zeros((6, ERROR_SIZE))  # d(twist) / d(error state)
    for r in range(3):
        pose[r, ERROR_POSITION + r] = 1.0
        twist[3 + r, ERROR_GYRO_BIAS + r] = -1.0
        for c in range(3):
            pose[3 + r, ERROR_ATTITUDE + c] = rotation[r, c]
            twist[r, ERROR_VELOCITY + c] = rotation[c, r]
    # [v_b]x: the body velocity seen through the attitude error
    twist[0, ERROR_ATTITUDE + 1], twist[0, ERROR_ATTITUDE + 2] = -body[2], body[1]
    twist[1, ERROR_ATTITUDE], twist[1, ERROR_ATTITUDE + 2] = body[2], -body[0]
    twist[2, ERROR_ATTITUDE], twist[2, ERROR_ATTITUDE + 1] = -body[1], body[0]
    for jacobian, start in ((pose, ESTIMATE_POSE_COVARIANCE), (twist, ESTIMATE_TWIST_COVARIANCE)):
        product = np.zeros((6, ERROR_SIZE))
        for r in range(6):
            for k in range(ERROR_SIZE):
                if jacobian[r, k] != 0.0:
                    for c in range(ERROR_SIZE):
                        product[r, c] += jacobian[r, k] * covariance[k, c]
        for r in range(6):  # J (J P)^T = J P J^T (P symmetric), over J's nonzeros
            for c in range(6):
                memory[start + COVARIANCE_SIDE * r + c] = 0.0
            for k in range(ERROR_SIZE):
                if jacobian[r, k] != 0.0:
                    for c in range(6):
                        memory[start + COVARIANCE_SIDE * r + c] += jacobian[r, k] * product[c, k]
    for j in range(3):
        memory[ESTIMATE_TWIST_COVARIANCE + COVARIANCE_SIDE * (3 + j) + 3 + j] += \
            constants[RATE_VARIANCE]


@jit
def estimate(constants, sensors, memory, tick, received):
    """At control tick `tick`: the IMU's sample of this tick into the ring; the delayed
    horizon (tick - L) propagated by the sample of its tick and the motion-capture sample
    taken then fused; now's estimate that propagated over the ring's later samples, into
    received (MEASURED_COLUMNS,). A second call at one tick writes the same."""
    x = memory[NOMINAL:NOMINAL + NOMINAL_SIZE]
    if memory[LAST_TICK] != tick:
        memory[LAST_TICK] = tick
        unit, aid = sensors[int(constants[IMU_ROW])], sensors[int(constants[AID_ROW])]
        slots = int(constants[HISTORY_SLOTS])
        delayed = memory[DELAYED:DELAYED + NOMINAL_SIZE]
        shape = (ERROR_SIZE, ERROR_SIZE)
        covariance = memory[DELAYED_COVARIANCE:HISTORY].copy().reshape(shape)
        if tick == 0:
            start(constants, aid, delayed, covariance)
        if unit[ARRIVED] == tick and tick > 0:
            entry = HISTORY + (tick % slots) * SAMPLE
            memory[entry] = tick
            for j in range(6):
                memory[entry + 1 + j] = unit[OUTPUT + imu.OUTPUT_SPECIFIC_FORCE + j]
        horizon = tick - slots + 1
        propagate_sample(constants, memory, horizon, delayed, covariance)
        if aid[ARRIVED] == tick and tick > 0 and aid[TAKEN] == horizon:
            update(constants, aid, delayed, covariance, memory, tick)
        memory[DELAYED_COVARIANCE:HISTORY] = covariance.reshape(ERROR_SIZE * ERROR_SIZE)
        x[:] = delayed
        for later in range(max(horizon + 1, 1), tick + 1):  # the output predictor
            propagate_sample(constants, memory, later, x, covariance)
        memory[COVARIANCE:DELAYED] = covariance.reshape(ERROR_SIZE * ERROR_SIZE)
        if unit[ARRIVED] == tick:
            for j in range(3):
                memory[RATE + j] = (unit[OUTPUT + imu.OUTPUT_RATE + j]
                                    - x[NOMINAL_GYRO_BIAS + j])
        publish(constants, x, covariance, memory)
    for j in range(3):
        received[MEASURED_POSITION + j] = x[NOMINAL_POSITION + j]
        received[MEASURED_VELOCITY + j] = x[NOMINAL_VELOCITY + j]
        received[MEASURED_BODY_RATES + j] = memory[RATE + j]
    q = NOMINAL_QUATERNION
    (received[MEASURED_EULER], received[MEASURED_EULER + 1],
     received[MEASURED_EULER + 2]) = quaternion_euler(x[q], x[q + 1], x[q + 2], x[q + 3])
