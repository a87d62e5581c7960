"""Null-space formulation of the formation EOM (seed Eq. 2.71-2.72 closed by Eq. 2.57).

World frame (z up), SI units, the state layout of docs/conventions.md. With N_f a basis of the
null space of the constraint Jacobian G_f (``G_f N_f = 0``, Eq. 2.71), projecting
``M_f q_ddot + C_f q_dot + f_g + G_f^T Lambda = B_f u_f + d_f`` (Eq. 2.46) on N_f removes the
constraint forces (Eq. 2.72); the n equations it loses are the constraints at acceleration
level (Eq. 2.57):

    [ N_f^T M_f ]            [ N_f^T f_f          ]
    [    G_f    ]  q_ddot =  [ -G_dot_f q_dot_f   ],    f_f = B_f u_f + d_f - f_g - C_f q_dot.

The arithmetic is written once, compiled, in `multilift_sim.physics.nullspace` (the dense
solve on the translations, each UAV's attitude by `physics.free_motion`, the projection back
onto the manifold); this class is a `FormationModel` whose constants select that form
(FORMATION_NULL_SPACE, read by `physics.formation_dae.solve`, so its RK4 step is the same
compiled RK4), plus the projection after every step.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim import kernels
from multilift_sim.constraints import cable_tension
from multilift_sim.dynamics import FormationModel, Integration
from multilift_sim.formation_params import FormationParams
from multilift_sim.physics.layout import FORMATION_PROJECTION_STEPS, FORMATION_PROJECTION_TOLERANCE
from multilift_sim.physics.nullspace import project, translational_masses


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
    alpha_f = 20, with no gain to tune. It costs a dense solve per evaluation and the projection
    per step, compiled: 13.8 us per RK4 step of the single-lift swing against the multiplier
    form's 4.1 us, 16.8 against 5.1 us for the twin-lift (500 periods of two 5 ms steps
    timed with time.perf_counter on 2026-12-03).
    """

    def __init__(self, params: FormationParams, projection: bool = True,
                 projection_tolerance: float = 1e-14, max_newton_steps: int = 4):
        self.params = params
        # the Baumgarte gains play no part here: this FormationModel, in the null-space form,
        # supplies the accelerations, RK4, wrenches, the layout and the energy/gust reporting
        self.formation = FormationModel(dataclasses.replace(params, baumgarte_alpha=0.0,
                                                            baumgarte_beta=0.0),
                                        null_space=True)
        self.layout = self.formation.layout
        self.projection = projection
        self.projection_tolerance = projection_tolerance      # |g_i| / l_i^2 accepted
        self.max_newton_steps = max_newton_steps
        self.uav_masses = self.formation.uav_masses
        self.uav_inertia = self.formation.uav_inertia
        self.cable_lengths = self.formation.cable_lengths
        self.payload_mass = self.formation.payload_mass
        self.gravity = self.formation.gravity
        self._masses = translational_masses(self.formation._uavs, self.formation._formation)
        self._project = kernels.runnable(project)
        # the compiled period projects after each RK4 step (physics.formation_dae)
        if projection:
            self.formation._formation[FORMATION_PROJECTION_STEPS] = max_newton_steps
            self.formation._formation[FORMATION_PROJECTION_TOLERANCE] = projection_tolerance

    # --------------------------------------------------------------------------- dynamics
    def wrenches(self, rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """Body wrenches ``(u_T [N], tau [N m])`` (FLU), shape (n, 4) (FormationModel's)."""
        return self.formation.wrenches(rotor_speeds)

    def accelerations_from_wrenches(self, x: np.ndarray,
                                    wrenches: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(acc (q_ddot, then the attitude blocks' rates), multipliers Lambda (n,) [N/m]) by Eq.
        2.71-2.72
        with Eq. 2.57, under body wrenches (n, 4) (u_T [N], tau [N m], FLU)."""
        return self.formation.accelerations_from_wrenches(x, wrenches)

    def accelerations(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> tuple[np.ndarray, np.ndarray]:
        """(q_ddot, Lambda) at time t [s] under rotor speeds [rad/s] (autonomous model)."""
        return self.formation.accelerations(t, x, rotor_speeds)

    def derivative(self, t: float, x: np.ndarray,
                   rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """State derivative, the state's shape (FormationModel.derivative)."""
        return self.formation.derivative(t, x, rotor_speeds)

    def step(self, t: float, x: np.ndarray, rotor_speeds: Sequence[ArrayLike],
             dt: float) -> np.ndarray:
        """One classic RK4 step of dt [s] with the rotor speeds held, then (with projection)
        the state put back on g = 0, g_dot = 0."""
        x_next = self.formation.step(t, x, rotor_speeds, dt)
        return self.project(x_next) if self.projection else x_next

    def integrate(self, x: np.ndarray, rotor_speeds: Sequence[ArrayLike], dt: float,
                  steps: int) -> Integration:
        """`steps` projected RK4 steps of dt [s] with the rotor speeds [rad/s] commanded, in
        the one compiled period (`physics.actuators.actuated_period`, which projects after each
        step); the tension is the one at x."""
        return self.formation.integrate(x, rotor_speeds, dt, steps)

    def physics_constants(self) -> tuple[np.ndarray, ...]:
        """(uavs, gusts, formation, allocation, actuators): the arrays the compiled tick reads
        (`FormationModel.physics_constants`), in the null-space form with its projection."""
        return self.formation.physics_constants()

    def project(self, x: np.ndarray) -> np.ndarray:
        """x moved onto the constraint manifold (`physics.nullspace.project`: positions by
        Newton steps along M^-1 G^T until |g_i| <= projection_tolerance l_i^2, at most
        max_newton_steps, one suffices after an RK4 step; then the velocities onto g_dot = 0).
        Returns a new array."""
        out = np.array(x, dtype=float)
        self._project(out, self.formation._uavs, self._masses, self.projection_tolerance,
                      self.max_newton_steps)
        return out

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
