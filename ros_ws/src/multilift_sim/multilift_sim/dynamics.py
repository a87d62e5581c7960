"""Formation DAE of n >= 1 multirotors carrying one payload on rigid cables (seed Eq. 2.41-2.70).

World frame (z up), SI units, state layout of docs/conventions.md: ``x = (q_f, q_f_dot)`` with
``q_f = (r_1, eta_1, ..., r_n, eta_n, r_p)`` of length 6n + 3.

Equations of motion (seed Eq. 2.46, 2.59-2.60, 2.70):

    M_f q_ddot + C_f q_dot + f_g + G^T Lambda = B_f u_f + d_f
    g_ddot + 2 alpha_f g_dot + beta_f^2 g = 0            (Baumgarte, Eq. 2.59)

With ``f = B_f u_f + d_f - f_g - C_f q_dot`` the multipliers are

    Lambda = (G M^-1 G^T)^-1 (G M^-1 f + G_dot q_dot + 2 alpha_f g_dot + beta_f^2 g)
    q_ddot = M^-1 (f - G^T Lambda),

which is Eq. 2.60/2.70 with the signs gathered. The cable rows of G touch only the UAV
translations (mass m_i I) and the payload (m_p I), and C_f, B_f only couple each UAV's own
coordinates, so the model never forms the (6n+3)^2 matrices:

- each UAV's attitude is integrated on its own (Euler equation pulled back to eta, see
  multirotor.py), vectorised over the n UAVs;
- with ``d_i = r_p - r_i``, ``G M^-1 G^T = diag(4 |d_i|^2 / m_i) + 4 D D^T / m_p`` (n x n) and
  ``(G M^-1 f)_i = 2 d_i . (a_p - a_i)`` with a the unconstrained accelerations.

Forces: UAV i gets thrust ``u_T R(eta_i) e_z`` and gravity ``-m_i g e_z``, and body torque tau
enters as ``W^T tau``; the payload gets gravity and the air-relative quadratic drag of
disturbances.py (gusts included). Rotor speeds are held constant over each RK4 step.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim import kernels
from multilift_sim.disturbances import Gust, gust_velocity
from multilift_sim.frames import seed_to_world_vector
from multilift_sim.multirotor import MultirotorParams, rotational_kinetic_energy


@dataclass(frozen=True, kw_only=True)
class FormationParams:
    """Physical and numerical parameters of the formation DAE (world frame, SI units)."""

    uavs: tuple[MultirotorParams, ...]       # UAV i = index i-1; UAV 1 is the leader
    cable_lengths: tuple[float, ...]         # l_i [m], one per UAV
    payload_mass: float                      # m_p [kg]
    payload_drag_coefficient: float          # c_pd of seed Eq. 2.53 [N s^2/m^2]
    baumgarte_alpha: float                   # alpha_f of seed Eq. 2.59 [1/s]
    baumgarte_beta: float                    # beta_f of seed Eq. 2.59 [1/s]
    gusts: tuple[Gust, ...] = ()             # 1-cosine gusts acting on the payload
    gravity: float = 9.81                    # g [m/s^2], along -z of the world frame

    def __post_init__(self) -> None:
        uavs = tuple(self.uavs)
        if not uavs:
            raise ValueError('FormationParams.uavs must hold at least one MultirotorParams')
        for i, uav in enumerate(uavs):
            if not isinstance(uav, MultirotorParams):
                raise ValueError(f'FormationParams.uavs[{i}] must be a MultirotorParams, got '
                                 f'{type(uav).__name__}')
        lengths = tuple(float(v) for v in self.cable_lengths)
        if len(lengths) != len(uavs):
            raise ValueError(f'FormationParams.cable_lengths has {len(lengths)} entries for '
                             f'{len(uavs)} UAVs')
        for i, length in enumerate(lengths):
            if not (math.isfinite(length) and length > 0):
                raise ValueError(f'FormationParams.cable_lengths[{i}] (cable {i + 1}) must be '
                                 f'finite and > 0 [m], got {length!r}')
        gusts = tuple(self.gusts)
        for i, gust in enumerate(gusts):
            if not isinstance(gust, Gust):
                raise ValueError(f'FormationParams.gusts[{i}] must be a Gust, got '
                                 f'{type(gust).__name__}')
        checks = (('payload_mass', lambda v: v > 0, '> 0'),
                  ('payload_drag_coefficient', lambda v: v >= 0, '>= 0'),
                  ('baumgarte_alpha', lambda v: v >= 0, '>= 0'),
                  ('baumgarte_beta', lambda v: v >= 0, '>= 0'),
                  ('gravity', lambda v: v >= 0, '>= 0'))
        for name, rule, text in checks:
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and rule(value)):
                raise ValueError(f'FormationParams.{name} must be finite and {text}, got '
                                 f'{value!r}')
        object.__setattr__(self, 'uavs', uavs)
        object.__setattr__(self, 'cable_lengths', lengths)
        object.__setattr__(self, 'gusts', gusts)

    @property
    def n_uavs(self) -> int:
        return len(self.uavs)


@dataclass(frozen=True)
class StateLayout:
    """Named views into the packed formation state ``x = (q_f, q_f_dot)`` of length 2(6n+3).

    Each accessor returns a view (writable when x is a contiguous float array), not a copy.
    """

    n_uavs: int

    def __post_init__(self) -> None:
        if self.n_uavs < 1:
            raise ValueError(f'StateLayout.n_uavs must be >= 1, got {self.n_uavs}')

    @property
    def n_coordinates(self) -> int:
        """Length of q_f: 6n + 3."""
        return 6 * self.n_uavs + 3

    @property
    def size(self) -> int:
        """Length of the state x: 2 (6n + 3)."""
        return 2 * self.n_coordinates

    def coordinates(self, x: np.ndarray) -> np.ndarray:
        """q_f, shape (6n + 3,)."""
        return x[:self.n_coordinates]

    def rates(self, x: np.ndarray) -> np.ndarray:
        """q_f_dot, shape (6n + 3,)."""
        return x[self.n_coordinates:]

    def _uav_block(self, q: np.ndarray) -> np.ndarray:
        return q[:6 * self.n_uavs].reshape(self.n_uavs, 6)

    def uav_positions(self, x: np.ndarray) -> np.ndarray:
        """UAV centres of mass r_i [m], world, shape (n, 3)."""
        return self._uav_block(self.coordinates(x))[:, :3]

    def uav_euler(self, x: np.ndarray) -> np.ndarray:
        """UAV ZYX Euler angles eta_i (roll, pitch, yaw) [rad], shape (n, 3)."""
        return self._uav_block(self.coordinates(x))[:, 3:]

    def payload_position(self, x: np.ndarray) -> np.ndarray:
        """Payload position r_p [m], world, shape (3,)."""
        return self.coordinates(x)[6 * self.n_uavs:]

    def uav_velocities(self, x: np.ndarray) -> np.ndarray:
        """UAV velocities [m/s], world, shape (n, 3)."""
        return self._uav_block(self.rates(x))[:, :3]

    def uav_euler_rates(self, x: np.ndarray) -> np.ndarray:
        """UAV Euler angle rates eta_dot_i [rad/s], shape (n, 3)."""
        return self._uav_block(self.rates(x))[:, 3:]

    def payload_velocity(self, x: np.ndarray) -> np.ndarray:
        """Payload velocity [m/s], world, shape (3,)."""
        return self.rates(x)[6 * self.n_uavs:]

    def pack(self, uav_positions: ArrayLike, uav_euler: ArrayLike, payload_position: ArrayLike,
             uav_velocities: ArrayLike | None = None, uav_euler_rates: ArrayLike | None = None,
             payload_velocity: ArrayLike | None = None) -> np.ndarray:
        """Packed state from its parts (world frame, SI); omitted rates are zero."""
        x = np.zeros(self.size)
        self.uav_positions(x)[:] = np.reshape(uav_positions, (self.n_uavs, 3))
        self.uav_euler(x)[:] = np.reshape(uav_euler, (self.n_uavs, 3))
        self.payload_position(x)[:] = payload_position
        if uav_velocities is not None:
            self.uav_velocities(x)[:] = np.reshape(uav_velocities, (self.n_uavs, 3))
        if uav_euler_rates is not None:
            self.uav_euler_rates(x)[:] = np.reshape(uav_euler_rates, (self.n_uavs, 3))
        if payload_velocity is not None:
            self.payload_velocity(x)[:] = payload_velocity
        return x


# Up to this many UAVs the plain-float kernel is faster than the numpy one, whose cost is per
# call, not per UAV (us per RK4 step, float vs numpy, on the 2-core development machine:
# n = 1: 39 vs 353, n = 10: 139 vs 282, n = 24: 315 vs 314, n = 48: 625 vs 383).
FLOAT_KERNEL_MAX_UAVS = 20


@dataclass(frozen=True)
class Integration:
    """What holding the rotor speeds over a control period gives (`Formulation.integrate`)."""
    state: np.ndarray              # the formation state at the end, (2(6n+3),)
    cable_tension: np.ndarray      # T_i = 2 l_i lambda_i at the start [N], (n,)
    constraint: np.ndarray         # g_i at the end [m^2], (n,)
    constraint_rate: np.ndarray    # g_i_dot at the end [m^2/s], (n,)


class FormationModel:
    """The stabilised formation DAE (seed Eq. 2.70) with structure-exploiting solves.

    ``rotor_speeds`` arguments are sequences of n per-UAV arrays of rotor speeds [rad/s]
    (shape (n_r,) each, rotor order of docs/conventions.md), held constant over a step.

    Two kernels compute the same accelerations: a numpy one vectorised over the UAVs that forms
    the n x n matrix G M^-1 G^T, and a plain-float one that loops over the UAVs and applies
    the Woodbury identity (a 3 x 3 solve, below). Small arrays make numpy's per-call overhead
    dominate, so ``kernel='auto'`` picks the float kernel for up to FLOAT_KERNEL_MAX_UAVS UAVs
    (for any number where it runs compiled: `kernels.enabled()`);
    ``'float'`` or ``'numpy'`` force one. They agree to rounding
    (tests/test_dynamics_formation.py).
    """

    def __init__(self, params: FormationParams, kernel: str = 'auto'):
        if kernel not in ('auto', 'float', 'numpy'):
            raise ValueError(f"FormationModel kernel must be 'auto', 'float' or 'numpy', got "
                             f'{kernel!r}')
        self.params = params
        self.layout = StateLayout(params.n_uavs)
        n = params.n_uavs
        self._n = n
        self._nq = self.layout.n_coordinates
        self._allocators = tuple(uav.allocator() for uav in params.uavs)
        rotor_counts = {a.n_rotors for a in self._allocators}
        # One (n, 4, n_r) stack when every UAV has the same rotor count, else per-UAV products.
        self._stacked_allocation = (np.stack([a.matrix for a in self._allocators])
                                    if len(rotor_counts) == 1 else None)
        self.uav_masses = np.array([uav.mass for uav in params.uavs])
        self.uav_inertia = np.array([uav.inertia for uav in params.uavs])      # (n, 3)
        self.cable_lengths = np.array(params.cable_lengths)
        self.payload_mass = float(params.payload_mass)
        self.gravity = float(params.gravity)
        self._two_alpha = 2.0 * params.baumgarte_alpha
        self._beta_sq = params.baumgarte_beta ** 2
        self._lengths_sq = self.cable_lengths ** 2
        self._inv_masses = 1.0 / self.uav_masses
        self._inv_payload_mass = 1.0 / self.payload_mass
        moments = self.uav_inertia.T                                             # (3, n)
        self._inv_inertia = 1.0 / moments
        # Euler's equation J omega_dot = tau - omega x J omega, per axis:
        # omega_dot_x = tau_x / I_xx - (I_zz - I_yy) / I_xx omega_y omega_z, and cyclically.
        self._gyro_coefficients = np.array([(moments[2] - moments[1]) / moments[0],
                                            (moments[0] - moments[2]) / moments[1],
                                            (moments[1] - moments[0]) / moments[2]])
        self._has_drag = params.payload_drag_coefficient > 0
        # compiled, the float kernel's O(n) loop beats numpy's n x n solve at every n
        self.uses_float_kernel = (kernel == 'float' or (kernel == 'auto' and (
            n <= FLOAT_KERNEL_MAX_UAVS or kernels.enabled())))
        # Per-UAV constants of the float kernel: (m_i, l_i^2, 1/I (3), gyro coefficients (3)).
        self._uav_constants = [
            (float(self.uav_masses[i]), float(self._lengths_sq[i]),
             *self._inv_inertia[:, i].tolist(), *self._gyro_coefficients[:, i].tolist())
            for i in range(n)]
        # (MULTILIFT_KERNEL, kernels.integrator(), kernels.model_constants), made on first use
        self._compiled: tuple | None = None

    # ----------------------------------------------------------------------------- inputs
    def wrenches(self, rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """Body wrenches ``u_i = (u_T [N], tau_x, tau_y, tau_z [N m])`` (FLU), shape (n, 4)."""
        if len(rotor_speeds) != self._n:
            raise ValueError(f'rotor_speeds has {len(rotor_speeds)} entries for {self._n} UAVs')
        if self._stacked_allocation is not None:
            try:
                speeds = np.asarray(rotor_speeds, dtype=float)
            except ValueError:     # ragged: the loop below names the UAV
                speeds = None
            if speeds is not None and speeds.shape == self._stacked_allocation.shape[::2]:
                return np.einsum('ikr,ir->ik', self._stacked_allocation, speeds * speeds)
        wrenches = np.empty((self._n, 4))
        for i, (allocator, speeds) in enumerate(zip(self._allocators, rotor_speeds)):
            speeds = np.asarray(speeds, dtype=float)
            if speeds.shape != (allocator.n_rotors,):
                raise ValueError(f'rotor_speeds[{i}] (uav{i + 1}) must have shape '
                                 f'({allocator.n_rotors},), got {speeds.shape}')
            wrenches[i] = allocator.wrench(speeds)
        return wrenches

    # --------------------------------------------------------------------------- dynamics
    def accelerations(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> tuple[np.ndarray, np.ndarray]:
        """(q_ddot (6n+3,), cable multipliers Lambda (n,) [N/m]) at time t [s] and state x.

        q_ddot holds [m/s^2] for positions and [rad/s^2] for Euler angles (world frame).
        """
        del t  # the model is autonomous: the inputs are held, gusts are stationary
        return self.accelerations_from_wrenches(x, self.wrenches(rotor_speeds))

    def accelerations_from_wrenches(self, x: np.ndarray,
                                    wrenches: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """As accelerations(), from body wrenches (n, 4) (u_T [N], tau [N m], FLU)."""
        x = np.asarray(x, dtype=float)
        wrenches = np.asarray(wrenches, dtype=float)
        if self.uses_float_kernel:
            q_ddot, multipliers = self._solve_floats(x.tolist(), wrenches.tolist())
            return np.array(q_ddot), np.array(multipliers)
        return self._solve_arrays(x, wrenches)

    def derivative(self, t: float, x: np.ndarray,
                   rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """State derivative ``x_dot = (q_f_dot, q_f_ddot)``, shape (2(6n+3),)."""
        x = np.asarray(x, dtype=float)
        q_ddot, _ = self.accelerations(t, x, rotor_speeds)
        return np.concatenate((x[self._nq:], q_ddot))

    def step(self, t: float, x: np.ndarray, rotor_speeds: Sequence[ArrayLike],
             dt: float) -> np.ndarray:
        """One classic RK4 step of length dt [s] from (t, x) with the rotor speeds held."""
        del t  # autonomous, see accelerations()
        wrenches = self.wrenches(rotor_speeds)
        x = np.asarray(x, dtype=float)
        if self.uses_float_kernel:
            return np.array(self.rk4_floats(x.tolist(), wrenches.tolist(), dt)[0])
        return self._rk4_arrays(x, wrenches, dt)

    def integrate(self, x: np.ndarray, rotor_speeds: Sequence[ArrayLike], dt: float,
                  steps: int) -> Integration:
        """`steps` RK4 steps of dt [s] from x with the rotor speeds [rad/s] held (one control
        period of seed Algorithm 1). The wrenches are formed once (the speeds are held) and
        the tension is that of the first stage of the first step (the multipliers at x)."""
        wrenches = self.wrenches(rotor_speeds)
        if self.uses_float_kernel and kernels.enabled():  # the same kernel, compiled
            mode = kernels.mode()
            if self._compiled is None or self._compiled[0] != mode:
                self._compiled = (mode, kernels.integrator(), kernels.model_constants(self))
            state, multipliers, g, g_dot = kernels.integrate(*self._compiled[1:], x, wrenches,
                                                             dt, steps)
            return Integration(state, 2.0 * self.cable_lengths * multipliers, g, g_dot)
        if self.uses_float_kernel:
            w = wrenches.tolist()
            state, multipliers = self.rk4_floats(list(map(float, x)), w, dt)
            for _ in range(steps - 1):
                state = self.rk4_floats(state, w, dt)[0]
            g, g_dot = self._residuals_floats(state)
            return Integration(np.array(state), 2.0 * self.cable_lengths * multipliers,
                               np.array(g), np.array(g_dot))
        x = np.asarray(x, dtype=float)
        _, multipliers = self._solve_arrays(x, wrenches)
        for _ in range(steps):
            x = self._rk4_arrays(x, wrenches, dt)
        g, g_dot = self.constraint_residuals(x)
        return Integration(x, 2.0 * self.cable_lengths * multipliers, g, g_dot)

    def _residuals_floats(self, x: list[float]) -> tuple[list[float], list[float]]:
        """(g [m^2], g_dot [m^2/s]) per cable from a state as floats (the arithmetic of
        constraint_residuals without numpy's per-call overhead)."""
        nq, p = self._nq, 6 * self._n
        px, py, pz = x[p:p + 3]
        pvx, pvy, pvz = x[nq + p:nq + p + 3]
        g, g_dot = [], []
        for i, (_, length_sq, *_rest) in enumerate(self._uav_constants):
            b = 6 * i
            dx, dy, dz = px - x[b], py - x[b + 1], pz - x[b + 2]
            dvx, dvy, dvz = pvx - x[nq + b], pvy - x[nq + b + 1], pvz - x[nq + b + 2]
            g.append(dx * dx + dy * dy + dz * dz - length_sq)
            g_dot.append(2.0 * (dx * dvx + dy * dvy + dz * dvz))
        return g, g_dot

    def rk4_floats(self, x: list[float], wrenches: list[list[float]],
                   dt: float) -> tuple[list[float], list[float]]:
        """One RK4 step on plain floats (float kernel) with the body wrenches held:
        (the new state, the cable multipliers at the start state)."""
        nq, solve, half = self._nq, self._solve_floats, 0.5 * dt
        # k = q_dot + q_ddot is list concatenation: the state derivative (q_dot, q_ddot)
        acc, multipliers = solve(x, wrenches)
        k1 = x[nq:] + acc
        x2 = [xi + half * ki for xi, ki in zip(x, k1)]
        k2 = x2[nq:] + solve(x2, wrenches)[0]
        x3 = [xi + half * ki for xi, ki in zip(x, k2)]
        k3 = x3[nq:] + solve(x3, wrenches)[0]
        x4 = [xi + dt * ki for xi, ki in zip(x, k3)]
        k4 = x4[nq:] + solve(x4, wrenches)[0]
        sixth = dt / 6.0
        return ([xi + sixth * (a + 2.0 * (b + c) + d)
                 for xi, a, b, c, d in zip(x, k1, k2, k3, k4)], multipliers)

    def _rk4_arrays(self, x: np.ndarray, wrenches: np.ndarray, dt: float) -> np.ndarray:
        nq, solve = self._nq, self._solve_arrays
        k1 = np.concatenate((x[nq:], solve(x, wrenches)[0]))
        x2 = x + 0.5 * dt * k1
        k2 = np.concatenate((x2[nq:], solve(x2, wrenches)[0]))
        x3 = x + 0.5 * dt * k2
        k3 = np.concatenate((x3[nq:], solve(x3, wrenches)[0]))
        x4 = x + dt * k3
        k4 = np.concatenate((x4[nq:], solve(x4, wrenches)[0]))
        return x + (dt / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)

    def _payload_force_per_mass(self, position: Sequence[float],
                                velocity: Sequence[float]) -> tuple[float, float, float]:
        """Drag (with gusts) on the payload divided by m_p [m/s^2], gravity excluded.

        disturbances.payload_drag and gust_velocity in plain floats (they cost microseconds of
        numpy overhead per call here); tests compare the model against those functions.
        """
        if not self._has_drag:
            return 0.0, 0.0, 0.0
        air_x = air_y = air_z = 0.0
        for gust in self.params.gusts:
            speed = gust.speed(position)
            if speed != 0.0:
                air_x += speed * gust.direction[0]
                air_y += speed * gust.direction[1]
                air_z += speed * gust.direction[2]
        rel_x, rel_y, rel_z = velocity[0] - air_x, velocity[1] - air_y, velocity[2] - air_z
        # Eq. 2.53 on the air-relative velocity: -c_pd v_rel |v_rel| / m_p
        scale = (-self.params.payload_drag_coefficient * self._inv_payload_mass
                 * math.sqrt(rel_x * rel_x + rel_y * rel_y + rel_z * rel_z))
        return scale * rel_x, scale * rel_y, scale * rel_z

    def _solve_floats(self, x: list[float],
                      wrenches: list[list[float]]) -> tuple[list[float], list[float]]:
        """q_ddot and Lambda with plain floats, one UAV at a time (the maths of _solve_arrays,
        whose comments give the equations).

        The cable solve uses the Woodbury identity on ``A = G M^-1 G^T = Delta + 4 D D^T / m_p``
        with ``Delta = diag(delta_i)``, ``delta_i = 4 |d_i|^2 / m_i``: ``A^-1 b = Delta^-1 (b -
        D y)`` where ``S y = D^T Delta^-1 b`` and ``S = m_p/4 I + sum_i d_i d_i^T / delta_i``
        = ``(m_p I + sum_i m_i e_i e_i^T) / 4`` (e_i the cable directions): a 3 x 3 system, the
        payload's effective mass, always invertible.
        """
        n, nq, gravity = self._n, self._nq, self.gravity
        two_alpha, beta_sq = self._two_alpha, self._beta_sq
        sin, cos = math.sin, math.cos
        p = 6 * n
        px, py, pz = x[p], x[p + 1], x[p + 2]
        pvx, pvy, pvz = x[nq + p], x[nq + p + 1], x[nq + p + 2]
        drag_ax, drag_ay, drag_az = self._payload_force_per_mass((px, py, pz), (pvx, pvy, pvz))
        acc = [0.0] * nq
        cables = []
        # S (symmetric, entries s_jk) and its right-hand side D^T Delta^-1 b (sb_j)
        s00 = s11 = s22 = 0.25 * self.payload_mass
        s01 = s02 = s12 = sb0 = sb1 = sb2 = 0.0
        for i, (mass, length_sq, inv_ixx, inv_iyy, inv_izz, gyro_x, gyro_y,
                gyro_z) in enumerate(self._uav_constants):
            base = 6 * i
            rx, ry, rz, phi, theta, psi = x[base:base + 6]
            vx, vy, vz, phi_dot, theta_dot, psi_dot = x[nq + base:nq + base + 6]
            thrust, torque_x, torque_y, torque_z = wrenches[i]
            s_phi, c_phi = sin(phi), cos(phi)
            s_theta, c_theta = sin(theta), cos(theta)
            s_psi, c_psi = sin(psi), cos(psi)

            # attitude: W eta_ddot = omega_dot - W_dot eta_dot, then W^-1 (Eq. 2.8)
            c_theta_psi_dot = c_theta * psi_dot
            omega_x = phi_dot - s_theta * psi_dot
            omega_y = c_phi * theta_dot + s_phi * c_theta_psi_dot
            omega_z = c_phi * c_theta_psi_dot - s_phi * theta_dot
            s_theta_theta_psi_dot = s_theta * theta_dot * psi_dot
            w_eta_ddot_x = (torque_x * inv_ixx - gyro_x * omega_y * omega_z
                            + c_theta_psi_dot * theta_dot)
            w_eta_ddot_y = (torque_y * inv_iyy - gyro_y * omega_z * omega_x
                            - phi_dot * omega_z + s_phi * s_theta_theta_psi_dot)
            w_eta_ddot_z = (torque_z * inv_izz - gyro_z * omega_x * omega_y
                            + phi_dot * omega_y + c_phi * s_theta_theta_psi_dot)
            yaw_part = s_phi * w_eta_ddot_y + c_phi * w_eta_ddot_z
            acc[base + 3] = w_eta_ddot_x + s_theta / c_theta * yaw_part
            acc[base + 4] = c_phi * w_eta_ddot_y - s_phi * w_eta_ddot_z
            acc[base + 5] = yaw_part / c_theta

            # thrust along R e_z
            thrust_per_mass = thrust / mass
            s_theta_c_phi = s_theta * c_phi
            thrust_ax = (c_psi * s_theta_c_phi + s_psi * s_phi) * thrust_per_mass
            thrust_ay = (s_psi * s_theta_c_phi - c_psi * s_phi) * thrust_per_mass
            thrust_az = c_theta * c_phi * thrust_per_mass

            # cable i: d = r_p - r_i, its rate, and row i of the multiplier equation (Eq. 2.60)
            dx, dy, dz = px - rx, py - ry, pz - rz
            dvx, dvy, dvz = pvx - vx, pvy - vy, pvz - vz
            offset_sq = dx * dx + dy * dy + dz * dz
            cable_rhs = (2.0 * (dx * (drag_ax - thrust_ax) + dy * (drag_ay - thrust_ay)
                                + dz * (drag_az - thrust_az))              # G M^-1 f
                         + 2.0 * (dvx * dvx + dvy * dvy + dvz * dvz)        # G_dot q_dot
                         + two_alpha * 2.0 * (dx * dvx + dy * dvy + dz * dvz)
                         + beta_sq * (offset_sq - length_sq))
            inv_delta = 0.25 * mass / offset_sq
            s00 += dx * dx * inv_delta
            s01 += dx * dy * inv_delta
            s02 += dx * dz * inv_delta
            s11 += dy * dy * inv_delta
            s12 += dy * dz * inv_delta
            s22 += dz * dz * inv_delta
            weighted_rhs = cable_rhs * inv_delta
            sb0 += dx * weighted_rhs
            sb1 += dy * weighted_rhs
            sb2 += dz * weighted_rhs
            cables.append((dx, dy, dz, cable_rhs, inv_delta, thrust_ax, thrust_ay, thrust_az,
                           mass))
        # y = S^-1 sb by the adjugate of the symmetric 3 x 3 S
        c00 = s11 * s22 - s12 * s12
        c01 = s02 * s12 - s01 * s22
        c02 = s01 * s12 - s02 * s11
        c11 = s00 * s22 - s02 * s02
        c12 = s01 * s02 - s00 * s12
        c22 = s00 * s11 - s01 * s01
        inv_det = 1.0 / (s00 * c00 + s01 * c01 + s02 * c02)
        y0 = (c00 * sb0 + c01 * sb1 + c02 * sb2) * inv_det
        y1 = (c01 * sb0 + c11 * sb1 + c12 * sb2) * inv_det
        y2 = (c02 * sb0 + c12 * sb1 + c22 * sb2) * inv_det
        multipliers = [0.0] * n
        sum_x = sum_y = sum_z = 0.0
        for i, (dx, dy, dz, cable_rhs, inv_delta, thrust_ax, thrust_ay, thrust_az,
                mass) in enumerate(cables):
            multiplier = (cable_rhs - dx * y0 - dy * y1 - dz * y2) * inv_delta
            multipliers[i] = multiplier
            pull = 2.0 * multiplier / mass           # UAV i: +2 lambda_i d_i / m_i
            base = 6 * i
            acc[base] = thrust_ax + pull * dx
            acc[base + 1] = thrust_ay + pull * dy
            acc[base + 2] = thrust_az + pull * dz - gravity
            sum_x += multiplier * dx
            sum_y += multiplier * dy
            sum_z += multiplier * dz
        pull = 2.0 * self._inv_payload_mass          # payload: -2 sum_i lambda_i d_i / m_p
        acc[p] = drag_ax - pull * sum_x
        acc[p + 1] = drag_ay - pull * sum_y
        acc[p + 2] = drag_az - pull * sum_z - gravity
        return acc, multipliers

    def _solve_arrays(self, x: np.ndarray, wrench: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """q_ddot and Lambda for state x under per-UAV body wrenches (n, 4), vectorised."""
        n, nq = self._n, self._nq
        uav_q = x[:6 * n].reshape(n, 6)
        uav_v = x[nq:nq + 6 * n].reshape(n, 6)
        payload_position = x[6 * n:nq]
        payload_velocity = x[nq + 6 * n:]
        angles = uav_q[:, 3:].T                      # rows phi, theta, psi; columns UAVs
        rates = uav_v[:, 3:].T
        sines = np.sin(angles)
        cosines = np.cos(angles)
        s_phi, s_theta, s_psi = sines[0], sines[1], sines[2]
        c_phi, c_theta, c_psi = cosines[0], cosines[1], cosines[2]
        phi_dot, theta_dot, psi_dot = rates[0], rates[1], rates[2]
        q_ddot = np.empty(nq)
        uav_acc = q_ddot[:6 * n].reshape(n, 6)

        # Attitude: omega = W eta_dot (Eq. 2.7), Euler's equation, eta_ddot = W^-1 (omega_dot
        # - W_dot eta_dot) -- the same as M_eta^-1 (W^T tau - C_eta eta_dot), see multirotor.py.
        c_theta_psi_dot = c_theta * psi_dot
        omega_x = phi_dot - s_theta * psi_dot
        omega_y = c_phi * theta_dot + s_phi * c_theta_psi_dot
        omega_z = c_phi * c_theta_psi_dot - s_phi * theta_dot
        torque = wrench[:, 1:].T
        gyro = self._gyro_coefficients
        inv_inertia = self._inv_inertia
        s_theta_theta_psi_dot = s_theta * theta_dot * psi_dot
        # W eta_ddot = omega_dot - W_dot eta_dot, W_dot from kinematics.euler_rate_matrix_dot
        w_eta_ddot_x = (torque[0] * inv_inertia[0] - gyro[0] * omega_y * omega_z
                        + c_theta_psi_dot * theta_dot)
        w_eta_ddot_y = (torque[1] * inv_inertia[1] - gyro[1] * omega_z * omega_x
                        - phi_dot * omega_z + s_phi * s_theta_theta_psi_dot)
        w_eta_ddot_z = (torque[2] * inv_inertia[2] - gyro[2] * omega_x * omega_y
                        + phi_dot * omega_y + c_phi * s_theta_theta_psi_dot)
        yaw_part = s_phi * w_eta_ddot_y + c_phi * w_eta_ddot_z         # W^-1 of Eq. 2.8
        uav_acc[:, 3] = w_eta_ddot_x + s_theta / c_theta * yaw_part
        uav_acc[:, 4] = c_phi * w_eta_ddot_y - s_phi * w_eta_ddot_z
        uav_acc[:, 5] = yaw_part / c_theta

        # Unconstrained translational accelerations: thrust along R e_z (Eq. 2.6, 2.20).
        thrust_per_mass = wrench[:, 0] * self._inv_masses
        s_theta_c_phi = s_theta * c_phi
        thrust_acc = np.empty((n, 3))
        thrust_acc[:, 0] = (c_psi * s_theta_c_phi + s_psi * s_phi) * thrust_per_mass
        thrust_acc[:, 1] = (s_psi * s_theta_c_phi - c_psi * s_phi) * thrust_per_mass
        thrust_acc[:, 2] = c_theta * c_phi * thrust_per_mass
        payload_force_acc = np.array(self._payload_force_per_mass(payload_position,
                                                                  payload_velocity))
        # Gravity is common to every body, so it cancels in a_p - a_i; it is added at the end.

        # Cable multipliers (Eq. 2.60) with d_i = r_p - r_i.
        offsets = payload_position - uav_q[:, :3]
        relative_velocity = payload_velocity - uav_v[:, :3]
        offsets_sq = np.einsum('ij,ij->i', offsets, offsets)
        residual = offsets_sq - self._lengths_sq                                   # g
        residual_rate = 2.0 * np.einsum('ij,ij->i', offsets, relative_velocity)    # g_dot
        jacobian_rate = 2.0 * np.einsum('ij,ij->i', relative_velocity, relative_velocity)
        free_acc = 2.0 * np.einsum('ij,ij->i', offsets, payload_force_acc - thrust_acc)
        rhs = (free_acc + jacobian_rate + self._two_alpha * residual_rate
               + self._beta_sq * residual)
        # G M^-1 G^T = diag(4 |d_i|^2 / m_i) + 4 D D^T / m_p
        schur = (4.0 * self._inv_payload_mass) * (offsets @ offsets.T)
        schur[np.diag_indices(n)] += 4.0 * offsets_sq * self._inv_masses
        multipliers = np.linalg.solve(schur, rhs)

        # q_ddot = M^-1 (f - G^T Lambda): UAV i gets +2 lambda_i d_i / m_i, payload
        # -2 sum_i lambda_i d_i / m_p.
        pull = (2.0 * multipliers)[:, None] * offsets
        uav_acc[:, :3] = thrust_acc + pull * self._inv_masses[:, None]
        uav_acc[:, 2] -= self.gravity
        payload_acc = payload_force_acc - pull.sum(axis=0) * self._inv_payload_mass
        payload_acc[2] -= self.gravity
        q_ddot[6 * n:] = payload_acc
        return q_ddot, multipliers

    # -------------------------------------------------------------------------- reporting
    def cable_tension(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """Cable tensions ``T_i = 2 l_i lambda_i`` [N], shape (n,); negative = compression."""
        _, multipliers = self.accelerations(t, x, rotor_speeds)
        return 2.0 * self.cable_lengths * multipliers

    def constraint_residuals(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(g [m^2], g_dot [m^2/s]) of every cable (seed Eq. 2.42, 2.56), shapes (n,)."""
        x = np.asarray(x, dtype=float)
        layout = self.layout
        offsets = layout.payload_position(x) - layout.uav_positions(x)
        relative_velocity = layout.payload_velocity(x) - layout.uav_velocities(x)
        residual = np.einsum('ij,ij->i', offsets, offsets) - self._lengths_sq
        return residual, 2.0 * np.einsum('ij,ij->i', offsets, relative_velocity)

    def kinetic_energy(self, x: np.ndarray) -> float:
        """Translational plus rotational kinetic energy of UAVs and payload [J] (Eq. 2.43)."""
        x = np.asarray(x, dtype=float)
        layout = self.layout
        velocities = layout.uav_velocities(x)
        payload_velocity = layout.payload_velocity(x)
        translational = 0.5 * (np.sum(self.uav_masses * np.sum(velocities ** 2, axis=1))
                               + self.payload_mass * payload_velocity @ payload_velocity)
        rotational = np.sum(rotational_kinetic_energy(self.uav_inertia, layout.uav_euler(x),
                                                      layout.uav_euler_rates(x)))
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
        return gust_velocity(self.params.gusts, self.layout.payload_position(np.asarray(x)))

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
    All velocities are zero, which satisfies Eq. 2.56. Returns x of length 18.
    """
    seed_offset = cable_length * np.array([math.cos(alpha) * math.sin(beta), -math.sin(alpha),
                                           math.cos(alpha) * math.cos(beta)])
    uav_position = np.asarray(uav_position, dtype=float)
    return StateLayout(1).pack(uav_position, eta, uav_position + seed_to_world_vector(seed_offset))
