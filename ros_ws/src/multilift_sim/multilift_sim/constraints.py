"""Rigid-cable constraints of the formation (seed Eq. 2.42, 2.56-2.57, 2.66-2.67).

Cable i is a massless rigid rod of length l_i joining UAV i's centre of mass r_i and the payload
r_p (world frame, m). With ``d_i = r_p - r_i``:

    g_i = |d_i|^2 - l_i^2                      [m^2]      (Eq. 2.42)
    g_i_dot = 2 d_i . (v_p - v_i)              [m^2/s]    (Eq. 2.56)
    dg_i/dr_i = -2 d_i^T,  dg_i/dr_p = 2 d_i^T,  dg_i/deta_i = 0   (Eq. 2.66-2.67)
    (G_dot q_dot)_i = 2 |v_p - v_i|^2          [m^2/s^2]  (from Eq. 2.57)

The constraint force on the coordinates is ``-G^T Lambda`` (seed Eq. 2.46), so the cable pulls
the payload towards UAV i with force ``2 lambda_i d_i`` and tension ``T_i = 2 l_i lambda_i``.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.physics.layout import (POSITION, seed_coordinates, seed_payload_slot,
                                          seed_uav_slot)


def cable_residuals(uav_positions: ArrayLike, payload_position: ArrayLike,
                    cable_lengths: ArrayLike) -> np.ndarray:
    """Position-level residuals g_i [m^2] (seed Eq. 2.42), shape (n,).

    uav_positions (n, 3) [m], payload_position (3,) [m], cable_lengths (n,) [m]; world frame.
    """
    offsets = np.asarray(payload_position, dtype=float) - np.asarray(uav_positions, dtype=float)
    lengths = np.asarray(cable_lengths, dtype=float)
    return np.einsum('ij,ij->i', offsets, offsets) - lengths * lengths


def cable_residual_rates(uav_positions: ArrayLike, uav_velocities: ArrayLike,
                         payload_position: ArrayLike, payload_velocity: ArrayLike) -> np.ndarray:
    """Velocity-level residuals ``g_i_dot = 2 d_i . (v_p - v_i)`` [m^2/s] (seed Eq. 2.56), (n,).

    Positions [m] and velocities [m/s] in the world frame; UAV arrays (n, 3), payload (3,).
    """
    offsets = np.asarray(payload_position, dtype=float) - np.asarray(uav_positions, dtype=float)
    relative_velocities = (np.asarray(payload_velocity, dtype=float)
                           - np.asarray(uav_velocities, dtype=float))
    return 2.0 * np.einsum('ij,ij->i', offsets, relative_velocities)


def constraint_jacobian(uav_positions: ArrayLike, payload_position: ArrayLike) -> np.ndarray:
    """Dense Jacobian ``G_f = dg/dq_f`` [m], shape (n, 6n + 3) (seed Eq. 2.65-2.67).

    Columns follow the coordinate layout of docs/conventions.md: per UAV (x, y, z, phi, theta,
    psi), then the payload (x_p, y_p, z_p). The attitude columns are zero. Meant for checks and
    analysis; the dynamics exploit the structure instead of forming G.
    """
    positions = np.asarray(uav_positions, dtype=float)
    n = positions.shape[0]
    offsets = np.asarray(payload_position, dtype=float) - positions
    jacobian = np.zeros((n, seed_coordinates(n)))
    for i in range(n):
        r = seed_uav_slot(i) + POSITION
        jacobian[i, r:r + 3] = -2.0 * offsets[i]            # Eq. 2.66
        jacobian[i, seed_payload_slot(n):] = 2.0 * offsets[i]    # Eq. 2.67
    return jacobian


def constraint_jacobian_rate_term(uav_velocities: ArrayLike,
                                  payload_velocity: ArrayLike) -> np.ndarray:
    """``G_dot q_dot = 2 |v_p - v_i|^2`` [m^2/s^2], shape (n,) (the velocity part of Eq. 2.57)."""
    relative_velocities = (np.asarray(payload_velocity, dtype=float)
                           - np.asarray(uav_velocities, dtype=float))
    return 2.0 * np.einsum('ij,ij->i', relative_velocities, relative_velocities)


def cable_tension(multipliers: ArrayLike, cable_lengths: ArrayLike) -> np.ndarray:
    """Cable tensions ``T_i = 2 l_i lambda_i`` [N] from the Lagrange multipliers [N/m].

    Positive = taut. A negative value means the rigid rod is in compression (a real cable would
    go slack); it is reported as is, not clipped.
    """
    return 2.0 * np.asarray(cable_lengths, dtype=float) * np.asarray(multipliers, dtype=float)
