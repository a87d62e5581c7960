"""Run statistics: one definition of each figure a run reports (pure numpy, no ROS).

The simulator (node or headless), the controller runtime, `run`, `run --headless`, `sweep` and
the reproduction report all read these definitions, so a figure means the same wherever it
is printed. World frame `world` (z up), SI units.

- tracking error: |r_ref(t) - r_1(t)| of the leader [m] (max and rms over the ticks);
- formation error: the virtual-constraint residual g_vc of a follower (seed Eq. 3.7-3.8) [m]
  (max |component| and mean Euclidean norm over the ticks);
- saturation: time a UAV spent with any rotor at a speed limit [s];
- tension: the cable tensions T_i = 2 l_i lambda_i [N] (min and max over cables and ticks);
- payload swing: the horizontal distance of the payload from its static-equilibrium place
  under the UAVs at the same tick [m] (`payload_swing`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import combinations

import numpy as np
from numpy.typing import ArrayLike

# How far outside a ball a candidate may lie and still count as inside it [m].
_FEASIBILITY = 1e-9
# How many of the most restrictive cables start the active-set search (see
# `equilibrium_payload_position`).
_WORKING_SET = 6


Point = tuple[float, float, float]


def _sphere_pair_lowest(c1: Point, r1: float, c2: Point, r2: float) -> Point | None:
    """Lowest point of the circle where the spheres (c1, r1) and (c2, r2) meet, or None
    (plain floats: the payload-swing statistic runs it for every pair of its working set)."""
    (x1, y1, z1), (x2, y2, z2) = c1, c2
    ax, ay, az = x2 - x1, y2 - y1, z2 - z1
    d = math.sqrt(ax * ax + ay * ay + az * az)
    if d < 1e-12 or d > r1 + r2 or d < abs(r1 - r2):
        return None
    ax, ay, az = ax / d, ay / d, az / d
    a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    radius = math.sqrt(max(r1 * r1 - a * a, 0.0))
    # -e_z without its part along the axis
    dx, dy, dz = ax * az, ay * az, -1.0 + az * az
    norm = math.sqrt(dx * dx + dy * dy + dz * dz)
    if norm < 1e-12:                                            # vertical axis: any point
        dx, dy, dz = 0.0, az, -ay                               # axis x e_x
        norm = math.sqrt(dy * dy + dz * dz)
    k = radius / norm
    return (x1 + a * ax + k * dx, y1 + a * ay + k * dy, z1 + a * az + k * dz)


def _sphere_triple_lowest(c1: Point, r1: float, c2: Point, r2: float, c3: Point,
                          r3: float) -> Point | None:
    """The lower of the (at most two) points where three spheres meet, or None (plain
    floats, as `_sphere_pair_lowest`)."""
    (x1, y1, z1), (x2, y2, z2), (x3, y3, z3) = c1, c2, c3
    ex, ey_, ez_ = x2 - x1, y2 - y1, z2 - z1
    d = math.sqrt(ex * ex + ey_ * ey_ + ez_ * ez_)
    if d < 1e-12:
        return None
    ex, ey_, ez_ = ex / d, ey_ / d, ez_ / d                     # e_x, the unit axis 1 -> 2
    wx, wy, wz = x3 - x1, y3 - y1, z3 - z1
    i = ex * wx + ey_ * wy + ez_ * wz
    fx, fy, fz = wx - i * ex, wy - i * ey_, wz - i * ez_        # e_y before its norm
    j = math.sqrt(fx * fx + fy * fy + fz * fz)
    if j < 1e-12:
        return None
    fx, fy, fz = fx / j, fy / j, fz / j
    gx, gy, gz = ey_ * fz - ez_ * fy, ez_ * fx - ex * fz, ex * fy - ey_ * fx  # e_z = e_x x e_y
    x = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    y = (r1 * r1 - r3 * r3 + i * i + j * j) / (2.0 * j) - i * x / j
    z_sq = r1 * r1 - x * x - y * y
    if z_sq < 0.0:
        return None
    bx, by, bz = x1 + x * ex + y * fx, y1 + x * ey_ + y * fy, z1 + x * ez_ + y * fz
    z = math.sqrt(z_sq)
    first = (bx + z * gx, by + z * gy, bz + z * gz)
    second = (bx - z * gx, by - z * gy, bz - z * gz)
    return first if first[2] <= second[2] else second


def _lowest_of_two(uavs: list[list[float]], lengths: list[float]) -> list[float] | None:
    """`equilibrium_payload_position` for one or two UAVs in plain floats (the per-tick path
    of the simulator's statistics)."""
    (x1, y1, z1), l1 = uavs[0], lengths[0]
    if len(uavs) == 1:
        return [x1, y1, z1 - l1]
    (x2, y2, z2), l2 = uavs[1], lengths[1]
    dx, dy, dz = x2 - x1, y2 - y1, z2 - z1
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    # a ball's bottom inside the other ball: that cable alone holds the payload
    if dx * dx + dy * dy + (dz + l1) ** 2 <= (l2 * (1.0 + _FEASIBILITY)) ** 2:
        return [x1, y1, z1 - l1]
    if dx * dx + dy * dy + (dz - l2) ** 2 <= (l1 * (1.0 + _FEASIBILITY)) ** 2:
        return [x2, y2, z2 - l2]
    if d < 1e-12 or d > l1 + l2:
        return None
    # lowest point of the circle where the spheres meet (as _sphere_pair_lowest)
    ax, ay, az = dx / d, dy / d, dz / d
    a = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d)
    radius = math.sqrt(max(l1 * l1 - a * a, 0.0))
    wx, wy, wz = az * ax, az * ay, az * az - 1.0                # -e_z less its axis part
    norm = math.sqrt(wx * wx + wy * wy + wz * wz)
    if norm < 1e-12:
        return None
    k = radius / norm
    return [x1 + a * ax + k * wx, y1 + a * ay + k * wy, z1 + a * az + k * wz]


