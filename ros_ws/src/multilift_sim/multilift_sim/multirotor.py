"""Parameters and equation-of-motion terms of one multirotor (seed Sec. 2.4, Eq. 2.16-2.30).

Translation is ``m r_ddot = R e_z u_T - m g e_z + d`` in the world frame (z up). Attitude uses
ZYX Euler angles as generalised coordinates (seed Eq. 2.28):

    M_eta(eta) eta_ddot + c_eta(eta, eta_dot) = W^T tau + d_eta,

with ``M_eta = W^T J W`` (Eq. 2.24), tau the body torque (FLU) and ``W^T`` the input matrix B of
Eq. 2.30. The velocity term c_eta (``C_eta eta_dot`` of Eq. 2.27-2.28) is derived here as
``W^T (J W_dot eta_dot + omega x J omega)``, i.e. the Euler equation ``J omega_dot + omega x J
omega = tau`` pulled back to Euler coordinates; this equals ``M_eta_dot eta_dot - 1/2
d/deta (eta_dot^T M_eta eta_dot)`` (tests/unit/test_multirotor.py checks it by finite differences).
Departure from the print: the element list of C_eta printed after Eq. 2.27 does not satisfy
that identity (tests/unit/test_multirotor.py shows the mismatch), so it is not used.

Functions take one vehicle (inertia (3,), eta (3,)) or a stack (inertia (n, 3), eta (n, 3)).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.allocation import Allocator, rotor_count
from multilift_sim.kinematics import (euler_rate_matrix, euler_rate_matrix_dot,
                                      euler_rate_matrix_inverse)


@dataclass(frozen=True)
class MultirotorParams:
    """Physical parameters of one multirotor UAV (seed Table 4.2 lists the reference vehicle)."""

    mass: float                          # m [kg]
    inertia: tuple[float, float, float]  # principal moments (I_xx, I_yy, I_zz) [kg m^2], body
    frame_type: str                      # a registered frame (multilift_sim.vehicles)
    arm_length: float                    # l_r [m]
    thrust_coefficient: float            # k_T [N s^2/rad^2]
    moment_coefficient: float            # k_D [N m s^2/rad^2]
    rotor_speed_min: float               # omega_r,min [rad/s]
    rotor_speed_max: float               # omega_r,max [rad/s]
    # the rotors' actuators (physics.actuators; not in the seed, whose rotors answer at once)
    motor_time_constant: float = 0.0     # tau_m [s] of each rotor's first-order lag; 0: none
    motor_rate_limit: float = math.inf   # the largest |d omega / dt| [rad/s^2]; inf: none
    # the UAV's quadratic drag in the wind, -c_d |v - w| (v - w) (not in the seed, whose UAVs
    # meet no air)
    drag_coefficient: float = 0.0        # c_d [N s^2/m^2]
    # the sphere about r_i that the clearance checks keep clear (physics.clearance; issue 34)
    radius: float = 0.0                  # [m]

    def __post_init__(self) -> None:
        rotor_count(self.frame_type)  # ValueError naming the valid frame types
        inertia = tuple(float(v) for v in self.inertia)
        if len(inertia) != 3 or not all(math.isfinite(v) and v > 0 for v in inertia):
            raise ValueError(f'MultirotorParams.inertia must be three positive principal '
                             f'moments [kg m^2], got {self.inertia!r}')
        object.__setattr__(self, 'inertia', inertia)
        for name in ('mass', 'arm_length', 'thrust_coefficient', 'moment_coefficient',
                     'rotor_speed_max'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f'MultirotorParams.{name} must be finite and > 0, got {value!r}')
        if not (math.isfinite(self.rotor_speed_min) and self.rotor_speed_min >= 0):
            raise ValueError(f'MultirotorParams.rotor_speed_min must be finite and >= 0, got '
                             f'{self.rotor_speed_min!r}')
        if not (math.isfinite(self.motor_time_constant) and self.motor_time_constant >= 0):
            raise ValueError(f'MultirotorParams.motor_time_constant must be finite and >= 0 '
                             f'[s], got {self.motor_time_constant!r}')
        if not (math.isfinite(self.drag_coefficient) and self.drag_coefficient >= 0):
            raise ValueError(f'MultirotorParams.drag_coefficient must be finite and >= 0 '
                             f'[N s^2/m^2], got {self.drag_coefficient!r}')
        if not self.motor_rate_limit > 0:  # inf allowed: no limit
            raise ValueError(f'MultirotorParams.motor_rate_limit must be > 0 [rad/s^2] (inf: '
                             f'none), got {self.motor_rate_limit!r}')
        if self.rotor_speed_min >= self.rotor_speed_max:
            raise ValueError(f'MultirotorParams.rotor_speed_min ({self.rotor_speed_min}) must be '
                             f'< rotor_speed_max ({self.rotor_speed_max})')

    @property
    def n_rotors(self) -> int:
        """Number of rotors n_r of the frame type."""
        return rotor_count(self.frame_type)

    def collective_thrust(self, rotor_speeds: ArrayLike) -> float | np.ndarray:
        """u_T = k_T sum_k omega_k^2 [N] of rotor speeds [rad/s] (seed Eq. 2.9, along body +z:
        docs/conventions.md); rotor_speeds (..., n_r) gives shape (...)."""
        speeds = np.asarray(rotor_speeds, dtype=float)
        # np.sum's reduction without its Python wrapper (a per-tick call)
        total = self.thrust_coefficient * np.add.reduce(speeds * speeds, axis=-1)
        return float(total) if total.ndim == 0 else total

    def thrust_margin(self, rotor_speeds: ArrayLike) -> float | np.ndarray:
        """1 - u_T / u_T,max = 1 - sum_k omega_k^2 / (n_r omega_max^2): the share of the
        largest thrust that rotor speeds [rad/s] leave (issue 35; every rotor counted fully
        effective); rotor_speeds (..., n_r) gives shape (...)."""
        speeds = np.asarray(rotor_speeds, dtype=float)
        share = np.add.reduce(speeds * speeds, axis=-1) / (self.n_rotors
                                                           * self.rotor_speed_max ** 2)
        margin = 1.0 - share
        return float(margin) if margin.ndim == 0 else margin

    @property
    def max_thrust(self) -> float:
        """Total thrust with every rotor at rotor_speed_max [N]: ``n_r k_T omega_max^2``."""
        return self.n_rotors * self.thrust_coefficient * self.rotor_speed_max ** 2

    def allocator(self) -> Allocator:
        """The rotor-speed <-> wrench map of this vehicle."""
        return Allocator(self.frame_type, self.arm_length, self.thrust_coefficient,
                         self.moment_coefficient)


def euler_mass_matrix(inertia: ArrayLike, eta: ArrayLike) -> np.ndarray:
    """Attitude inertia ``M_eta = W^T J W`` [kg m^2] of seed Eq. 2.23-2.24.

    inertia: principal moments (..., 3) [kg m^2]; eta: Euler angles (..., 3) [rad].
    Returns (..., 3, 3), symmetric and positive definite away from ``theta = +-pi/2``.
    """
    w = euler_rate_matrix(eta)
    moments = np.asarray(inertia, dtype=float)
    return np.swapaxes(w, -1, -2) @ (moments[..., :, None] * w)


def euler_velocity_term(inertia: ArrayLike, eta: ArrayLike, eta_dot: ArrayLike) -> np.ndarray:
    """Velocity (Coriolis and centripetal) term ``C_eta eta_dot`` [N m] of seed Eq. 2.28.

    Derived as ``W^T (J W_dot eta_dot + omega x J omega)`` with ``omega = W eta_dot``; see the
    module docstring for why the printed C_eta is not used. Shapes (..., 3) -> (..., 3).
    """
    moments = np.asarray(inertia, dtype=float)
    rates = np.asarray(eta_dot, dtype=float)
    w = euler_rate_matrix(eta)
    omega = (w @ rates[..., None])[..., 0]
    w_dot_eta_dot = (euler_rate_matrix_dot(eta, rates) @ rates[..., None])[..., 0]
    body_term = moments * w_dot_eta_dot + np.cross(omega, moments * omega)
    return (np.swapaxes(w, -1, -2) @ body_term[..., None])[..., 0]


def euler_acceleration(inertia: ArrayLike, eta: ArrayLike, eta_dot: ArrayLike,
                       body_torque: ArrayLike) -> np.ndarray:
    """Euler angle accelerations eta_ddot [rad/s^2] under body torque tau [N m] (FLU).

    Solves ``M_eta eta_ddot + C_eta eta_dot = W^T tau`` (seed Eq. 2.28 and 2.30) via the
    equivalent ``eta_ddot = W^-1 (J^-1 (tau - omega x J omega) - W_dot eta_dot)``, which needs no
    3x3 solve. Shapes (..., 3) -> (..., 3).
    """
    moments = np.asarray(inertia, dtype=float)
    rates = np.asarray(eta_dot, dtype=float)
    w = euler_rate_matrix(eta)
    omega = (w @ rates[..., None])[..., 0]
    omega_dot = (np.asarray(body_torque, dtype=float) - np.cross(omega, moments * omega)) / moments
    rhs = omega_dot - (euler_rate_matrix_dot(eta, rates) @ rates[..., None])[..., 0]
    return (euler_rate_matrix_inverse(eta) @ rhs[..., None])[..., 0]


def rotational_kinetic_energy(inertia: ArrayLike, eta: ArrayLike,
                              eta_dot: ArrayLike) -> np.ndarray:
    """``1/2 omega^T J omega`` [J] with ``omega = W eta_dot`` (seed Eq. 2.21). (..., 3) -> (...)."""
    rates = np.asarray(eta_dot, dtype=float)
    omega = (euler_rate_matrix(eta) @ rates[..., None])[..., 0]
    return 0.5 * np.sum(np.asarray(inertia, dtype=float) * omega * omega, axis=-1)
