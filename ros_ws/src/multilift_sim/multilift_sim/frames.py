"""The one mapping between the seed's frames and multilift's frames.

The seed (the dissertation) writes its equations in a z-down inertial frame with FRD bodies
(x forward, y right, z down). multilift uses REP-103: a z-up ``world`` frame and FLU bodies
(x forward, y left, z up); see docs/conventions.md. The two inertial frames (and the two body
frames) differ by a 180 deg rotation about x, ``P = diag(1, -1, -1)``, so that

- inertial vectors (positions, velocities, forces) map as ``(x, y, z) -> (x, -y, -z)``;
- body vectors (torques, body rates) map the same way, ``(tx, ty, tz) -> (tx, -ty, -tz)``;
- ZYX Euler angles map as ``(phi, theta, psi) -> (phi, -theta, -psi)``, because
  ``P R_seed(eta_seed) P = R_world(eta_world)`` (P commutes with a rotation about x and flips
  the sense of rotations about y and z).

Every map is its own inverse; the named pairs exist so a call site says which way it goes.
All functions take arrays of shape (..., 3) and return new float arrays of the same shape.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

# P = diag(1, -1, -1): the 180 deg rotation about x between the seed and the world frames.
_AXIS_FLIP = np.array([1.0, -1.0, -1.0])


def _flip(v: ArrayLike) -> np.ndarray:
    array = np.asarray(v, dtype=float)
    if array.shape[-1:] != (3,):
        raise ValueError(f'expected an array of shape (..., 3), got shape {array.shape}')
    return array * _AXIS_FLIP


def seed_to_world_vector(v: ArrayLike) -> np.ndarray:
    """Inertial vector(s) from the seed's z-down frame to the z-up world frame.

    Positions [m], velocities [m/s], accelerations [m/s^2] or forces [N], shape (..., 3):
    ``(x, y, z)_world = (x, -y, -z)_seed``.
    """
    return _flip(v)


def world_to_seed_vector(v: ArrayLike) -> np.ndarray:
    """Inertial vector(s) from the z-up world frame to the seed's z-down frame, shape (..., 3)."""
    return _flip(v)


def seed_to_world_euler(eta: ArrayLike) -> np.ndarray:
    """ZYX Euler angles (roll, pitch, yaw) [rad] of an FRD body in the seed frame to those of
    the same attitude as an FLU body in the world frame: ``(phi, -theta, -psi)``.

    Also maps Euler angle rates [rad/s] and accelerations [rad/s^2]. Shape (..., 3).
    """
    return _flip(eta)


def world_to_seed_euler(eta: ArrayLike) -> np.ndarray:
    """ZYX Euler angles [rad] (or their rates) from world/FLU to seed/FRD, shape (..., 3)."""
    return _flip(eta)


def seed_to_world_body_vector(v: ArrayLike) -> np.ndarray:
    """Body-frame vector(s) from FRD (seed) to FLU (multilift): ``(vx, -vy, -vz)``.

    Body torques [N m], body angular rates [rad/s], body forces [N]; shape (..., 3).
    """
    return _flip(v)


def world_to_seed_body_vector(v: ArrayLike) -> np.ndarray:
    """Body-frame vector(s) from FLU (multilift) to FRD (seed): ``(vx, -vy, -vz)``."""
    return _flip(v)
