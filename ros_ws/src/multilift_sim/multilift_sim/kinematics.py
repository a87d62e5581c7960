"""Attitude kinematics with ZYX Euler angles (seed Eq. 2.3-2.8).

``eta = (roll phi, pitch theta, yaw psi)`` [rad]. Every function accepts one attitude of shape
(3,) or a stack of shape (..., 3), e.g. (n, 3) for the n UAVs of a formation, and returns the
matching (..., 3, 3) stack. The formulas hold in the world (z-up, FLU) frame of multilift and,
unchanged, in the seed's z-down/FRD frame (see frames.py).
"""
from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim import kernels
from multilift_sim.physics.measurement import (euler_quaternions, euler_rotations,
                                              quaternion_eulers)


def _angles(eta: ArrayLike) -> np.ndarray:
    angles = np.asarray(eta, dtype=float)
    if angles.shape[-1:] != (3,):
        raise ValueError(f'Euler angles must have shape (..., 3), got shape {angles.shape}')
    return angles


def rotation_matrix(eta: ArrayLike) -> np.ndarray:
    """Rotation matrix ``R = Rz(psi) Ry(theta) Rx(phi)`` mapping body to world (seed Eq. 2.6).

    eta: Euler angles [rad], shape (..., 3). Returns shape (..., 3, 3); a body-frame vector
    ``v_b`` is ``R @ v_b`` in the world frame. physics.measurement.euler_rotation over the stack:
    the R the simulator reports each tick (odometry_states), written once.
    """
    return _over_stack(euler_rotations, eta, (3, 3))


def euler_rate_matrix(eta: ArrayLike) -> np.ndarray:
    """Matrix W of seed Eq. 2.7: body angular rates ``omega = W(eta) eta_dot`` [rad/s].

    eta: Euler angles [rad], shape (..., 3). Returns shape (..., 3, 3). W depends on roll and
    pitch only and is singular at ``theta = +-pi/2`` (det W = cos theta).
    """
    angles = _angles(eta)
    s_phi, s_theta, _ = np.moveaxis(np.sin(angles), -1, 0)
    c_phi, c_theta, _ = np.moveaxis(np.cos(angles), -1, 0)
    w = np.zeros(angles.shape + (3,))
    w[..., 0, 0] = 1.0
    w[..., 0, 2] = -s_theta
    w[..., 1, 1] = c_phi
    w[..., 1, 2] = s_phi * c_theta
    w[..., 2, 1] = -s_phi
    w[..., 2, 2] = c_phi * c_theta
    return w


def euler_rate_matrix_inverse(eta: ArrayLike) -> np.ndarray:
    """Inverse of W (seed Eq. 2.8): ``eta_dot = W^-1 omega``. Shape (..., 3) -> (..., 3, 3)."""
    angles = _angles(eta)
    s_phi, s_theta, _ = np.moveaxis(np.sin(angles), -1, 0)
    c_phi, c_theta, _ = np.moveaxis(np.cos(angles), -1, 0)
    w_inv = np.zeros(angles.shape + (3,))
    w_inv[..., 0, 0] = 1.0
    w_inv[..., 0, 1] = s_phi * s_theta / c_theta
    w_inv[..., 0, 2] = c_phi * s_theta / c_theta
    w_inv[..., 1, 1] = c_phi
    w_inv[..., 1, 2] = -s_phi
    w_inv[..., 2, 1] = s_phi / c_theta
    w_inv[..., 2, 2] = c_phi / c_theta
    return w_inv


def euler_rate_matrix_dot(eta: ArrayLike, eta_dot: ArrayLike) -> np.ndarray:
    """Time derivative of W(eta) along ``eta_dot`` [rad/s]; shapes (..., 3) -> (..., 3, 3).

    Units of the result: 1/s. Used for the body angular acceleration
    ``omega_dot = W eta_ddot + W_dot eta_dot``.
    """
    angles = _angles(eta)
    rates = np.asarray(eta_dot, dtype=float)
    s_phi, s_theta, _ = np.moveaxis(np.sin(angles), -1, 0)
    c_phi, c_theta, _ = np.moveaxis(np.cos(angles), -1, 0)
    phi_dot, theta_dot, _ = np.moveaxis(rates, -1, 0)
    w_dot = np.zeros(np.broadcast_shapes(angles.shape, rates.shape) + (3,))
    w_dot[..., 0, 2] = -c_theta * theta_dot
    w_dot[..., 1, 1] = -s_phi * phi_dot
    w_dot[..., 1, 2] = c_phi * c_theta * phi_dot - s_phi * s_theta * theta_dot
    w_dot[..., 2, 1] = -c_phi * phi_dot
    w_dot[..., 2, 2] = -s_phi * c_theta * phi_dot - c_phi * s_theta * theta_dot
    return w_dot


def quaternion_from_euler(eta: ArrayLike) -> np.ndarray:
    """Unit quaternion (x, y, z, w) of ``R = Rz(psi) Ry(theta) Rx(phi)`` (body -> world).

    eta: Euler angles (roll, pitch, yaw) [rad], shape (..., 3). Returns shape (..., 4), scalar
    part last as geometry_msgs/Quaternion orders it. physics.measurement.euler_quaternion over
    the stack (the odometry's quaternion, written once).
    """
    return _over_stack(euler_quaternions, eta, (4,))


@functools.cache
def _kernel(function, mode: str):
    return kernels.runnable(function, mode)


def _over_stack(function, eta: ArrayLike, shape: tuple[int, ...]) -> np.ndarray:
    """function(angles (m, 3), out (m, prod(shape))) (a physics.measurement kernel, compiled or
    not as MULTILIFT_KERNEL says) over a stack of Euler angles (..., 3): shape (...,) + shape."""
    angles = _angles(eta)
    rows = np.ascontiguousarray(angles.reshape(-1, 3))
    out = np.empty((rows.shape[0], int(np.prod(shape))))
    _kernel(function, kernels.mode())(rows, out)
    return out.reshape(angles.shape[:-1] + shape)


def euler_from_quaternion(q: ArrayLike) -> np.ndarray:
    """ZYX Euler angles (roll, pitch, yaw) [rad], shape (..., 3), of unit quaternions
    (x, y, z, w), shape (..., 4): the inverse of `quaternion_from_euler` for |pitch| < pi/2
    (physics.measurement.quaternion_euler over the stack, the measured state's angles)."""
    quat = np.asarray(q, dtype=float)
    if quat.shape[-1:] != (4,):
        raise ValueError(f'quaternions must have shape (..., 4), got shape {quat.shape}')
    rows = np.ascontiguousarray(quat.reshape(-1, 4)[:, [3, 0, 1, 2]])  # (w, x, y, z)
    out = np.empty((rows.shape[0], 3))
    _kernel(quaternion_eulers, kernels.mode())(rows, out)
    return out.reshape(quat.shape[:-1] + (3,))