def _lowest_in(uavs: np.ndarray, lengths: np.ndarray, members: list[int]) -> np.ndarray | None:
    """The lowest point inside every ball (r_i, l_i), i in `members`, or None if they do not
    meet. The optimum of `min z` over an intersection of balls lies on at most three spheres,
    so it is the lowest feasible one of: a ball's bottom, a pair's lowest circle point, a
    triple's lower meeting point."""
    centres = [tuple(row) for row in uavs[members].tolist()]
    radii = lengths[members].tolist()
    slack = [_FEASIBILITY * (1.0 + r) for r in radii]
    best: Point | None = None

    def consider(point: Point | None) -> None:
        nonlocal best
        if point is None or (best is not None and point[2] >= best[2]):
            return
        px, py, pz = point
        for (cx, cy, cz), radius, allowed in zip(centres, radii, slack):
            dx, dy, dz = cx - px, cy - py, cz - pz
            if not math.sqrt(dx * dx + dy * dy + dz * dz) - radius <= allowed:  # NaN too
                return
        best = point

    for (cx, cy, cz), radius in zip(centres, radii):
        consider((cx, cy, cz - radius))
    if best is None:
        pairs = list(zip(centres, radii))
        for (c1, r1), (c2, r2) in combinations(pairs, 2):
            consider(_sphere_pair_lowest(c1, r1, c2, r2))
        for (c1, r1), (c2, r2), (c3, r3) in combinations(pairs, 3):
            consider(_sphere_triple_lowest(c1, r1, c2, r2, c3, r3))
    return None if best is None else np.array(best)


