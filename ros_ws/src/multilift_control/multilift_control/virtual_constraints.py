"""The formation's virtual constraints (seed §3.2, Eq. 3.1-3.7, Table 3.1): `FormationGeometry`
(a geometry of the registry `multilift_sim.formation_geometry.FORMATION_GEOMETRIES` for n UAVs),
`VirtualConstraints` (its rows g_vc, their Jacobian and rates, the targets) and
`virtual_forces` (Eq. 3.8-3.12). World frame (z up); UAV 1 (index 0) is the leader. The
arithmetic is the laws' (`laws.constraints` the rows, `laws.follower` the forces); these classes
build their arrays once and call them. The follower that keeps them is `formation.py`'s."""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from multilift_control import laws
from multilift_control.laws import constraints as rows_laws
from multilift_control.laws.follower import virtual_forces as virtual_forces_law
from multilift_control.laws.layout import ROW_AXIS, ROW_DISTANCE, ROW_FIRST, ROW_SECOND, ROW_SIZE
from multilift_sim import formation_geometry  # start places and the V offsets v_1i, world
from multilift_sim import kernels
from multilift_sim.registry import one_of

GEOMETRIES = formation_geometry.FORMATION_GEOMETRIES  # seed Table 3.1: the one registry


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
        one_of('FormationGeometry.kind', self.kind, GEOMETRIES)
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
        (self._residual, self._jacobian, self._row_rate, self._jacobian_rate_product,
         self._free_follower_motions) = map(laws.runnable, (
            rows_laws.residual, rows_laws.jacobian, rows_laws.row_rate,
            rows_laws.jacobian_rate_product, rows_laws.free_follower_motions))
        # one-time queries of a formation's set-up (a follower's rows, the linear rows'
        # constant Jacobian): the laws' own source run uncompiled, the same numbers without
        # loading two more compiled functions from numba's cache (about 0.2 s of a process's
        # start; the uncompiled Jacobian of a V of 100 takes 0.6 ms)
        self._rows_of = kernels.uncompiled(rows_laws.rows_of)
        self._setup_jacobian = kernels.uncompiled(rows_laws.jacobian)

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

    @functools.cached_property
    def linear_jacobian(self) -> np.ndarray:
        """J_vc of linear (and V) rows, constant (Eq. 3.7), shape (m, 3n), read-only."""
        if not self.linear:
            raise ValueError(f'the {self.geometry.kind!r} rows are not linear: their J_vc '
                             'depends on r (`jacobian`)')
        jac = self._setup_jacobian(self.rows, np.zeros((self.n, 3)))
        jac.flags.writeable = False
        return jac

    def rate(self, r: np.ndarray, v: np.ndarray) -> np.ndarray:
        """g_vc_dot = J_vc r_f_dot (m,): [m/s] or [m^2/s], row by row as the followers' laws
        take it (`laws.constraints.row_rate`)."""
        r, v = self._check(r), self._check(v, 'v')
        return np.array([self._row_rate(self.rows, r, v, k) for k in range(self.m)])

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
