"""Control allocation of a multirotor (seed Eq. 2.9-2.15) from its frame's rotor positions and
spins (the registered frames of `multilift_sim.vehicles`: the seed's planar ones and any part).
Everything is in the FLU body frame: thrust along +z_b, ``u = (u_T [N], tau_x, tau_y,
tau_z [N m])``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim import vehicles


def rotor_count(frame_type: str) -> int:
    """Number of rotors n_r of a registered frame (ValueError for an unknown one)."""
    return len(vehicles.frame(frame_type).SPINS)


def rotor_positions(frame_type: str, arm_length: float) -> np.ndarray:
    """Rotor hub positions [m], body FLU, (n_r, 3), of a registered frame
    (`multilift_sim.vehicles`)."""
    return np.asarray(vehicles.frame(frame_type).rotor_positions(arm_length), dtype=float)


def rotor_spin_directions(frame_type: str) -> np.ndarray:
    """+1 for a rotor spinning clockwise seen from above, -1 counter-clockwise (n_r,).

    A clockwise rotor's reaction (drag) moment on the body is ``+k_D omega^2`` about body +z.
    """
    return np.asarray(vehicles.frame(frame_type).SPINS, dtype=float)


def allocation_matrix(frame_type: str, arm_length: float, thrust_coefficient: float,
                      moment_coefficient: float) -> np.ndarray:
    """Allocation matrix K_r of seed Eq. 2.14, shape (4, n_r): ``u = K_r omega^2``.

    arm_length l_r [m], thrust_coefficient k_T [N s^2/rad^2], moment_coefficient
    k_D [N m s^2/rad^2]. Rows: thrust u_T [N] along body +z, then body torques
    (tau_x, tau_y, tau_z) [N m] in FLU. Column k is rotor k's contribution per rad^2/s^2:
    ``(k_T, (r_k x k_T e_z)_x, (r_k x k_T e_z)_y, spin_k k_D)`` (seed Eq. 2.12-2.13 with the
    thrust along +z_b of the z-up convention).
    """
    positions = rotor_positions(frame_type, arm_length)
    spins = rotor_spin_directions(frame_type)
    matrix = np.empty((4, positions.shape[0]))
    matrix[0] = thrust_coefficient
    # r x (0, 0, f) = (r_y f, -r_x f, 0)
    matrix[1] = positions[:, 1] * thrust_coefficient
    matrix[2] = -positions[:, 0] * thrust_coefficient
    matrix[3] = spins * moment_coefficient
    return matrix


@dataclass(frozen=True)
class Allocator:
    """Maps rotor speeds to the body wrench and back for one vehicle (seed Eq. 2.14-2.15).

    The inverse is least-norm (pseudo-inverse) on omega^2, so it is exact for any u when
    n_r = 4 and the minimum-norm solution for hexa- and octorotors.
    """

    frame_type: str
    arm_length: float            # l_r [m]
    thrust_coefficient: float    # k_T [N s^2/rad^2]
    moment_coefficient: float    # k_D [N m s^2/rad^2]
    matrix: np.ndarray = field(init=False, repr=False, compare=False)
    pseudo_inverse: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        matrix = allocation_matrix(self.frame_type, self.arm_length, self.thrust_coefficient,
                                   self.moment_coefficient)
        matrix.flags.writeable = False
        pseudo_inverse = np.linalg.pinv(matrix)
        pseudo_inverse.flags.writeable = False
        object.__setattr__(self, 'matrix', matrix)
        object.__setattr__(self, 'pseudo_inverse', pseudo_inverse)

    @property
    def n_rotors(self) -> int:
        return self.matrix.shape[1]

    def wrench(self, omega: ArrayLike) -> np.ndarray:
        """Body wrench ``u = (u_T [N], tau_x, tau_y, tau_z [N m])`` (FLU) of rotor speeds
        omega [rad/s], shape (..., n_r) -> (..., 4)."""
        speeds = np.asarray(omega, dtype=float)
        return (speeds * speeds) @ self.matrix.T

    def rotor_speeds(self, u: ArrayLike, omega_min: float,
                     omega_max: float) -> tuple[np.ndarray, np.ndarray]:
        """Rotor speeds [rad/s] realising the wrench u (shape (..., 4)) as closely as the limits
        allow: ``omega^2 = pinv(K_r) u`` clipped to ``[omega_min^2, omega_max^2]``.

        Returns (omega, saturated_mask), both shape (..., n_r); the mask is True for each rotor
        whose unclipped omega^2 lay outside the limits.
        """
        squared = np.asarray(u, dtype=float) @ self.pseudo_inverse.T
        low, high = omega_min * omega_min, omega_max * omega_max
        saturated = (squared < low) | (squared > high)
        return np.sqrt(np.clip(squared, low, high)), saturated
