"""The error-state extended Kalman filter's equations (issue 33 item 2; docs/estimation.md),
written once as compiled functions over arrays, for every estimator part that uses them
(`estimators.ekf`). Frames: world z up (ENU-like, gravity (0, 0, -g)), body FLU; SI units.

The nominal state x (NOMINAL_SIZE,): position p [m] and velocity v [m/s] (world), the unit
quaternion q = (w, x, y, z) body -> world, the accelerometer's bias b_a [m/s^2] and the gyro's
b_g [rad/s] (body). The error state dx (ERROR_SIZE,): dp, dv, the attitude error dtheta [rad] as
a body-frame rotation vector (q_true = q (x) Exp(dtheta)), db_a, db_g. Its covariance P
(ERROR_SIZE, ERROR_SIZE). Sola, "Quaternion kinematics for the error-state Kalman filter"
(2017), Sec. 5.3 (local angular error, discrete time), with the IMU's samples integrated
increments over the sample interval dt (PX4 EKF2 takes delta angles and delta velocities):

    a_w = R (a_m - b_a) + g_w,   p += v dt + a_w dt^2 / 2,   v += a_w dt,
    q = q (x) Exp((w_m - b_g) dt)

and the error's transition F (`propagate`) with the noise the sensor draws (`sensors.imu`):
white noise of density N [unit/sqrt(Hz)] averaged over dt (variance N^2 / dt per sample,
entering v as dt, p as dt^2 / 2, theta as dt) and the biases' random walks (variance
sigma_b^2 dt per sample, stepped before the sample they bias).

Measurements (`fuse`) are of single components of the error state (H a row of the identity:
a position, a velocity or an attitude-error component), fused one scalar at a time; with
independent noises this is the joint update, and the sum of the scalar normalised
innovations squared is the joint NIS (Bar-Shalom, Li, Kirubarajan 2001, Sec. 5.4).
"""

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import quaternion_rotation, rotation_quaternion, turn

# -- the nominal state's slots (NOMINAL_SIZE,) -------------------------------------------------
NOMINAL_POSITION = 0        # p [m], world (3)
NOMINAL_VELOCITY = 3        # v [m/s], world (3)
NOMINAL_QUATERNION = 6      # q (w, x, y, z), body -> world (4)
NOMINAL_ACCEL_BIAS = 10     # b_a [m/s^2], body (3)
NOMINAL_GYRO_BIAS = 13      # b_g [rad/s], body (3)
NOMINAL_SIZE = 16
# -- the error state's slots (ERROR_SIZE,) ----------------------------------------------------
ERROR_POSITION = 0          # dp [m]
ERROR_VELOCITY = 3          # dv [m/s]
ERROR_ATTITUDE = 6          # dtheta [rad], body
ERROR_ACCEL_BIAS = 9        # db_a [m/s^2]
ERROR_GYRO_BIAS = 12        # db_g [rad/s]
ERROR_SIZE = 15
# -- the IMU's noise, as `propagate` reads it (4,) --------------------------------------------
NOISE_ACCEL = 0             # accelerometer white noise density [m/s^2/sqrt(Hz)]
NOISE_GYRO = 1              # gyro white noise density [rad/s/sqrt(Hz)]
NOISE_ACCEL_WALK = 2        # accelerometer bias random walk [m/s^3/sqrt(Hz)]
NOISE_GYRO_WALK = 3         # gyro bias random walk [rad/s^2/sqrt(Hz)]


