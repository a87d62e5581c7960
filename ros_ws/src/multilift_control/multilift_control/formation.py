"""Formation control by virtual constraints (seed §3.2, Eq. 3.1-3.13, Table 3.1): the follower.

The followers keep the formation geometry by producing, with their thrust, the constraint force
that would hold the UAVs on the hypersurface g_vc(r_f) = 0 (Eq. 3.5). Everything is in the world
frame (z up) of docs/conventions.md; the seed writes its equations in a z-down frame, so its
"V" offsets v_1i go through `multilift_sim.frames` (`formation_geometry.v_offset`).
UAV 1 (index 0) is the leader. The arithmetic is the laws' (`multilift_control.laws`:
`constraints` the rows, `follower` the forces and a follower's tick); the constraints it keeps
are `virtual_constraints`' (FormationGeometry, VirtualConstraints); the class here builds its
arrays once and calls the laws, compiled or not as MULTILIFT_KERNEL says (`laws.runnable`).
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from multilift_control import laws
from multilift_control.cascade import (CascadeController, ControlOutput, FormationStates,
                                       UavState)
from multilift_control.laws.follower import follower_force, follower_tick, formation_terms
from multilift_control.laws.layout import (FOLLOWER_ALTITUDE_OFFSET, FOLLOWER_BETA_SQ,
                                           FOLLOWER_COMMANDED, FOLLOWER_FREE_MODE_GAIN,
                                           FOLLOWER_GRAVITY, FOLLOWER_HOVER_MASS,
                                           FOLLOWER_INTEGRAL, FOLLOWER_INTEGRAL_LIMIT,
                                           FOLLOWER_KD_Z, FOLLOWER_KI_Z, FOLLOWER_KP_Z,
                                           FOLLOWER_LEADER_CLIMB, FOLLOWER_LIFT,
                                           FOLLOWER_LINEAR,
                                           FOLLOWER_MEMORY_SIZE, FOLLOWER_SIZE,
                                           FOLLOWER_TWO_ALPHA, FOLLOWER_YAW)
from multilift_control.virtual_constraints import FormationGeometry, VirtualConstraints
from multilift_sim import formation_geometry  # the start places, world
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.registry import one_of
from multilift_sim.scenario import ControlConfig
from multilift_sim.start import uav_offsets

OWN_THRUST = ('commanded', 'measured')  # where a follower's u_i comes from (FormationFollower)
_COND_LIMIT = 1e10  # cond(J M^-1 J^T) above which the linear law takes its pseudo-inverse


# The last (J, M^-1) -> A^+ of `_law_inverse`: every follower of a formation needs the same one
# (an SVD and an inverse of a 3(n-1) square matrix each: 1.4 s for the 99 followers of a V of
# 100, built one after the other in a headless run)
_last_law_inverse: tuple[bytes, np.ndarray] | None = None


def _law_inverse(jac: np.ndarray, inv_m: np.ndarray) -> np.ndarray:
    """A^+ of A = J M^-1 J^T: A^-1, or the pseudo-inverse when A is ill-conditioned."""
    global _last_law_inverse
    key = jac.tobytes() + inv_m.tobytes() + repr(jac.shape).encode()
    if _last_law_inverse is not None and _last_law_inverse[0] == key:
        return _last_law_inverse[1]
    a = (jac * inv_m) @ jac.T
    a_plus = np.linalg.inv(a) if np.linalg.cond(a) < _COND_LIMIT else np.linalg.pinv(a)
    a_plus.flags.writeable = False
    _last_law_inverse = (key, a_plus)
    return a_plus


class FormationFollower:
    """Controller of follower UAV `index` (>= 1): keeps its rows of g_vc and the leader's
    altitude (seed §3.2).

    Each tick, from the states of all n UAVs and their thrust vectors u (world) [N]:
    - horizontal: F_xy = (u_i + u_vf,i)_xy, u_vf from `virtual_forces`. The seed feeds u_vf
      alone to Eq. 3.13; we read u_vf as the correction to the force the follower already
      produces (it enters Eq. 3.9 next to u), so the follower adds it to its own thrust. Repeated
      every tick with the leader unaltered this converges to the follower-only solution
      Lambda_i = 0, i.e. for linear rows a_i = a_1 + 2 alpha_vc J r_dot + beta_vc^2 g_vc with
      a_i = (u_i - m_i g e_z) / m_i.
      u_i: with own_thrust='commanded' (default) the lift this follower asked for at its last
      tick, R(eta_d) e_z u_T with u_T after rotor saturation (the caller's thrust_vectors[i] at
      the first tick only); with 'measured' the caller's thrust_vectors[i] every tick. The
      measured lift lags the command by the attitude loop; fed back, it raised the twin-lift's
      largest formation error in the headless simulator from 0.44 m to 0.74 m.
    - free follower motions (`VirtualConstraints.free_follower_motions`: a circle's rotation
      about the leader, each 'distance' follower's tangent; none for linear and V rows): the
      law leaves the force there at F = u_i, unrestored and undamped, and in the headless
      circle3 run the triangle spins up after the leader's first turn (with point masses too:
      tests/test_formation.py). With `free_mode_gain` k_f [1/s] (not in the seed; None = off,
      `from_scenario` uses 2 alpha_vc) the followers' forces in those motions become
      m_i (a_1 + k_f (v_1 - v_i)) with a_1 = (u_1)_xy / m_1 the leader's horizontal thrust
      acceleration. u_vf has no component there, so the law is unchanged where rows act.
    - vertical: an altitude loop to z_d,i = z_1 (the leader's altitude, seed §3.2) plus
      `altitude_offset` (default: the d_z of a linear geometry, zero for the seed's):
      F_z = hover_mass (g + kp_z e - kd_z zi_dot + ki_z int e dt), e = z_d,i - z_i: the
      reference z_1 is updated in the outer loop and the damping is on the follower's own
      vertical velocity (seed §4.3: hence the follower's lag in the climb, Fig. 4.7), the
      integral clamped to +-g/2 as the cascade's; the z entries of the scenario's position
      gains. (`from_scenario` sets altitude_offset from the start: equal
      cables cannot hold every UAV of a V of five at the leader's height.)
    - yaw held at `yaw` (default: the yaw measured at the first tick);
    - roll, pitch, thrust from Eq. 3.13 (`cascade.attitude_from_force`), then the cascade's
      attitude loop and `RotorMixer` (`CascadeController.command`).
    masses: the m_i of M_f,r (n,) [kg]; hover_mass: this UAV and its payload share [kg].
    """

    def __init__(self, vehicle: MultirotorParams, index: int, constraints: VirtualConstraints,
                 masses: np.ndarray, gains: ControlConfig, hover_mass: float, gravity: float,
                 alpha_vc: float, beta_vc: float, yaw: float | None = None,
                 own_thrust: str = 'commanded', altitude_offset: float | None = None,
                 free_mode_gain: float | None = None):
        if not 1 <= index < constraints.n:
            raise ValueError(f'follower index must be within 1..{constraints.n - 1}, got {index}')
        one_of('own_thrust', own_thrust, OWN_THRUST)
        if free_mode_gain is not None and not (math.isfinite(free_mode_gain)
                                               and free_mode_gain >= 0):
            raise ValueError(f'free_mode_gain must be None or finite and >= 0 [1/s], got '
                             f'{free_mode_gain!r}')
        self.own_thrust = own_thrust
        self.free_mode_gain = free_mode_gain
        self.vehicle = vehicle
        self.index = index
        self.constraints = constraints
        self.masses = np.asarray(masses, dtype=float).reshape(constraints.n)
        self.gains = gains
        self.hover_mass = hover_mass
        self.gravity = gravity
        self.alpha_vc = alpha_vc
        self.beta_vc = beta_vc
        self.rows = constraints.rows_of(index)
        if altitude_offset is None:  # d_z of a linear geometry, else 0
            nominal = constraints.nominal_positions(np.zeros(3))
            altitude_offset = nominal[index, 2] - nominal[0, 2]
        self.altitude_offset = float(altitude_offset)  # z_d,i - z_1 [m]
        self.cascade = CascadeController(vehicle, gains, hover_mass, gravity)
        self.integral_limit = 0.5 * gravity
        self.constants = np.empty(FOLLOWER_SIZE)  # the FOLLOWER_* slots
        self.constants[FOLLOWER_TWO_ALPHA] = 2.0 * alpha_vc
        self.constants[FOLLOWER_BETA_SQ] = beta_vc ** 2
        self.constants[FOLLOWER_ALTITUDE_OFFSET] = self.altitude_offset
        self.constants[FOLLOWER_HOVER_MASS] = hover_mass
        self.constants[FOLLOWER_GRAVITY] = gravity
        self.constants[FOLLOWER_KP_Z] = gains.position_kp[2]
        self.constants[FOLLOWER_KD_Z] = gains.position_kd[2]
        self.constants[FOLLOWER_KI_Z] = gains.position_ki[2]
        self.constants[FOLLOWER_INTEGRAL_LIMIT] = self.integral_limit
        self.constants[FOLLOWER_COMMANDED] = float(own_thrust == 'commanded')
        self.constants[FOLLOWER_FREE_MODE_GAIN] = (math.nan if free_mode_gain is None
                                                   else free_mode_gain)
        self.constants[FOLLOWER_LINEAR] = float(constraints.linear)
        self.constants[FOLLOWER_LEADER_CLIMB] = 0.0  # the seed's: damping on -z_i_dot
        # linear rows: the law's constant matrices P, Q (none for nonlinear rows)
        self.law_p, self.law_q = (self._linear_law_matrices() if constraints.linear
                                  else (np.zeros((3, 0)), np.zeros((3, 0))))
        # what the law remembers (FOLLOWER_INTEGRAL, _LAST_T, _LIFT, _YAW; NaN: none yet)
        self.memory = np.full(FOLLOWER_MEMORY_SIZE, math.nan)
        self.memory[FOLLOWER_INTEGRAL] = 0.0
        self.memory[FOLLOWER_YAW] = math.nan if yaw is None else yaw
        self._terms = laws.runnable(formation_terms)
        self._tick = laws.runnable(follower_tick)
        self._force = laws.runnable(follower_force)

    @property
    def lift(self) -> np.ndarray | None:
        """The lift asked at the last tick, R(eta_d) e_z u_T, world [N] (None before it)."""
        lift = self.memory[FOLLOWER_LIFT:FOLLOWER_LIFT + 3]
        return None if math.isnan(lift[0]) else lift.copy()

    @property
    def integral(self) -> float:
        """The altitude loop's integral term [m/s^2]."""
        return float(self.memory[FOLLOWER_INTEGRAL])

    @property
    def yaw(self) -> float | None:
        """The heading held [rad] (None before the first tick measured it)."""
        yaw = float(self.memory[FOLLOWER_YAW])
        return None if math.isnan(yaw) else yaw

    @classmethod
    def from_scenario(cls, scenario, index: int, **options) -> FormationFollower:
        """The follower of `scenario` (a multilift_sim.scenario.Scenario with a formation);
        `options` (yaw, own_thrust, altitude_offset, free_mode_gain) go to the constructor.

        Choices made here, each overridable through `options`:
        - M_f,r uses each UAV's hover mass (UAV + payload/n) rather than the seed's m_i, so that
          f_i balances the hover thrust that carries the payload share;
        - free_mode_gain = 2 alpha_vc, the rows' own damping of g_dot (pass None for the bare
          law; without it the circle3 and 'distance' formations spin up after a turn);
        - altitude_offset = z_i - z_1 of the scenario's start (`formation_geometry`: the payload
          hangs below the UAVs' centroid, every cable at its length). Zero for the twin, the V
          of three and circles; for the V of five equal cables cannot put every UAV at the
          leader's height, and tracking z_1 (the seed's z_d,i) there made the followers shed
          thrust until the leader saturated and the formation fell.
        """
        n = scenario.n_uavs
        config = scenario.formation
        masses = np.array([u.vehicle.mass + scenario.payload.mass / n for u in scenario.uavs])
        constraints = VirtualConstraints(FormationGeometry.from_config(config, n))
        options.setdefault('free_mode_gain', 2.0 * config.alpha_vc)
        if 'altitude_offset' not in options:
            start, _ = formation_geometry.hanging_payload(
                constraints.nominal_positions(scenario.uavs[0].position),
                [u.cable_length for u in scenario.uavs], scenario.payload.attach_points,
                uav_offsets(scenario))  # the simulator's start (simulation.formation_start)
            options['altitude_offset'] = float(start[index, 2] - start[0, 2])
        return cls(scenario.uavs[index].vehicle, index, constraints, masses, scenario.control,
                   float(masses[index]), scenario.simulation.gravity, config.alpha_vc,
                   config.beta_vc, **options)

    def _linear_law_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """For linear (and V) rows J_vc and M are constant, so this follower's row of
        u_vf = -J^T (J M^-1 J^T)^-1 rhs (`virtual_forces`) is a fixed linear map of rhs:
        u_vf,i = P rhs with P = -J_i^T A^+ (A^+ = A^-1, or the pseudo-inverse when A is
        ill-conditioned: the least-squares, minimum-norm Lambda of `virtual_forces`). With
        rhs = J (M^-1 (u - f) + 2 alpha v) + beta^2 g_vc (J_dot = 0) this is
        u_vf,i = Q (M^-1 (u - f) + 2 alpha v) + beta^2 P g_vc, Q = P J: O(n) per tick instead
        of the O(n^3) solve of the general law (`laws.follower.linear_virtual_force`).
        Returns (P (3, m), Q (3, 3n)), read-only."""
        c = self.constraints
        jac = c.linear_jacobian
        a_plus = _law_inverse(jac, np.repeat(1.0 / self.masses, 3))
        p = -(jac[:, 3 * self.index:3 * self.index + 3].T @ a_plus)
        q = p @ jac
        return p, q

    def desired_force(self, t: float, states: Sequence[UavState], thrust_vectors: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(F world [N], errors g_vc[rows_of(i)], error rates J r_dot[rows_of(i)]).

        The force the thrust should produce (the law of the class docstring) before Eq. 3.13;
        advances the altitude integral to t [s]. `update` computes it once per tick.
        """
        vectors = np.asarray(thrust_vectors, dtype=float)
        terms = self._terms(self.constants, self.masses, self.constraints.rows,
                            self.constraints.targets, FormationStates.of(states).array, vectors)
        return self._force(self.constants, self.masses, self.constraints.rows,
                           self.constraints.targets, self.law_p, self.law_q, self.index,
                           self.memory, float(t), vectors, terms)

    def update(self, t: float, states: Sequence[UavState], thrust_vectors: np.ndarray
               ) -> tuple[ControlOutput, np.ndarray, np.ndarray]:
        """One control tick at simulated time t [s] (`laws.follower.follower_tick`: what the
        followers of the tick share, then this follower's step, in one call).

        states: all n UAVs at the same tick; thrust_vectors (n, 3): each UAV's current lift
        R_i e_z u_T,i, world [N]. Returns (ControlOutput, the follower's rows of g_vc [m or
        m^2], their rates [m/s or m^2/s]).
        """
        c = self.cascade
        speeds, saturated, setpoint, thrust, errors, rates = self._tick(
            self.constants, self.masses, self.constraints.rows, self.constraints.targets,
            self.law_p, self.law_q, self.index, self.memory, float(t),
            FormationStates.of(states).array, np.asarray(thrust_vectors, dtype=float),
            c.constants, c.mixer.rows)
        return ControlOutput(speeds, saturated, setpoint, thrust), errors, rates
