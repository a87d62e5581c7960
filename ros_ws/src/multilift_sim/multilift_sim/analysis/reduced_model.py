"""Reduced-coordinate single-lift model (seed Sec. 2.6, Eq. 2.33-2.40), the reference solution.

Written in the SEED frame on purpose, so it is an independent check of the world-frame DAE of
dynamics.py: inertial frame z down, FRD body, gravity ``+g e_z``, thrust ``-u_T R e_z`` with
``u_T = k_T sum omega^2 > 0`` (seed Eq. 2.9). Coordinates

    q = (x, y, z, phi, theta, psi, alpha, beta)      [m, rad]

with the payload at ``r_p = r + l (c_a s_b, -s_a, c_a c_b)`` (Eq. 2.33) and the equation of
motion ``M q_ddot + C q_dot + f_g = B_u u`` (Eq. 2.34). The printed M_r, C_r, M_p, C_p and f_g
(Eq. 2.36-2.39) agree with a derivation from the Lagrangian (tests/unit/test_reduced_model.py checks
them by finite differences); the one slip is the block 0_{3x3} in C of Eq. 2.35, which must be
0_{3x2}. The attitude blocks M_eta and C_eta eta_dot come from multirotor.py (the printed C_eta
is wrong, see there). Integrated with scipy's solve_ivp; frames.py maps results to the world.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import solve_ivp
from scipy.optimize import OptimizeResult

from multilift_sim.formation_params import StateLayout
from multilift_sim.frames import (seed_to_world_euler, seed_to_world_vector,
                                  world_to_seed_body_vector)
from multilift_sim.kinematics import euler_rate_matrix, rotation_matrix
from multilift_sim.multirotor import MultirotorParams, euler_mass_matrix, euler_velocity_term

N_COORDINATES = 8


def cable_direction(alpha: float, beta: float) -> np.ndarray:
    """Unit vector from the UAV to the payload in the seed frame (Eq. 2.33): (c_a s_b, -s_a,
    c_a c_b)."""
    return np.array([math.cos(alpha) * math.sin(beta), -math.sin(alpha),
                     math.cos(alpha) * math.cos(beta)])


def _cable_direction_derivatives(alpha: float, beta: float) -> np.ndarray:
    """Columns d e/d alpha and d e/d beta of the cable direction e, shape (3, 2)."""
    s_a, c_a, s_b, c_b = math.sin(alpha), math.cos(alpha), math.sin(beta), math.cos(beta)
    return np.array([[-s_a * s_b, c_a * c_b],
                     [-c_a, 0.0],
                     [-s_a * c_b, -c_a * s_b]])


@dataclass(frozen=True)
class ReducedSingleLiftModel:
    """One UAV and a payload on a rigid cable in independent coordinates (seed frame)."""

    uav: MultirotorParams
    payload_mass: float      # m_p [kg]
    cable_length: float      # l [m]
    gravity: float = 9.81    # g [m/s^2], along +z of the seed frame

    # ------------------------------------------------------------------ model matrices
    def payload_position(self, q: ArrayLike) -> np.ndarray:
        """Payload position r_p [m] in the seed frame (Eq. 2.33)."""
        return np.asarray(q[:3], dtype=float) + self.cable_length * cable_direction(q[6], q[7])

    def payload_velocity(self, q: ArrayLike, q_dot: ArrayLike) -> np.ndarray:
        """Payload velocity [m/s] in the seed frame, the time derivative of Eq. 2.33."""
        return (np.asarray(q_dot[:3], dtype=float) + self.cable_length
                * _cable_direction_derivatives(q[6], q[7]) @ np.asarray(q_dot[6:8]))

    def mass_matrix(self, q: ArrayLike) -> np.ndarray:
        """M of Eq. 2.35 (with M_r, M_p of Eq. 2.36, 2.38 and M_eta of Eq. 2.24), (8, 8)."""
        m, m_p, length = self.uav.mass, self.payload_mass, self.cable_length
        alpha = q[6]
        coupling = m_p * length * _cable_direction_derivatives(alpha, q[7])   # M_r, Eq. 2.36
        mass = np.zeros((N_COORDINATES, N_COORDINATES))
        mass[:3, :3] = (m + m_p) * np.eye(3)
        mass[3:6, 3:6] = euler_mass_matrix(self.uav.inertia, q[3:6])
        mass[:3, 6:] = coupling
        mass[6:, :3] = coupling.T
        mass[6, 6] = m_p * length ** 2                                      # M_p, Eq. 2.38
        mass[7, 7] = m_p * length ** 2 * math.cos(alpha) ** 2
        return mass

    def velocity_term(self, q: ArrayLike, q_dot: ArrayLike) -> np.ndarray:
        """``C q_dot`` of Eq. 2.35 (C_r of Eq. 2.37, C_p of Eq. 2.38), shape (8,)."""
        m_p, length = self.payload_mass, self.cable_length
        alpha, beta = q[6], q[7]
        alpha_dot, beta_dot = q_dot[6], q_dot[7]
        s_a, c_a, s_b, c_b = math.sin(alpha), math.cos(alpha), math.sin(beta), math.cos(beta)
        coupling_rate = m_p * length * np.array(                             # C_r, Eq. 2.37
            [[-c_a * s_b * alpha_dot - s_a * c_b * beta_dot,
              -s_a * c_b * alpha_dot - c_a * s_b * beta_dot],
             [s_a * alpha_dot, 0.0],
             [-c_a * c_b * alpha_dot + s_a * s_b * beta_dot,
              s_a * s_b * alpha_dot - c_a * c_b * beta_dot]])
        pendulum = m_p * length ** 2 * s_a * c_a * np.array(                 # C_p, Eq. 2.38
            [[0.0, beta_dot],
             [-beta_dot, -alpha_dot]])
        angle_rates = np.asarray(q_dot[6:8], dtype=float)
        term = np.empty(N_COORDINATES)
        term[:3] = coupling_rate @ angle_rates
        term[3:6] = euler_velocity_term(self.uav.inertia, q[3:6], q_dot[3:6])
        term[6:] = pendulum @ angle_rates
        return term

    def gravity_term(self, q: ArrayLike) -> np.ndarray:
        """f_g of Eq. 2.39 (gradient of U = -(m z + m_p z_p) g, z down), shape (8,)."""
        m, m_p, g, length = self.uav.mass, self.payload_mass, self.gravity, self.cable_length
        alpha, beta = q[6], q[7]
        term = np.zeros(N_COORDINATES)
        term[2] = -(m + m_p) * g
        term[6] = m_p * g * length * math.sin(alpha) * math.cos(beta)
        term[7] = m_p * g * length * math.cos(alpha) * math.sin(beta)
        return term

    def input_term(self, q: ArrayLike, thrust: float, body_torque_frd: ArrayLike) -> np.ndarray:
        """``B_u u`` of Eq. 2.40 (B of Eq. 2.30), shape (8,).

        thrust: u_T = k_T sum omega^2 > 0 [N], acting along -z of the FRD body (the seed's
        ``B_r u_T`` with its negative u_T of Eq. 2.9); body_torque_frd [N m] in FRD.
        """
        term = np.zeros(N_COORDINATES)
        term[:3] = -thrust * rotation_matrix(q[3:6])[:, 2]
        term[3:6] = euler_rate_matrix(q[3:6]).T @ np.asarray(body_torque_frd, dtype=float)
        return term

    # -------------------------------------------------------------------- integration
    def seed_wrench(self, rotor_speeds: ArrayLike) -> tuple[float, np.ndarray]:
        """(u_T [N], body torque [N m] in FRD) of rotor speeds [rad/s] (rotor order of
        docs/conventions.md); allocation.py works in FLU, frames.py maps the torque."""
        wrench = self.uav.allocator().wrench(rotor_speeds)
        return float(wrench[0]), world_to_seed_body_vector(wrench[1:])

    def derivative(self, t: float, state: ArrayLike, thrust: float,
                   body_torque_frd: ArrayLike) -> np.ndarray:
        """``(q_dot, q_ddot)`` of the state ``(q, q_dot)`` (16,) under a held seed wrench."""
        del t  # autonomous
        q, q_dot = state[:N_COORDINATES], state[N_COORDINATES:]
        rhs = (self.input_term(q, thrust, body_torque_frd) - self.velocity_term(q, q_dot)
               - self.gravity_term(q))
        return np.concatenate((q_dot, np.linalg.solve(self.mass_matrix(q), rhs)))

    def simulate(self, state0: ArrayLike, rotor_speeds: ArrayLike, t_final: float,
                 t_eval: ArrayLike | None = None, rtol: float = 1e-10,
                 atol: float = 1e-12) -> OptimizeResult:
        """Integrate from state0 at t = 0 to t_final [s] with constant rotor speeds [rad/s]
        (scipy solve_ivp, DOP853, tight tolerances, dense output). Seed frame states."""
        thrust, torque = self.seed_wrench(rotor_speeds)
        return solve_ivp(self.derivative, (0.0, t_final), np.asarray(state0, dtype=float),
                         method='DOP853', t_eval=t_eval, rtol=rtol, atol=atol,
                         dense_output=True, args=(thrust, torque))

    def linearise(self, state: ArrayLike, rotor_speeds: ArrayLike,
                  relative_step: float = 1e-6) -> np.ndarray:
        """State matrix ``A = d x_dot / d x`` (16, 16) by central finite differences."""
        thrust, torque = self.seed_wrench(rotor_speeds)
        state = np.asarray(state, dtype=float)
        jacobian = np.empty((state.size, state.size))
        for k in range(state.size):
            step = relative_step * max(1.0, abs(state[k]))
            plus, minus = state.copy(), state.copy()
            plus[k] += step
            minus[k] -= step
            jacobian[:, k] = (self.derivative(0.0, plus, thrust, torque)
                              - self.derivative(0.0, minus, thrust, torque)) / (2.0 * step)
        return jacobian

    # ---------------------------------------------------------------- frame conversion
    def to_world_positions(self, states: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """World-frame (UAV positions, payload positions) [m] of seed states (k, 16) or (16,)
        (or coordinates (k, 8)), each shape (k, 3) or (3,)."""
        states = np.asarray(states, dtype=float)
        alpha, beta = states[..., 6], states[..., 7]
        offset = self.cable_length * np.stack([np.cos(alpha) * np.sin(beta), -np.sin(alpha),
                                               np.cos(alpha) * np.cos(beta)], axis=-1)
        uav = states[..., :3]
        return seed_to_world_vector(uav), seed_to_world_vector(uav + offset)

    def to_formation_state(self, state: ArrayLike) -> np.ndarray:
        """The packed world-frame DAE state (docs/conventions.md) of a seed state: its Euler
        rates become body rates omega = W(eta) eta_dot (Eq. 2.7)."""
        state = np.asarray(state, dtype=float)
        q, q_dot = state[:N_COORDINATES], state[N_COORDINATES:]
        eta = seed_to_world_euler(q[3:6])
        return StateLayout(1).pack(
            seed_to_world_vector(q[:3]), eta,
            seed_to_world_vector(self.payload_position(q)),
            uav_velocities=seed_to_world_vector(q_dot[:3]),
            uav_body_rates=euler_rate_matrix(eta) @ seed_to_world_euler(q_dot[3:6]),
            payload_velocity=seed_to_world_vector(self.payload_velocity(q, q_dot)))


def rest_state(uav_position_seed: Sequence[float], eta_seed: Sequence[float], alpha: float,
               beta: float) -> np.ndarray:
    """Seed-frame reduced state (16,) at rest: UAV at uav_position_seed [m] with Euler angles
    eta_seed [rad] (FRD), payload at angles alpha, beta [rad] (Eq. 2.33)."""
    state = np.zeros(2 * N_COORDINATES)
    state[:3] = uav_position_seed
    state[3:6] = eta_seed
    state[6:8] = alpha, beta
    return state
