"""Null-space formulation of the formation EOM (seed Eq. 2.71-2.72 closed by Eq. 2.57).

World frame (z up), SI units, the state layout of docs/conventions.md. With N_f a basis of the
null space of the constraint Jacobian G_f (``G_f N_f = 0``, Eq. 2.71), projecting
``M_f q_ddot + C_f q_dot + f_g + G_f^T Lambda = B_f u_f + d_f`` (Eq. 2.46) on N_f removes the
constraint forces (Eq. 2.72); the n equations it loses are the constraints at acceleration
level (Eq. 2.57):

    [ N_f^T M_f ]            [ N_f^T f_f          ]
    [    G_f    ]  q_ddot =  [ -G_dot_f q_dot_f   ],    f_f = B_f u_f + d_f - f_g - C_f q_dot.

Any basis of ker G_f serves. The attitude columns of G_f are zero (Eq. 2.66) and M_f is block
diagonal (Eq. 2.47), so this module takes ``N_f = blockdiag(N_t, I)`` on (translations,
attitudes) with N_t an orthonormal basis of ker G_t (the last 2n + 3 columns of a complete QR
of G_t^T; G_t = G_f's translational columns): the attitude rows are each UAV's own Euler
equation (Eq. 2.28, multirotor.euler_acceleration) and the rest is a dense (3n + 3) solve
with M_t = diag(m_i I, m_p I). The multipliers, for the tensions, follow from
``G_t^T Lambda = f_t - M_t a``. The terms come from the existing parts, not re-derived:
FormationModel.wrenches (allocation), kinematics.rotation_matrix (B_r, Eq. 2.20),
multirotor.euler_acceleration, disturbances.payload_drag / gust_velocity (Eq. 2.53, 2.55),
constraints.constraint_jacobian / constraint_jacobian_rate_term (Eq. 2.65-2.67, 2.57).
"""
from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.constraints import (cable_residuals, cable_tension, constraint_jacobian,
                                       constraint_jacobian_rate_term)
from multilift_sim.disturbances import gust_velocity, payload_drag
from multilift_sim.dynamics import FormationModel, Integration
from multilift_sim.formation_params import FormationParams
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.multirotor import euler_acceleration


