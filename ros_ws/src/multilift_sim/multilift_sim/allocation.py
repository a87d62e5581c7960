"""Rotor layout and control allocation of planar multirotors (seed Eq. 2.9-2.15).

The allocation matrix is built from the geometry of seed Eq. 2.11-2.13 with the rotor numbering
and spin directions of docs/conventions.md, not copied from the seed's Table 2.1 (whose print is
garbled). Everything is in the FLU body frame: thrust along +z_b, ``u = (u_T [N], tau_x, tau_y,
tau_z [N m])``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

# frame type -> (number of rotors, arm angle offset xi_c [rad]); "+" has xi_c = 0, "x" pi/n_r.
_FRAMES: dict[str, tuple[int, float]] = {
    'quad_plus': (4, 0.0),
    'quad_x': (4, math.pi / 4),
    'hexa_plus': (6, 0.0),
    'hexa_x': (6, math.pi / 6),
    'octo_plus': (8, 0.0),
    'octo_x': (8, math.pi / 8),
}
FRAME_TYPES: tuple[str, ...] = tuple(_FRAMES)


def _frame(frame_type: str) -> tuple[int, float]:
    try:
        return _FRAMES[frame_type]
    except KeyError:
        raise ValueError(f'unknown frame_type {frame_type!r}; valid frame types are '
                         f'{", ".join(FRAME_TYPES)}') from None


def rotor_count(frame_type: str) -> int:
    """Number of rotors n_r of a frame type (ValueError for an unknown type)."""
    return _frame(frame_type)[0]


def rotor_positions(frame_type: str, arm_length: float) -> np.ndarray:
    """Rotor hub positions in the FLU body frame [m], shape (n_r, 3).

    Rotor k (k = 1..n_r, row k-1) sits at arm angle ``xi_k = 2 pi (k-1)/n_r + xi_c`` measured
    clockwise seen from above, at ``l_r (cos xi_k, -sin xi_k, 0)``. Departure from the print:
    seed Eq. 2.11 writes ``2 pi i / n_r``, which would put rotor 1 a full spacing past the front;
    we use ``k - 1`` so rotor 1 is the front ("+") or front-right ("x") one, as in the
    conventions and the Q+ row of seed Table 2.1.
    """
    n_rotors, offset = _frame(frame_type)
    arm_angle = 2.0 * np.pi * np.arange(n_rotors) / n_rotors + offset
    return arm_length * np.stack(
        [np.cos(arm_angle), -np.sin(arm_angle), np.zeros(n_rotors)], axis=1)


def rotor_spin_directions(frame_type: str) -> np.ndarray:
    """+1 for a rotor spinning clockwise seen from above (odd k), -1 counter-clockwise (even k).

    A clockwise rotor's reaction (drag) moment on the body is ``+k_D omega^2`` about body +z.
    """
    n_rotors, _ = _frame(frame_type)
    return np.where(np.arange(n_rotors) % 2 == 0, 1.0, -1.0)


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