def equilibrium_payload_position(uav_positions: ArrayLike, cable_lengths: ArrayLike
                                 ) -> np.ndarray | None:
    """Where the payload would hang at rest under UAVs held at `uav_positions` (n, 3) [m] on
    cables of `cable_lengths` (n,) [m]: the lowest point within reach of every cable (the
    minimum of the potential m_p g z over |r_p - r_i| <= l_i). None when the cables cannot
    all reach one point.

    One UAV: l_1 straight below it. Two: the lowest point of the circle the cables span (or
    below one UAV while the other cable is slack). Three or more: an active-set search that
    starts with the cables whose lowest reach is highest and adds any cable the candidate
    violates. With rigid cables and three or more UAVs the payload is held at this place by
    the constraints themselves, so its swing stays at rounding level.
    """
    uavs = np.asarray(uav_positions, dtype=float).reshape(-1, 3)
    lengths = np.asarray(cable_lengths, dtype=float).reshape(-1)
    if len(uavs) <= 2:
        rest = _lowest_of_two(uavs.tolist(), lengths.tolist())
        return None if rest is None else np.array(rest)
    order = np.argsort(-(uavs[:, 2] - lengths), kind='stable')
    members = sorted(order[:_WORKING_SET].tolist())
    while True:
        point = _lowest_in(uavs, lengths, members)
        if point is None:
            return None
        gaps = np.linalg.norm(uavs - point, axis=1) - lengths
        gaps[members] = -np.inf
        worst = int(np.argmax(gaps))
        if gaps[worst] <= _FEASIBILITY * (1.0 + lengths[worst]):
            return point
        members = sorted(members + [worst])


def payload_swing_at(uav_positions: ArrayLike, payload_position: ArrayLike,
                     cable_lengths: ArrayLike) -> float:
    """`payload_swing` at one instant: uav_positions (n, 3), payload_position (3,) [m]."""
    rest = equilibrium_payload_position(uav_positions, cable_lengths)
    if rest is None:
        return math.nan
    return math.hypot(float(payload_position[0]) - rest[0],
                      float(payload_position[1]) - rest[1])


def payload_swing(uav_positions: ArrayLike, payload_position: ArrayLike,
                  cable_lengths: ArrayLike) -> np.ndarray:
    """Payload swing [m]: the horizontal distance of the payload from its static-equilibrium
    place under the UAVs (`equilibrium_payload_position`) at the same instant.

    uav_positions (..., n, 3), payload_position (..., 3), world [m]; cable_lengths (n,) [m].
    Returns shape (...) (NaN where the cables cannot meet).
    """
    uavs = np.asarray(uav_positions, dtype=float)
    payload = np.asarray(payload_position, dtype=float)
    lead = payload.shape[:-1]
    uavs = uavs.reshape(-1, *uavs.shape[-2:])
    flat = payload.reshape(-1, 3)
    out = np.empty(len(flat))
    lengths = np.asarray(cable_lengths, dtype=float)
    for k, (u, p) in enumerate(zip(uavs, flat)):
        out[k] = payload_swing_at(u, p, lengths)
    return out.reshape(lead)


@dataclass
class PeakRms:
    """Max and root mean square of a non-negative signal sampled once per tick."""
    max: float = 0.0
    sum_sq: float = 0.0
    samples: int = 0

    def add(self, value: float) -> None:
        if value > self.max:
            self.max = value
        self.sum_sq += value * value
        self.samples += 1

    @property
    def rms(self) -> float:
        return math.sqrt(self.sum_sq / self.samples) if self.samples else 0.0


@dataclass
class TrackingStatistics:
    """The leader's tracking error |r_ref - r_1| [m]."""
    error: PeakRms = field(default_factory=PeakRms)

    def add(self, reference_position: np.ndarray, position: np.ndarray) -> None:
        dx, dy, dz = (np.asarray(reference_position, float)
                      - np.asarray(position, float)).tolist()
        self.error.add(math.sqrt(dx * dx + dy * dy + dz * dz))  # in floats: once a tick

    def as_dict(self) -> dict:
        return {'max_tracking_error': self.error.max, 'rms_tracking_error': self.error.rms,
                'answered_states': self.error.samples}


@dataclass
class FormationErrorStatistics:
    """A follower's virtual-constraint residual g_vc [m] (its rows, seed Eq. 3.7-3.8)."""
    max_abs: float = 0.0
    norm_sum: float = 0.0
    samples: int = 0

    def add(self, residual: np.ndarray) -> None:
        rows = np.asarray(residual, dtype=float).ravel().tolist()  # in floats: once a tick
        if rows:
            self.max_abs = max(self.max_abs, max(abs(v) for v in rows))
            self.norm_sum += math.sqrt(sum(v * v for v in rows))
        self.samples += 1

    def as_dict(self) -> dict:
        return {'max_abs_formation_error': self.max_abs,
                'mean_formation_error_norm': self.norm_sum / max(self.samples, 1),
                'answered_states': self.samples}


