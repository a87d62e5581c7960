"""A rigid body's attitude in the state: its block (layout BODY_*: the unit quaternion q =
(w, x, y, z), body -> world, and the body rates omega [rad/s]) for every UAV and a rigid
payload alike (issue 31, item 6). The rotation of a quaternion, the kinematics q_dot =
q (x) (0, omega) / 2, a small turn and the renormalisation after an RK4 step: the one place
of these equations for the compiled functions (the Euler angles the controllers read are
computed from q once, `measurement.quaternion_euler`). Slots are `physics.layout`'s.
"""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import BODY_QUATERNION


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
