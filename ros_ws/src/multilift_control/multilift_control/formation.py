"""Formation control by virtual constraints (seed §3.2, Eq. 3.1-3.13, Table 3.1).

The followers keep the formation geometry by producing, with their thrust, the constraint force
that would hold the UAVs on the hypersurface g_vc(r_f) = 0 (Eq. 3.5). Everything is in the world
frame (z up) of docs/conventions.md; the seed writes its equations in a z-down frame, so its
"V" offsets v_1i go through `multilift_sim.frames` (`formation_geometry.v_offset`).
UAV 1 (index 0) is the leader. The arithmetic is the laws' (`multilift_control.laws`:
`constraints` the rows, `follower` the forces and a follower's tick); the classes here build
their arrays once and call them, compiled or not as MULTILIFT_KERNEL says (`laws.runnable`).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from multilift_control import laws
from multilift_control.cascade import (CascadeController, ControlOutput, FormationStates,
                                       UavState)
from multilift_control.laws import constraints as rows_laws
from multilift_control.laws.follower import follower_force, follower_tick, formation_terms
from multilift_control.laws.follower import virtual_forces as virtual_forces_law
from multilift_control.laws.layout import (FOLLOWER_ALTITUDE_OFFSET, FOLLOWER_BETA_SQ,
                                           FOLLOWER_COMMANDED, FOLLOWER_FREE_MODE_GAIN,
                                           FOLLOWER_GRAVITY, FOLLOWER_HOVER_MASS,
                                           FOLLOWER_INTEGRAL, FOLLOWER_INTEGRAL_LIMIT,
                                           FOLLOWER_KD_Z, FOLLOWER_KI_Z, FOLLOWER_KP_Z,
                                           FOLLOWER_LIFT, FOLLOWER_LINEAR,
                                           FOLLOWER_MEMORY_SIZE, FOLLOWER_SIZE,
                                           FOLLOWER_TWO_ALPHA, FOLLOWER_YAW, ROW_AXIS,
                                           ROW_DISTANCE, ROW_FIRST, ROW_SECOND, ROW_SIZE)
from multilift_sim import formation_geometry  # start places and the V offsets v_1i, world
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.scenario import ControlConfig

GEOMETRIES = formation_geometry.FORMATION_GEOMETRIES  # seed Table 3.1: the one registry

OWN_THRUST = ('commanded', 'measured')  # where a follower's u_i comes from (FormationFollower)
_COND_LIMIT = 1e10  # cond(J M^-1 J^T) above which the linear law takes its pseudo-inverse


@dataclass(frozen=True)
class FormationGeometry:
    """A formation geometry of seed Table 3.1 for n UAVs, world frame.

    kind: one of GEOMETRIES. offsets (linear only): desired r_1 - r_i per follower i = 2..n,
    world [m] (d_x, d_y, d_z of Eq. 3.2-3.4). distance (distance, v, circle): d [m]; for the
    circle the side of the regular polygon. half_angle (v only): gamma [rad], the vertex angle
    is 2 gamma. Fields a kind does not use must keep their defaults.
    """
    kind: str
    n: int
    offsets: tuple[tuple[float, float, float], ...] = ()
    distance: float = 0.0
    half_angle: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in GEOMETRIES:
            raise ValueError(f'FormationGeometry.kind must be one of {GEOMETRIES}, '
                             f'got {self.kind!r}')
        if isinstance(self.n, bool) or not isinstance(self.n, int) or self.n < 2:
            raise ValueError(f'FormationGeometry.n must be an integer >= 2, got {self.n!r}')
        if self.kind == 'circle' and self.n < 3:
            raise ValueError(f'FormationGeometry.n must be >= 3 for a circle, got {self.n}')
        if self.kind == 'linear':
            self._check_offsets()
        elif len(self.offsets) != 0:
            raise ValueError(f'FormationGeometry.offsets is only for the linear geometry, '
                             f'not {self.kind!r}')
        if self.kind == 'linear':
            if self.distance != 0.0:
                raise ValueError('FormationGeometry.distance is unused by the linear geometry '
                                 f'(give offsets), got {self.distance!r}')
        elif not (math.isfinite(self.distance) and self.distance > 0):
            raise ValueError(f'FormationGeometry.distance must be finite and > 0 [m] for '
                             f'{self.kind!r}, got {self.distance!r}')
        if self.kind == 'v':
            if not (math.isfinite(self.half_angle) and 0 < self.half_angle < math.pi / 2):
                raise ValueError(f'FormationGeometry.half_angle must be within (0, pi/2) rad '
                                 f'for a V, got {self.half_angle!r}')
        elif self.half_angle != 0.0:
            raise ValueError(f'FormationGeometry.half_angle is only for the V, not '
                             f'{self.kind!r}, got {self.half_angle!r}')

    def _check_offsets(self) -> None:
        if len(self.offsets) != self.n - 1:
            raise ValueError(f'FormationGeometry.offsets must give one (dx, dy, dz) per follower '
                             f'({self.n - 1}), got {len(self.offsets)}')
        offsets = []
        for k, offset in enumerate(self.offsets):
            values = tuple(float(x) for x in offset)
            if len(values) != 3 or not all(math.isfinite(x) for x in values):
                raise ValueError(f'FormationGeometry.offsets[{k}] (UAV {k + 2}) must be three '
                                 f'finite numbers [m], got {offset!r}')
            offsets.append(values)
        places = np.vstack([np.zeros(3), -np.array(offsets)])
        for a in range(self.n):
            for b in range(a + 1, self.n):
                if np.linalg.norm(places[a] - places[b]) < 1e-9:
                    raise ValueError(f'FormationGeometry.offsets put UAV {a + 1} and UAV {b + 1} '
                                     'at the same place')
        object.__setattr__(self, 'offsets', tuple(offsets))

    @classmethod
    def from_config(cls, config, n: int) -> FormationGeometry:
        """The geometry of a scenario's `FormationConfig` (geometry, offsets, distance,
        half_angle) for n UAVs."""
        return cls(kind=config.geometry, n=n, offsets=tuple(config.offsets),
                   distance=config.distance, half_angle=config.half_angle)


class VirtualConstraints:
    """The virtual constraint vector g_vc(r_f) of seed Eq. 3.5 for a geometry, world frame.

    Rows, in order (UAV 1 = index 0 the leader, followers i = 2..n):
    - linear: for each follower the three rows (r_1 - r_i)_axis - offset_axis [m]
      (Eq. 3.2-3.4, Table 3.1 row 1);
    - v: the linear rows with offset = -v_1i, i.e. g_vc = J_vc r_f + v_c (Eq. 3.6-3.7);
    - distance: for each follower |r_1 - r_i|^2 - d^2 [m^2] (Eq. 3.1; Table 3.1 prints "- d",
      read as d^2, a slip);
    - circle: the n UAVs on a regular polygon of side d with the leader a vertex (radius
      R = d / (2 sin(pi/n))): first |r_1 - r_j|^2 - chord_j^2 for every follower j, with
      chord_j = 2 R sin(pi k/n), k = min(j-1, n-j+1) steps round the polygon, then
      |r_j - r_j+1|^2 - d^2 for consecutive followers [m^2]. With the leader's two edges this is
      every side of the polygon plus the leader's diagonals (a rigid fan in the plane: 2n - 3
      rows). For n = 3 these are Table 3.1's three rows, in its order (with d^2).
    Positions r are arrays (n, 3) [m], velocities v (n, 3) [m/s], world frame; the flattened
    formation vector r_f is r.reshape(3n).
    """

    def __init__(self, geometry: FormationGeometry):
        self.geometry = geometry
        self.n = geometry.n
        self.linear = geometry.kind in ('linear', 'v')
        pairs: list[tuple[int, int]] = []
        axes: list[int] = []
        targets: list[float] = []  # linear: offset [m]; distance: length [m]
        if self.linear:
            for j, offset in enumerate(self.offsets(), start=1):
                for axis in range(3):
                    pairs.append((0, j))
                    axes.append(axis)
                    targets.append(float(offset[axis]))
        elif geometry.kind == 'distance':
            for j in range(1, self.n):
                pairs.append((0, j))
                targets.append(geometry.distance)
        else:  # circle
            radius = geometry.distance / (2 * math.sin(math.pi / self.n))
            for j in range(1, self.n):
                steps = min(j, self.n - j)
                pairs.append((0, j))
                targets.append(2 * radius * math.sin(math.pi * steps / self.n))
            for j in range(1, self.n - 1):
                pairs.append((j, j + 1))
                targets.append(geometry.distance)
        self.pairs = np.array(pairs, dtype=int).reshape(-1, 2)
        self.axes = np.array(axes, dtype=int)
        self.targets = np.array(targets, dtype=float)
        self.m = len(self.pairs)
        # the laws' rows (ROW_* slots): a distance row's axis is ROW_DISTANCE
        self.rows = np.empty((self.m, ROW_SIZE), dtype=np.int64)
        self.rows[:, ROW_FIRST] = self.pairs[:, 0]
        self.rows[:, ROW_SECOND] = self.pairs[:, 1]
        self.rows[:, ROW_AXIS] = self.axes if self.linear else ROW_DISTANCE
        for array in (self.pairs, self.axes, self.targets, self.rows):
            array.flags.writeable = False
        self._residual = laws.runnable(rows_laws.residual)
        self._jacobian = laws.runnable(rows_laws.jacobian)
        self._rates = laws.runnable(rows_laws.rates)
        self._jacobian_rate_product = laws.runnable(rows_laws.jacobian_rate_product)
        self._free_follower_motions = laws.runnable(rows_laws.free_follower_motions)
        self._rows_of = laws.runnable(rows_laws.rows_of)

    def offsets(self) -> np.ndarray:
        """(n-1, 3) desired r_1 - r_i per follower [m], world (linear and v only)."""
        g = self.geometry
        if g.kind == 'linear':
            return np.array(g.offsets, dtype=float).reshape(-1, 3)
        if g.kind == 'v':
            return -np.array([formation_geometry.v_offset(i, g.distance, g.half_angle)
                              for i in range(2, self.n + 1)])
        raise ValueError(f'offsets exist only for linear rows, not for {g.kind!r}')

    @property
    def v_c(self) -> np.ndarray:
        """The constant vector v_c of Eq. 3.6 (g_vc = J_vc r_f + v_c), shape (3(n-1),) [m]."""
        return -self.offsets().reshape(-1)

    def _check(self, r: np.ndarray, name: str = 'r') -> np.ndarray:
        r = np.asarray(r, dtype=float)
        if r.shape != (self.n, 3):
            raise ValueError(f'{name} must have shape ({self.n}, 3), got {r.shape}')
        return r

    def residual(self, r: np.ndarray) -> np.ndarray:
        """g_vc(r) (m,): [m] for linear rows, [m^2] for distance rows."""
        return self._residual(self.rows, self.targets, self._check(r))

    def jacobian(self, r: np.ndarray) -> np.ndarray:
        """J_vc = d g_vc / d r_f, shape (m, 3n); constant (Eq. 3.7) for linear rows."""
        return self._jacobian(self.rows, self._check(r))

    def rate(self, r: np.ndarray, v: np.ndarray) -> np.ndarray:
        """g_vc_dot = J_vc r_f_dot (m,): [m/s] or [m^2/s]."""
        return self._rates(self.rows, self._check(r), self._check(v, 'v'))

    def jacobian_rate_product(self, r: np.ndarray, v: np.ndarray) -> np.ndarray:
        """J_vc_dot r_f_dot (m,): zero for linear rows, 2 |v_i - v_j|^2 for distance rows
        [m^2/s^2]."""
        self._check(r)
        return self._jacobian_rate_product(self.rows, self._check(v, 'v'))

    def rows_of(self, i: int) -> list[int]:
        """Indices of the rows that involve UAV index i (0 = leader)."""
        if not 0 <= i < self.n:
            raise ValueError(f'UAV index {i} outside 0..{self.n - 1}')
        return self._rows_of(self.rows, i).tolist()

    def free_follower_motions(self, r: np.ndarray, tol: float = 1e-9) -> np.ndarray:
        """Orthonormal basis (2(n-1), k) of the followers' horizontal motions that leave every
        row unchanged to first order with the leader held: the null space of J_vc's follower
        x, y columns (stacked x_2, y_2, .., x_n, y_n), singular values up to `tol` times the
        largest counting as zero. Empty (k = 0) for linear rows; for a circle the rotation
        about the leader, for 'distance' each follower's tangent."""
        return self._free_follower_motions(self.rows, self._check(r), float(tol))

    def nominal_positions(self, leader_position: np.ndarray) -> np.ndarray:
        """(n, 3) positions [m], world, satisfying every row, all at the leader's altitude
        (except a linear geometry with d_z offsets, which the rows themselves impose).

        linear, v: r_i = r_1 - offset_i (v: r_1 + v_1i). distance: the followers evenly on the
        rear half-circle of radius d, at angles pi/2 + pi (i-1)/n from +x for i = 2..n (the
        one follower of a twin straight behind). circle: the polygon's centre is R behind the
        leader, follower i at angle 2 pi (i-1)/n round it, counter-clockwise seen from above
        (UAV 2 on the +y side, as the V's UAV 2).
        """
        g = self.geometry
        # the scenario's start places (multilift_sim.formation_geometry), so the rows and the
        # simulator's initial formation cannot disagree
        return formation_geometry.nominal_positions(
            g.kind, self.n, np.asarray(leader_position, dtype=float).reshape(3),
            g.offsets, g.distance, g.half_angle)