@dataclass
class RunStatistics:
    """The simulator's figures of a run, accumulated tick by tick."""
    n_uavs: int
    max_abs_constraint: float = 0.0        # max_i,t |g_i| [m^2]
    max_abs_constraint_rate: float = 0.0   # max_i,t |g_i_dot| [m^2/s]
    max_rotor_speed: list = field(default_factory=list)   # per UAV [rad/s]
    saturated_time: list = field(default_factory=list)    # per UAV [s]
    min_tension: float = math.inf          # [N]
    max_tension: float = -math.inf         # [N]
    simulated_time: float = 0.0            # [s]
    max_gust_speed: float = 0.0            # peak gust speed met by the payload [m/s]
    slack_time: list = field(default_factory=list)        # per cable, time slack [s]
    swing: PeakRms = field(default_factory=PeakRms)      # payload swing [m]

    def __post_init__(self) -> None:
        self.max_rotor_speed = [0.0] * self.n_uavs
        self.saturated_time = [0.0] * self.n_uavs
        self.slack_time = [0.0] * self.n_uavs

    def add_slack(self, taut, period: float) -> None:
        """A control period [s] ending with these cables taut (cable_model: slack)."""
        for i, is_taut in enumerate(taut):
            if not is_taut:
                self.slack_time[i] += period

    def add_commands(self, peak_speeds, saturated, period: float) -> None:
        """One control period [s] of commands: each UAV's peak rotor speed [rad/s] and its
        saturation flags."""
        for i, (peak, flags) in enumerate(zip(peak_speeds, saturated)):
            if peak > self.max_rotor_speed[i]:
                self.max_rotor_speed[i] = float(peak)
            if any(flags):
                self.saturated_time[i] += period

    def add_tensions(self, tension) -> None:
        self.min_tension = min(self.min_tension, float(min(tension)))
        self.max_tension = max(self.max_tension, float(max(tension)))

    def add_constraints(self, abs_g: float, abs_g_dot: float) -> None:
        self.max_abs_constraint = max(self.max_abs_constraint, abs_g)
        self.max_abs_constraint_rate = max(self.max_abs_constraint_rate, abs_g_dot)

    def as_dict(self) -> dict:
        out = {k: v for k, v in self.__dict__.items() if k != 'swing'}
        out['max_payload_swing'] = self.swing.max
        out['rms_payload_swing'] = self.swing.rms
        return out


def summary_row(summary: dict) -> dict:
    """One flat row of a run's summary ({'sim': ..., 'leader': ..., 'follower2': ...}, as
    `run`, `run --headless` and the headless runner leave it): the columns of `sweep`.
    Figures a run does not have (no leader tracking, no followers) are None."""
    sim = summary.get('sim', {})
    followers = [v for k, v in summary.items() if k.startswith('follower')]
    leader = summary.get('leader', {})
    tracked = leader.get('answered_states', 0) > 0

    def finite(value: float | None) -> float | None:
        return value if value is not None and math.isfinite(value) else None

    return {
        'simulated_time': sim.get('simulated_time'),
        'max_abs_g': sim.get('max_abs_constraint'),
        'max_abs_g_dot': sim.get('max_abs_constraint_rate'),
        'max_rotor_speed': max(sim['max_rotor_speed']) if sim.get('max_rotor_speed') else None,
        'saturated_time': sum(sim['saturated_time']) if sim.get('saturated_time') else None,
        'min_tension': finite(sim.get('min_tension')),
        'max_tension': finite(sim.get('max_tension')),
        'payload_swing_max': sim.get('max_payload_swing'),
        'payload_swing_rms': sim.get('rms_payload_swing'),
        'max_gust_speed': sim.get('max_gust_speed'),
        'slack_time': sum(sim['slack_time']) if sim.get('slack_time') else None,
        'tracking_error_max': leader.get('max_tracking_error') if tracked else None,
        'tracking_error_rms': leader.get('rms_tracking_error') if tracked else None,
        'formation_error_max': (max(f['max_abs_formation_error'] for f in followers)
                                if followers else None),
        'formation_error_mean': (sum(f['mean_formation_error_norm'] for f in followers)
                                 / len(followers) if followers else None),
    }
