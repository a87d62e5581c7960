"""Formation DAE of n >= 1 multirotors carrying one payload on rigid cables (seed Eq. 2.41-2.70).

World frame (z up), SI units, state layout of docs/conventions.md: the translations
``q = (r_1, ..., r_n, r_p)`` (3n + 3) and ``q_dot``, then each UAV's attitude as a unit
quaternion and its body rates (and a rigid payload's): the seed's q_f = (r_i, eta_i, ..., r_p)
with each eta_i's ZYX angles replaced by a quaternion, which no attitude makes singular.

Equations of motion (seed Eq. 2.46, 2.59-2.60, 2.70):

    M_f q_ddot + C_f q_dot + f_g + G^T Lambda = B_f u_f + d_f
    g_ddot + 2 alpha_f g_dot + beta_f^2 g = 0            (Baumgarte, Eq. 2.59)

With ``f = B_f u_f + d_f - f_g - C_f q_dot`` the multipliers are

    Lambda = (G M^-1 G^T)^-1 (G M^-1 f + G_dot q_dot + 2 alpha_f g_dot + beta_f^2 g)
    q_ddot = M^-1 (f - G^T Lambda),

which is Eq. 2.60/2.70 with the signs gathered. The cable rows of G touch only the UAV
translations (mass m_i I) and the payload (m_p I), and C_f, B_f only couple each UAV's own
coordinates, so the model never forms the dense mass matrix (the arithmetic:
multilift_sim.physics.formation_dae):

- each UAV's attitude is integrated on its own (Euler's equation J omega_dot = tau -
  omega x J omega in body rates, Eq. 2.28, and q_dot = q (x) (0, omega) / 2);
- with ``d_i = r_p - r_i``, ``G M^-1 G^T = diag(4 |d_i|^2 / m_i) + 4 D D^T / m_p`` (n x n),
  solved by the Woodbury identity as a 3 x 3 system, and
  ``(G M^-1 f)_i = 2 d_i . (a_p - a_i)`` with a the unconstrained accelerations.

Forces: UAV i gets thrust ``u_T R_i e_z`` and gravity ``-m_i g e_z``, and body torque tau
enters Euler's equation; the payload gets gravity and the air-relative quadratic drag of
wind/gusts.py (gusts included). Rotor speeds are held constant over each RK4 step; with
lagging rotors (`vehicle.motor_time_constant`, `motor_rate_limit`) each step holds the speed
whose square is the step's mean of omega^2 (multilift_sim.physics.actuators).

The parameters and the state layout are multilift_sim.formation_params'.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim import kernels
from multilift_sim.frames import seed_to_world_vector
from multilift_sim.formation_params import (FormationParams, StateLayout, actuator_array,
                                             constant_arrays)
from multilift_sim.physics.layout import (CABLE_COLUMNS, FORMATION_NULL_SPACE,
                                          FORMATION_PRESCRIBED, FORMATION_TIME, FORMATION_WIND,
                                          WORK_ROWS, WRENCH_COLUMNS)


@dataclass(frozen=True)
class Integration:
    """What holding the rotor speeds over a control period gives (`Formulation.integrate`)."""
    state: np.ndarray              # the formation state at the end (StateLayout.size,)
    cable_tension: np.ndarray      # T_i = 2 l_i lambda_i at the start [N], (n,)
    constraint: np.ndarray         # g_i at the end [m^2], (n,)
    constraint_rate: np.ndarray    # g_i_dot at the end [m^2/s], (n,)


class FormationModel:
    """The stabilised formation DAE (seed Eq. 2.70) with structure-exploiting solves.

    ``rotor_speeds`` arguments are sequences of n per-UAV arrays of rotor speeds [rad/s]
    (shape (n_r,) each, rotor order of docs/conventions.md), held constant over a step;
    `integrate` takes them as commands the rotors follow (physics.actuators): `rotors` (n,
    rotors) holds the rotors' speeds [rad/s] (NaN before the first command), `effectiveness`
    (n, rotors) each rotor's share of its thrust and moment (1: intact).

    The arithmetic is `multilift_sim.physics.formation_dae` (numba functions over the arrays
    this model builds once: `constant_arrays`), compiled just in time, or under
    MULTILIFT_KERNEL=python its uncompiled run, the same source run by Python
    (`kernels.runnable`, resolved once when the model is made).
    """

    slack_cables = False  # whether its cables go slack (SlackCableModel)

    def __init__(self, params: FormationParams, null_space: bool = False):
        self.params = params
        self.layout = StateLayout(params.n_uavs, params.rigid_payload, params.chain_nodes)
        n = params.n_uavs
        self._n = n
        self._nq = self.layout.n_coordinates
        self._allocators = tuple(uav.allocator() for uav in params.uavs)
        self._rotor_counts = tuple(a.n_rotors for a in self._allocators)
        # (n, 4, rotors): each UAV's allocation matrix (seed Eq. 2.14), zero-padded to the
        # largest rotor count (a padded rotor at speed 0 adds nothing)
        self.allocation = np.zeros((n, 4, max(self._rotor_counts)))
        for i, allocator in enumerate(self._allocators):
            self.allocation[i, :, :allocator.n_rotors] = allocator.matrix
        self.uav_masses = np.array([uav.mass for uav in params.uavs])
        self.uav_inertia = np.array([uav.inertia for uav in params.uavs])      # (n, 3)
        self.cable_lengths = np.array(params.cable_lengths)
        self.payload_mass = float(params.payload_mass)
        self.gravity = float(params.gravity)
        self._uavs, self._gusts, self._formation = constant_arrays(params)
        # `null_space`: q_ddot by Eq. 2.71-2.72 (physics.nullspace; nullspace.NullSpaceModel)
        self._formation[FORMATION_NULL_SPACE] = 1.0 if null_space else 0.0
        self._actuators = actuator_array(params)
        self.rotors = np.full(self.allocation.shape[::2], math.nan)
        self.effectiveness = np.ones(self.allocation.shape[::2])
        # which cables are constraints: all of them here (SlackCableModel changes them), but
        # for a released one (physics.events); the released ones never constrain again
        self._taut = np.ones(n, dtype=bool)
        self.released = np.zeros(n, dtype=bool)
        # {name: physics function} as MULTILIFT_KERNEL said when the model was made (read once)
        self._mode = kernels.mode()
        self._loaded: dict[str, Callable] | None = None

    @property
    def taut(self) -> np.ndarray:
        """Which cables are constraints, (n,) bool: the model's own array."""
        return self._taut

    def set_wind(self, velocity: np.ndarray) -> None:
        """The wind [m/s], world, the model integrates in from now on (the steady wind plus a
        period's unsteady wind: simulation.wind_series)."""
        self._formation[FORMATION_WIND:FORMATION_WIND + 3] = velocity

    def physics_constants(self) -> tuple[np.ndarray, ...]:
        """(uavs (n, UAV_COLUMNS), gusts (k, GUST_COLUMNS), formation (FORMATION_SCALARS,),
        allocation (n, 4, rotors), actuators (n, ACTUATOR_COLUMNS)): the constants the
        compiled tick reads (physics.layout slots), the model's own arrays."""
        return self._uavs, self._gusts, self._formation, self.allocation, self._actuators

    # ------------------------------------------------------------------------- physics
    def _physics_functions(self) -> dict[str, Callable]:
        """The physics functions this model calls, by name (numba dispatchers)."""
        from multilift_sim.physics.actuators import actuated_period
        from multilift_sim.physics.allocation import rotor_wrenches
        from multilift_sim.physics.formation_dae import (air_velocity, integrate_period,
                                                         residuals, rk4_step, solve)
        return {'solve': solve, 'rk4_step': rk4_step, 'integrate_period': integrate_period,
                'residuals': residuals, 'rotor_wrenches': rotor_wrenches,
                'air_velocity': air_velocity, 'actuated_period': actuated_period}

    def _physics(self) -> dict[str, Callable]:
        """_physics_functions as MULTILIFT_KERNEL said when the model was made, loaded on first
        use."""
        if self._loaded is None:
            self._loaded = {name: kernels.runnable(function, self._mode) for name, function
                            in self._physics_functions().items()}
        return self._loaded

    def _wrench_array(self, wrenches: ArrayLike) -> np.ndarray:
        wrenches = np.ascontiguousarray(wrenches, dtype=np.float64)
        if wrenches.shape != (self._n, WRENCH_COLUMNS):
            raise ValueError(f'wrenches must have shape ({self._n}, {WRENCH_COLUMNS}), got '
                             f'{wrenches.shape}')
        return wrenches

    def _state_array(self, x: ArrayLike) -> np.ndarray:
        x = np.ascontiguousarray(x, dtype=np.float64)
        if x.shape != (self.layout.size,):
            raise ValueError(f'the state must have shape ({self.layout.size},), got {x.shape}')
        return x

    # ----------------------------------------------------------------------------- inputs
    def _speed_array(self, rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """The speeds as one (n, rotors) array, a smaller UAV's padded with zeros."""
        if len(rotor_speeds) != self._n:
            raise ValueError(f'rotor_speeds has {len(rotor_speeds)} entries for {self._n} UAVs')
        rotors = self.allocation.shape[2]
        speeds = None
        if len(set(self._rotor_counts)) == 1:
            try:
                speeds = np.asarray(rotor_speeds, dtype=float)
            except ValueError:     # ragged: the loop below names the UAV
                speeds = None
            if speeds is not None and speeds.shape != (self._n, rotors):
                speeds = None
        if speeds is None:
            speeds = np.zeros((self._n, rotors))
            for i, (count, own) in enumerate(zip(self._rotor_counts, rotor_speeds)):
                own = np.asarray(own, dtype=float)
                if own.shape != (count,):
                    raise ValueError(f'rotor_speeds[{i}] (uav{i + 1}) must have shape '
                                     f'({count},), got {own.shape}')
                speeds[i, :count] = own
        return np.ascontiguousarray(speeds)

    def wrenches(self, rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """Body wrenches ``u_i = (u_T [N], tau_x, tau_y, tau_z [N m])`` (FLU), shape (n, 4),
        of rotors at these speeds (and the model's `effectiveness`)."""
        wrenches = np.empty((self._n, WRENCH_COLUMNS))
        self._physics()['rotor_wrenches'](self.allocation, self._speed_array(rotor_speeds),
                                          self.effectiveness, wrenches)
        return wrenches

    # --------------------------------------------------------------------------- dynamics
    def accelerations(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> tuple[np.ndarray, np.ndarray]:
        """(acc, cable multipliers Lambda (n,) [N/m]) at time t [s] and state x: acc holds
        q_ddot (3n + 3,) [m/s^2] (world frame), then the rates of the bodies' attitude blocks
        (each quaternion's rate [1/s] and omega_dot [rad/s^2], body frame)."""
        self._at(t)  # autonomous (inputs held, gusts stationary) but for prescribed UAVs
        return self.accelerations_from_wrenches(x, self.wrenches(rotor_speeds))

    def _at(self, t: float) -> None:
        """The time [s] prescribed UAVs' drives are evaluated at (physics.prescribed), where
        the formation has any."""
        if self._formation[FORMATION_PRESCRIBED] != 0.0:
            self._formation[FORMATION_TIME] = t

    def accelerations_from_wrenches(self, x: np.ndarray,
                                    wrenches: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """As accelerations(), from body wrenches (n, 4) (u_T [N], tau [N m], FLU)."""
        # q_ddot, and with a rigid payload its attitude's rate (physics.rigid_payload)
        acc, multipliers = np.empty(self.layout.size - self._nq), np.empty(self._n)
        self._physics()['solve'](self._state_array(x), self._wrench_array(wrenches), self._uavs,
                                 self._gusts, self._formation, self._taut, acc, multipliers,
                                 np.empty((self._n, CABLE_COLUMNS)))
        return acc, multipliers

    def derivative(self, t: float, x: np.ndarray,
                   rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """State derivative ``x_dot = (q_dot, q_ddot, the attitude blocks' rates)``, the
        state's shape."""
        x = np.asarray(x, dtype=float)
        q_ddot, _ = self.accelerations(t, x, rotor_speeds)
        return np.concatenate((self.layout.rates(x), q_ddot))

    def step(self, t: float, x: np.ndarray, rotor_speeds: Sequence[ArrayLike],
             dt: float) -> np.ndarray:
        """One classic RK4 step of length dt [s] from (t, x) with the rotor speeds held."""
        self._at(t)  # see accelerations()
        out = np.empty(self.layout.size)
        self._physics()['rk4_step'](
            self._state_array(x), self.wrenches(rotor_speeds), self._uavs, self._gusts,
            self._formation, self._taut, float(dt), out, np.empty(self._n),
            np.empty((WORK_ROWS, self.layout.size)), np.empty((self._n, CABLE_COLUMNS)))
        return out

    def integrate(self, x: np.ndarray, rotor_speeds: Sequence[ArrayLike], dt: float,
                  steps: int) -> Integration:
        """`steps` RK4 steps of dt [s] from x with the rotor speeds [rad/s] commanded (one
        control period of seed Algorithm 1), the rotors following through their actuators
        (`rotors` moves to the period's end; instant rotors: the speeds held, the wrenches
        formed once). The tension is that of the first stage of the first step (the
        multipliers at x)."""
        state, multipliers, g, g_dot = self._physics()['actuated_period'](
            self._state_array(x), self._speed_array(rotor_speeds), self.rotors,
            self._actuators, self.effectiveness, self.allocation, self._uavs, self._gusts,
            self._formation, self._taut, self.released, self.slack_cables, float(dt), int(steps))
        return Integration(state, 2.0 * self.cable_lengths * multipliers, g, g_dot)

    # -------------------------------------------------------------------------- reporting
    def cable_tension(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """Cable tensions ``T_i = 2 l_i lambda_i`` [N], shape (n,); negative = compression."""
        _, multipliers = self.accelerations(t, x, rotor_speeds)
        return 2.0 * self.cable_lengths * multipliers

    def constraint_residuals(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(g [m^2], g_dot [m^2/s]) of every cable (seed Eq. 2.42, 2.56), shapes (n,)."""
        g, g_dot = np.empty(self._n), np.empty(self._n)
        self._physics()['residuals'](self._state_array(x), self._uavs, g, g_dot)
        return g, g_dot

    def kinetic_energy(self, x: np.ndarray) -> float:
        """Translational plus rotational kinetic energy of UAVs and payload [J] (Eq. 2.43)."""
        x = np.asarray(x, dtype=float)
        layout = self.layout
        velocities = layout.uav_velocities(x)
        payload_velocity = layout.payload_velocity(x)
        translational = 0.5 * (np.sum(self.uav_masses * np.sum(velocities ** 2, axis=1))
                               + self.payload_mass * payload_velocity @ payload_velocity)
        omega = layout.uav_body_rates(x)   # 1/2 omega_i . J_i omega_i (Eq. 2.24 in body rates)
        rotational = 0.5 * float(np.sum(self.uav_inertia * omega * omega))
        if layout.rigid_payload:  # the payload's own spin, 1/2 omega_p . J_p omega_p
            omega = layout.payload_body_rates(x)
            rotational += 0.5 * float(np.dot(self.params.payload_inertia, omega * omega))
        return float(translational + rotational)

    def potential_energy(self, x: np.ndarray) -> float:
        """Gravitational potential energy [J] relative to z = 0 (world z up)."""
        x = np.asarray(x, dtype=float)
        heights = self.layout.uav_positions(x)[:, 2]
        payload_height = self.layout.payload_position(x)[2]
        return float(self.gravity * (self.uav_masses @ heights
                                     + self.payload_mass * payload_height))

    def mechanical_energy(self, x: np.ndarray) -> float:
        """Kinetic (translation and rotation) plus gravitational potential energy [J]."""
        return self.kinetic_energy(x) + self.potential_energy(x)

    def gust_velocity_at_payload(self, t: float, x: np.ndarray) -> np.ndarray:
        """Gust (air) velocity w at the payload [m/s], world, shape (3,)."""
        del t  # stationary gusts
        position = self.layout.payload_position(np.asarray(x, dtype=float))
        return np.array(self._physics()['air_velocity'](float(position[0]), float(position[1]),
                                                        self._gusts))

    def payload_air_velocity(self, t: float, x: np.ndarray) -> np.ndarray:
        """Payload velocity relative to the air, ``v_p - w`` [m/s], world, shape (3,)."""
        x = np.asarray(x, dtype=float)
        return self.layout.payload_velocity(x) - self.gust_velocity_at_payload(t, x)


def initial_state_single_lift(uav_position: ArrayLike, eta: ArrayLike, cable_length: float,
                              alpha: float, beta: float) -> np.ndarray:
    """Single-lift state at rest with the payload placed by seed Eq. 2.33.

    uav_position [m] and eta [rad] in the world frame; alpha, beta [rad] in the SEED convention:
    ``r_p - r = l (c_a s_b, -s_a, c_a c_b)`` in the seed's z-down frame, mapped to the world
    with frames.seed_to_world_vector (so alpha = beta = 0 hangs the payload straight below).
    All velocities are zero, which satisfies Eq. 2.56. Returns x (docs/conventions.md).
    """
    seed_offset = cable_length * np.array([math.cos(alpha) * math.sin(beta), -math.sin(alpha),
                                           math.cos(alpha) * math.cos(beta)])
    uav_position = np.asarray(uav_position, dtype=float)
    return StateLayout(1).pack(uav_position, eta, uav_position + seed_to_world_vector(seed_offset))