def virtual_forces(constraints: VirtualConstraints, r: np.ndarray, v: np.ndarray,
                   thrust_vectors: np.ndarray, masses: np.ndarray, gravity: float,
                   alpha_vc: float, beta_vc: float) -> tuple[np.ndarray, np.ndarray]:
    """Virtual constraint forces u_vf = -J_vc^T Lambda_c (seed Eq. 3.8-3.12), world frame
    (`laws.follower.virtual_forces`, which tells how the print is read).

    r (n, 3) [m], v (n, 3) [m/s], thrust_vectors u_i (n, 3) [N] (the lift R_i e_z u_T,i of each
    UAV), masses m_i (n,) [kg], gravity g [m/s^2], alpha_vc [1/s], beta_vc [1/s].
    Returns (u_vf (n, 3) [N], Lambda (m,) [N/m or N/m^2]).
    """
    masses = np.asarray(masses, dtype=float).reshape(constraints.n)
    return laws.runnable(virtual_forces_law)(
        constraints.rows, constraints.targets, masses, float(gravity), 2.0 * alpha_vc,
        beta_vc ** 2, constraints._check(r), constraints._check(v, 'v'),
        constraints._check(thrust_vectors, 'thrust_vectors'))


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
        if own_thrust not in OWN_THRUST:
            raise ValueError(f'own_thrust must be one of {OWN_THRUST}, got {own_thrust!r}')
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
        self.constants.flags.writeable = False
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
                [u.cable_length for u in scenario.uavs])
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
        jac = c.jacobian(np.zeros((c.n, 3)))
        a_plus = _law_inverse(jac, np.repeat(1.0 / self.masses, 3))
        p = -(jac[:, 3 * self.index:3 * self.index + 3].T @ a_plus)
        q = p @ jac
        for array in (p, q):
            array.flags.writeable = False
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
