"""A rigid body's attitude in the state: its block (layout BODY_*: the unit quaternion q =
(w, x, y, z), body -> world, and the body rates omega [rad/s]) for every UAV and a rigid
payload alike (issue 31, item 6). The rotation of a quaternion, the kinematics q_dot =
q (x) (0, omega) / 2, a small turn and the renormalisation after an RK4 step, the product of
quaternions, Exp and Log of a rotation vector (the IMU's, the motion capture's and the EKF's):
the one place of these equations for the compiled functions (the Euler angles the controllers
read are computed from q once, `measurement.quaternion_euler`). Slots are `physics.layout`'s.
"""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import BODY_QUATERNION

SMALL_ANGLE = 1e-12  # [rad] below which Exp and Log take their first-order forms


@jit
def quaternion_rotation(x, base):
    """R (3, 3), body -> world, of the unit quaternion (w, x, y, z) at x[base:]."""
    w, qx = x[base + BODY_QUATERNION], x[base + BODY_QUATERNION + 1]
    qy, qz = x[base + BODY_QUATERNION + 2], x[base + BODY_QUATERNION + 3]
    r = np.empty((3, 3))
    r[0, 0] = 1.0 - 2.0 * (qy * qy + qz * qz)
    r[0, 1] = 2.0 * (qx * qy - w * qz)
    r[0, 2] = 2.0 * (qx * qz + w * qy)
    r[1, 0] = 2.0 * (qx * qy + w * qz)
    r[1, 1] = 1.0 - 2.0 * (qx * qx + qz * qz)
    r[1, 2] = 2.0 * (qy * qz - w * qx)
    r[2, 0] = 2.0 * (qx * qz - w * qy)
    r[2, 1] = 2.0 * (qy * qz + w * qx)
    r[2, 2] = 1.0 - 2.0 * (qx * qx + qy * qy)
    return r


@jit
def quaternion_axis_z(x, base):
    """R e_z (3 floats) [unit, world]: the body z axis (a UAV's thrust axis, Eq. 2.6), the
    third column of `quaternion_rotation`'s R without forming R."""
    w, qx = x[base + BODY_QUATERNION], x[base + BODY_QUATERNION + 1]
    qy, qz = x[base + BODY_QUATERNION + 2], x[base + BODY_QUATERNION + 3]
    return (2.0 * (qx * qz + w * qy), 2.0 * (qy * qz - w * qx), 1.0 - 2.0 * (qx * qx + qy * qy))


@jit
def quaternion_rate(x, base, o0, o1, o2):
    """q (x) (0, omega) / 2 [1/s] of the quaternion q at x[base:] and a rate omega =
    (o0, o1, o2) [rad/s], body frame: q_dot, as 4 floats (w, x, y, z)."""
    qw, qx = x[base + BODY_QUATERNION], x[base + BODY_QUATERNION + 1]
    qy, qz = x[base + BODY_QUATERNION + 2], x[base + BODY_QUATERNION + 3]
    return (0.5 * (-qx * o0 - qy * o1 - qz * o2), 0.5 * (qw * o0 + qy * o2 - qz * o1),
            0.5 * (qw * o1 + qz * o0 - qx * o2), 0.5 * (qw * o2 + qx * o1 - qy * o0))


@jit
def normalize_quaternion(x, base):
    """The quaternion at x[base:] scaled back to unit length (after an RK4 step, so R stays
    orthonormal)."""
    norm = 0.0
    for k in range(4):
        norm += x[base + BODY_QUATERNION + k] * x[base + BODY_QUATERNION + k]
    norm = math.sqrt(norm)
    for k in range(4):
        x[base + BODY_QUATERNION + k] /= norm


@jit
def turn_quaternion(x, base, t0, t1, t2):
    """The quaternion at x[base:] turned by the small body-frame rotation (t0, t1, t2) [rad]:
    q -> q (x) (1, t / 2), back to unit length (first order in t, as the Newton steps that
    call it are)."""
    rate = quaternion_rate(x, base, t0, t1, t2)
    for k in range(4):
        x[base + BODY_QUATERNION + k] += rate[k]
    normalize_quaternion(x, base)


@jit
def quaternion_norm_error(x, base):
    """| |q| - 1 | of the quaternion at x[base:]: 0 to rounding after a step's renormalisation;
    larger, the state no longer represents an attitude."""
    norm = 0.0
    for k in range(4):
        norm += x[base + BODY_QUATERNION + k] * x[base + BODY_QUATERNION + k]
    return abs(math.sqrt(norm) - 1.0)


@jit
def quaternion_product(a0, a1, a2, a3, b0, b1, b2, b3):
    """The Hamilton product a (x) b of quaternions (w, x, y, z), as 4 floats."""
    return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3, a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1, a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)


@jit
def rotation_quaternion(t0, t1, t2):
    """Exp(t): the unit quaternion (w, x, y, z) of the rotation vector t [rad]."""
    angle = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    if angle < SMALL_ANGLE:
        return 1.0, 0.5 * t0, 0.5 * t1, 0.5 * t2
    s = math.sin(0.5 * angle) / angle
    return math.cos(0.5 * angle), s * t0, s * t1, s * t2


@jit
def quaternion_rotation_vector(w, x, y, z):
    """Log(q): the rotation vector [rad] (3 floats, angle in [0, pi]) of the unit quaternion
    (w, x, y, z) (q and -q the same rotation)."""
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    if s < SMALL_ANGLE:
        return 2.0 * x, 2.0 * y, 2.0 * z
    scale = 2.0 * math.atan2(s, w) / s
    return scale * x, scale * y, scale * z


@jit
def turn(q, base, t0, t1, t2):
    """The unit quaternion at q[base:base + 4] turned by the body-frame rotation vector t [rad]:
    q -> q (x) Exp(t), back to unit length."""
    e0, e1, e2, e3 = rotation_quaternion(t0, t1, t2)
    r0, r1, r2, r3 = quaternion_product(q[base], q[base + 1], q[base + 2], q[base + 3],
                                        e0, e1, e2, e3)
    norm = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2 + r3 * r3)
    q[base], q[base + 1], q[base + 2], q[base + 3] = r0 / norm, r1 / norm, r2 / norm, r3 / norm


@jit
def attitude_difference(q, base, z0, z1, z2, z3):
    """Log(q^-1 (x) z) [rad] (3 floats): the body-frame rotation from the quaternion at
    q[base:] to z (w, x, y, z), the attitude error a measurement z of it shows."""
    r0, r1, r2, r3 = quaternion_product(q[base], -q[base + 1], -q[base + 2], -q[base + 3],
                                        z0, z1, z2, z3)
    return quaternion_rotation_vector(r0, r1, r2, r3)