@jit
def propagate(x, covariance, accel, gyro, dt, gravity, noise):
    """One IMU sample: the nominal state x (NOMINAL_SIZE,) and the covariance (ERROR_SIZE,
    ERROR_SIZE) over its interval dt [s], from the accelerometer's mean specific force accel
    (3,) [m/s^2] and the gyro's mean rate gyro (3,) [rad/s] (body FLU), gravity [m/s^2]
    (world -z), the IMU's noise (4,: NOISE_*). The biases' walks first (they step before
    the sample they bias), then P = F P F^T + Q (module docstring)."""
    for j in range(3):
        covariance[ERROR_ACCEL_BIAS + j, ERROR_ACCEL_BIAS + j] += (
            noise[NOISE_ACCEL_WALK] ** 2 * dt)
        covariance[ERROR_GYRO_BIAS + j, ERROR_GYRO_BIAS + j] += noise[NOISE_GYRO_WALK] ** 2 * dt
    rotation = quaternion_rotation(x, NOMINAL_QUATERNION)
    a_body = np.empty(3)
    rate = np.empty(3)
    for j in range(3):
        a_body[j] = accel[j] - x[NOMINAL_ACCEL_BIAS + j]
        rate[j] = (gyro[j] - x[NOMINAL_GYRO_BIAS + j]) * dt
    a_world = np.zeros(3)
    for r in range(3):
        for c in range(3):
            a_world[r] += rotation[r, c] * a_body[c]
    a_world[2] -= gravity
    # F: identity, then its blocks
    f = np.eye(ERROR_SIZE)
    skew = np.zeros((3, 3))  # R [a_body]_x
    for r in range(3):
        skew[r, 0] = rotation[r, 1] * a_body[2] - rotation[r, 2] * a_body[1]
        skew[r, 1] = rotation[r, 2] * a_body[0] - rotation[r, 0] * a_body[2]
        skew[r, 2] = rotation[r, 0] * a_body[1] - rotation[r, 1] * a_body[0]
    q_step = np.empty(4)
    q_step[0], q_step[1], q_step[2], q_step[3] = rotation_quaternion(rate[0], rate[1], rate[2])
    turned = quaternion_rotation(q_step, 0)  # R(w dt): the error's transition is its transpose
    for r in range(3):
        f[ERROR_POSITION + r, ERROR_VELOCITY + r] = dt
        for c in range(3):
            f[ERROR_POSITION + r, ERROR_ATTITUDE + c] = -0.5 * dt * dt * skew[r, c]
            f[ERROR_POSITION + r, ERROR_ACCEL_BIAS + c] = -0.5 * dt * dt * rotation[r, c]
            f[ERROR_VELOCITY + r, ERROR_ATTITUDE + c] = -dt * skew[r, c]
            f[ERROR_VELOCITY + r, ERROR_ACCEL_BIAS + c] = -dt * rotation[r, c]
            f[ERROR_ATTITUDE + r, ERROR_ATTITUDE + c] = turned[c, r]
        f[ERROR_ATTITUDE + r, ERROR_GYRO_BIAS + r] = -dt
    # the nominal state
    for j in range(3):
        x[NOMINAL_POSITION + j] += (x[NOMINAL_VELOCITY + j] * dt
                                    + 0.5 * a_world[j] * dt * dt)
        x[NOMINAL_VELOCITY + j] += a_world[j] * dt
    turn(x, NOMINAL_QUATERNION, rate[0], rate[1], rate[2])
    # P = F P F^T + Q, as F (F P)^T (P symmetric), both products over F's nonzeros only
    fp = np.zeros((ERROR_SIZE, ERROR_SIZE))
    for r in range(ERROR_SIZE):
        for k in range(ERROR_SIZE):
            if f[r, k] != 0.0:
                for c in range(ERROR_SIZE):
                    fp[r, c] += f[r, k] * covariance[k, c]
    covariance[:, :] = 0.0
    for r in range(ERROR_SIZE):
        for k in range(ERROR_SIZE):
            if f[r, k] != 0.0:
                for c in range(ERROR_SIZE):
                    covariance[r, c] += f[r, k] * fp[c, k]
    accel_white = noise[NOISE_ACCEL] ** 2  # N^2 / dt per sample, through dt^2/2 and dt
    for j in range(3):
        p, v, a = ERROR_POSITION + j, ERROR_VELOCITY + j, ERROR_ATTITUDE + j
        covariance[p, p] += 0.25 * dt ** 3 * accel_white
        covariance[p, v] += 0.5 * dt * dt * accel_white
        covariance[v, p] += 0.5 * dt * dt * accel_white
        covariance[v, v] += dt * accel_white
        covariance[a, a] += dt * noise[NOISE_GYRO] ** 2


@jit
def fuse(covariance, correction, component, innovation, variance):
    """One scalar measurement of error-state component `component` (H = its identity row):
    innovation [its unit] against the nominal state, noise `variance`; the error estimate
    `correction` (ERROR_SIZE,) and the covariance updated (P - P h h^T P / s). Returns the
    normalised innovation squared (innovation - correction[component])^2 / s."""
    s = covariance[component, component] + variance
    residual = innovation - correction[component]
    gain = covariance[:, component] / s
    row = covariance[component, :].copy()
    for r in range(ERROR_SIZE):
        correction[r] += gain[r] * residual
        for c in range(ERROR_SIZE):
            covariance[r, c] -= gain[r] * row[c]
    return residual * residual / s


@jit
def inject(x, covariance, correction):
    """The error estimate `correction` (ERROR_SIZE,) moved into the nominal state x (the
    quaternion turned by its dtheta) and the covariance made symmetric again; the reset's
    Jacobian (I - [dtheta / 2]_x, Sola Eq. 287) is taken as I (second order in dtheta)."""
    for j in range(3):
        x[NOMINAL_POSITION + j] += correction[ERROR_POSITION + j]
        x[NOMINAL_VELOCITY + j] += correction[ERROR_VELOCITY + j]
        x[NOMINAL_ACCEL_BIAS + j] += correction[ERROR_ACCEL_BIAS + j]
        x[NOMINAL_GYRO_BIAS + j] += correction[ERROR_GYRO_BIAS + j]
    turn(x, NOMINAL_QUATERNION, correction[ERROR_ATTITUDE], correction[ERROR_ATTITUDE + 1],
         correction[ERROR_ATTITUDE + 2])
    for r in range(ERROR_SIZE):
        for c in range(r + 1, ERROR_SIZE):
            mean = 0.5 * (covariance[r, c] + covariance[c, r])
            covariance[r, c] = mean
            covariance[c, r] = mean