class NullSpaceModel:
    """The formation EOM in the null-space form, RK4 with coordinate projection.

    Same interface as FormationModel for a simulation loop: ``step(t, x, rotor_speeds, dt)``,
    ``accelerations``, ``derivative``, ``cable_tension``, ``constraint_residuals``, the
    energies and the gust queries (the last ones are FormationModel's, delegated).
    ``rotor_speeds``: n per-UAV arrays [rad/s], held over a step.

    Residual drift. The projected ODE alone is Eq. 2.58 without stabilisation: its q_ddot is
    the same as FormationModel's with alpha_f = beta_f = 0, so |g| drifts exactly as the
    unstabilised DAE does (NullSpaceModel(projection=False) reproduces that run to rounding;
    RK4 at 10 ms on the seed's single-lift swing: 3.3e-5 m^2 after 60 s, still growing). What
    the null-space method adds is a cheap way back onto the manifold: after every step
    (``projection=True``, the default) the positions are put back on g = 0 by Newton steps
    along ``M^-1 G^T`` (the mass-weighted least change) and the velocities on g_dot = 0 by the
    matching linear projection -- the seed's Sec. 2.8 "extra step ... to find the dependent
    coordinates at each time-step", done in the mass metric rather than on fixed dependent
    coordinates. |g| then stays at rounding level (<= 1e-14 l^2; 5e-14 m^2 in that run) where
    Baumgarte holds it at 8e-7 m^2 (alpha_f = 20) or 3.5e-5 m^2 (alpha_f = 100, too stiff for
    a 10 ms step), and the positions are 25 times closer to the reduced model's than with
    alpha_f = 20, with no gain to tune. It costs a dense solve per evaluation: about 25 times
    FormationModel's structured float kernel for n = 1 (`multilift study baumgarte`).
    """

    def __init__(self, params: FormationParams, projection: bool = True,
                 projection_tolerance: float = 1e-14, max_newton_steps: int = 4):
        self.params = params
        # The Baumgarte gains play no part here; this FormationModel supplies wrenches, the
        # layout and the energy/gust reporting only.
        self.formation = FormationModel(dataclasses.replace(params, baumgarte_alpha=0.0,
                                                            baumgarte_beta=0.0))
        self.layout = self.formation.layout
        self.projection = projection
        self.projection_tolerance = projection_tolerance      # |g_i| / l_i^2 accepted
        self.max_newton_steps = max_newton_steps
        n = params.n_uavs
        self._n = n
        self._nq = self.layout.n_coordinates
        self.uav_masses = self.formation.uav_masses
        self.uav_inertia = self.formation.uav_inertia
        self.cable_lengths = self.formation.cable_lengths
        self.payload_mass = self.formation.payload_mass
        self.gravity = self.formation.gravity
        # diagonal of M^-1 on the translations; 0 on the attitudes, whose columns of G are zero
        inverse = np.zeros(self._nq)
        for i in range(n):
            inverse[6 * i:6 * i + 3] = 1.0 / self.uav_masses[i]
        inverse[6 * n:] = 1.0 / self.payload_mass
        self._inverse_translational_mass = inverse
        # translational coordinates (r_1, ..., r_n, r_p) and attitudes (eta_1, ..., eta_n) in q_f
        self._translations = np.array([6 * i + k for i in range(n) for k in range(3)]
                                      + [6 * n, 6 * n + 1, 6 * n + 2])
        self._attitudes = np.array([6 * i + 3 + k for i in range(n) for k in range(3)])
        self._translational_mass = 1.0 / inverse[self._translations]           # diag of M_t

    # --------------------------------------------------------------------------- dynamics
    def wrenches(self, rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """Body wrenches ``(u_T [N], tau [N m])`` (FLU), shape (n, 4) (FormationModel's)."""
        return self.formation.wrenches(rotor_speeds)

    def translational_forces(self, x: np.ndarray, wrenches: np.ndarray) -> np.ndarray:
        """f_t [N], shape (3n+3,): the translational rows of f_f = B_f u_f + d_f - f_g
        (Eq. 2.50-2.52; C_f has no translational part): UAV i ``u_T R(eta_i) e_z - m_i g e_z``
        (B_r of Eq. 2.20), then the payload's drag (air-relative, gusts included, Eq. 2.53)
        minus its weight."""
        layout, n = self.layout, self._n
        forces = np.empty((n + 1, 3))
        forces[:n] = wrenches[:, :1] * rotation_matrix(layout.uav_euler(x))[:, :, 2]
        forces[:n, 2] -= self.uav_masses * self.gravity
        position = layout.payload_position(x)
        forces[n] = payload_drag(layout.payload_velocity(x),
                                 gust_velocity(self.params.gusts, position),
                                 self.params.payload_drag_coefficient)
        forces[n, 2] -= self.payload_mass * self.gravity
        return forces.ravel()

    def _solve(self, x: np.ndarray, wrenches: np.ndarray,
               multipliers: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """q_ddot by Eq. 2.71-2.72 and 2.57, and (if asked) Lambda; see accelerations_from_
        wrenches."""
        layout, nq = self.layout, self._nq
        # attitude rows: M_eta eta_ddot = W^T tau - C_eta eta_dot (Eq. 2.28, 2.30)
        eta_ddot = euler_acceleration(self.uav_inertia, layout.uav_euler(x),
                                      layout.uav_euler_rates(x), wrenches[:, 1:])
        forces = self.translational_forces(x, wrenches)
        jacobian = constraint_jacobian(layout.uav_positions(x),
                                       layout.payload_position(x))[:, self._translations]
        # N_t: the last 2n + 3 columns of a complete QR of G_t^T span ker G_t (Eq. 2.71)
        q_factor, _ = np.linalg.qr(jacobian.T, mode='complete')
        null = q_factor[:, self._n:]
        system = np.vstack((null.T * self._translational_mass, jacobian))     # N^T M_t; G_t
        rhs = np.concatenate((null.T @ forces, -constraint_jacobian_rate_term(
            layout.uav_velocities(x), layout.payload_velocity(x))))
        acceleration = np.linalg.solve(system, rhs)
        q_ddot = np.empty(nq)
        q_ddot[self._translations] = acceleration
        q_ddot[self._attitudes] = eta_ddot.ravel()
        if not multipliers:
            return q_ddot, None
        # the eliminated constraint forces: G_t^T Lambda = f_t - M_t a (consistent by design)
        return q_ddot, np.linalg.solve(jacobian @ jacobian.T, jacobian @ (
            forces - self._translational_mass * acceleration))

    def accelerations_from_wrenches(self, x: np.ndarray,
                                    wrenches: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(q_ddot (6n+3,) [m/s^2, rad/s^2], multipliers Lambda (n,) [N/m]) by Eq. 2.71-2.72
        with Eq. 2.57, under body wrenches (n, 4) (u_T [N], tau [N m], FLU)."""
        return self._solve(np.asarray(x, dtype=float), np.asarray(wrenches, dtype=float), True)

    def accelerations(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> tuple[np.ndarray, np.ndarray]:
        """(q_ddot, Lambda) at time t [s] under rotor speeds [rad/s] (autonomous model)."""
        del t
        return self.accelerations_from_wrenches(x, self.wrenches(rotor_speeds))

    def derivative(self, t: float, x: np.ndarray,
                   rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """State derivative ``(q_dot, q_ddot)``, shape (2(6n+3),)."""
        x = np.asarray(x, dtype=float)
        return np.concatenate((x[self._nq:], self.accelerations(t, x, rotor_speeds)[0]))

    def step(self, t: float, x: np.ndarray, rotor_speeds: Sequence[ArrayLike],
             dt: float) -> np.ndarray:
        """One classic RK4 step of dt [s] with the rotor speeds held, then (with projection)
        the state put back on g = 0, g_dot = 0."""
        del t
        wrenches = self.wrenches(rotor_speeds)
        nq = self._nq

        def rate(state: np.ndarray) -> np.ndarray:
            return np.concatenate((state[nq:], self._solve(state, wrenches, False)[0]))
        x = np.asarray(x, dtype=float)
        k1 = rate(x)
        k2 = rate(x + 0.5 * dt * k1)
        k3 = rate(x + 0.5 * dt * k2)
        k4 = rate(x + dt * k3)
        x_next = x + (dt / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
        return self.project(x_next) if self.projection else x_next

    def integrate(self, x: np.ndarray, rotor_speeds: Sequence[ArrayLike], dt: float,
                  steps: int) -> Integration:
        """`steps` projected RK4 steps of dt [s] with the rotor speeds [rad/s] held; the
        tension is the one at x."""
        tension = self.cable_tension(0.0, x, rotor_speeds)
        for _ in range(steps):
            x = self.step(0.0, x, rotor_speeds, dt)
        g, g_dot = self.constraint_residuals(x)
        return Integration(x, tension, g, g_dot)

    def project(self, x: np.ndarray) -> np.ndarray:
        """x moved onto the constraint manifold: positions by Newton steps
        ``dq = -M^-1 G^T (G M^-1 G^T)^-1 g`` until |g_i| <= projection_tolerance l_i^2 (at most
        max_newton_steps; one suffices after an RK4 step, ~3 from a start 1e-3 l^2 off), then
        velocities ``dv = -M^-1 G^T (G M^-1 G^T)^-1 G v`` (exact: g_dot = G v is linear in v).
        Only translations move (the attitude columns of G are zero). Returns a new array."""
        layout, nq = self.layout, self._nq
        x = np.array(x, dtype=float)
        q, v = x[:nq], x[nq:]
        inverse = self._inverse_translational_mass
        limit = self.projection_tolerance * self.cable_lengths ** 2
        for _ in range(self.max_newton_steps):
            residual = cable_residuals(layout.uav_positions(x), layout.payload_position(x),
                                       self.cable_lengths)
            if np.all(np.abs(residual) <= limit):
                break
            jacobian = constraint_jacobian(layout.uav_positions(x), layout.payload_position(x))
            weighted = jacobian * inverse                                       # G M^-1
            q -= weighted.T @ np.linalg.solve(weighted @ jacobian.T, residual)
        jacobian = constraint_jacobian(layout.uav_positions(x), layout.payload_position(x))
        weighted = jacobian * inverse
        v -= weighted.T @ np.linalg.solve(weighted @ jacobian.T, jacobian @ v)
        return x

    # -------------------------------------------------------------------------- reporting
    def cable_tension(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """Cable tensions ``T_i = 2 l_i lambda_i`` [N], shape (n,); negative = compression."""
        _, multipliers = self.accelerations(t, x, rotor_speeds)
        return cable_tension(multipliers, self.cable_lengths)

    def constraint_residuals(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(g [m^2], g_dot [m^2/s]) of every cable (Eq. 2.42, 2.56), shapes (n,)."""
        return self.formation.constraint_residuals(x)

    def kinetic_energy(self, x: np.ndarray) -> float:
        """Kinetic energy of UAVs and payload [J] (Eq. 2.43)."""
        return self.formation.kinetic_energy(x)

    def potential_energy(self, x: np.ndarray) -> float:
        """Gravitational potential energy [J] relative to z = 0."""
        return self.formation.potential_energy(x)

    def mechanical_energy(self, x: np.ndarray) -> float:
        """Kinetic plus gravitational potential energy [J]."""
        return self.formation.mechanical_energy(x)

    def gust_velocity_at_payload(self, t: float, x: np.ndarray) -> np.ndarray:
        """Gust (air) velocity at the payload [m/s], world, shape (3,)."""
        return self.formation.gust_velocity_at_payload(t, x)

    def payload_air_velocity(self, t: float, x: np.ndarray) -> np.ndarray:
        """Payload velocity relative to the air [m/s], world, shape (3,)."""
        return self.formation.payload_air_velocity(t, x)
