"""What `/visualization/markers` draws, as plain numbers (no rclpy, no message types).

`FormationScene(scenario)` holds one `MarkerSpec` per marker of the scenario's MarkerArray, in
the array's order; `update(...)` writes one tick's poses, cable points and colours into them.
multilift_sim.ros.markers fills rclpy Marker messages from these specs and multilift_sim.wire.cdr
packs CDR from them, so the node's array and the headless bag's hold the same values. The
markers (world frame, z up, metres):

- ns `uav`, id i (1 = leader), CYLINDER: the UAV body, a disc BODY_DIAMETER_ARMS arm lengths
  across and BODY_HEIGHT thick, at the UAV's pose;
- ns `uav_heading`, id i, ARROW: the body x axis (front), 2 arm lengths long;
- ns `cable`, id i, LINE_LIST of CABLE_SEGMENTS segments: UAV i's centre of mass to the
  payload, coloured by tension; solid while taut, dashed while slack (`cable_model: slack`);
  a heavy cable (`cable_model: chain`) as its N links, UAV -> its inner nodes -> the payload;
- ns `payload`, id 0, SPHERE: the payload, PAYLOAD_DIAMETER across; a rigid body
  (docs/rigid_payload.md) its shape at its pose: a CUBE of its size (box) or a CYLINDER of
  its length and radius, laid along its x axis (cylinder), and the cables end at its attach
  points;
- ns `mission_path`, id 0, LINE_STRIP: the leader's reference path through the corners of
  `scenario.mission` (start, then the end of each segment);
- ns `gust_zone`, id k (from 0), CYLINDER: where gust k blows, radius H (its gradient distance)
  about its centre, spanning the heights the payload can reach (height does not matter to a
  gust, seed Eq. 2.55), translucent;
- ns `obstacle`, id k (from 0): `world.obstacles[k]` as its type draws it (`outline`: a CUBE,
  CYLINDER or SPHERE of its full size at its centre, turned by its yaw), translucent
  (docs/obstacles.md).

Cable colour: tension T [N] against the static share of the payload weight per cable,
T_ref = m_p g / n: blue at T <= 0+ (slack), green at T_ref, red at 2 T_ref and above; a negative
tension (the rigid rod in compression, which the model reports) is magenta.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

from multilift_sim.wire.msgvalues import quaternion
from multilift_sim.scenario import Scenario

PAYLOAD_DIAMETER = 0.3  # [m] drawn size of the payload (the model's payload is a point mass)
BODY_DIAMETER_ARMS = 2.6  # UAV disc diameter in arm lengths
BODY_HEIGHT = 0.06  # [m] UAV disc thickness
CABLE_WIDTH = 0.03  # [m] line width of a cable
CABLE_SEGMENTS = 8  # a cable is drawn as this many segments: end to end (taut) or half (slack)
PATH_WIDTH = 0.05  # [m] line width of the mission path
GUST_ALPHA = 0.15  # opacity of a gust zone
GUST_MARGIN = 1.0  # [m] a gust zone reaches this far above and below the payload's heights
OBSTACLE_ALPHA = 0.6  # opacity of an obstacle

# visualization_msgs/Marker types and action used here
ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST = 0, 1, 2, 3, 4, 5
ADD = 0

_LEADER = (0.95, 0.55, 0.05)  # orange
_FOLLOWER = (0.15, 0.45, 0.95)  # blue
_PAYLOAD = (0.35, 0.35, 0.35)
_PATH = (0.1, 0.7, 0.2)
_GUST = (0.55, 0.8, 1.0)
_COMPRESSION = (0.9, 0.1, 0.9)
_OBSTACLE = (0.55, 0.45, 0.35)  # brown-grey


def tension_color(tension: float, reference: float) -> tuple[float, float, float]:
    """RGB of a cable under `tension` [N] on the blue-green-red scale of T / `reference` [N].

    0 (or slack) is blue, `reference` green, 2 `reference` or more red; negative (compression)
    is magenta. `reference` must be positive.
    """
    if not math.isfinite(tension):
        return _COMPRESSION
    if tension < 0.0:
        return _COMPRESSION
    s = min(tension / (2.0 * reference), 1.0)
    if s <= 0.5:  # blue -> green
        u = s / 0.5
        return (0.0, u, 1.0 - u)
    u = (s - 0.5) / 0.5  # green -> red
    return (u, 1.0 - u, 0.0)


def mission_corners(scenario: Scenario) -> list[tuple[float, float, float]]:
    """The leader reference's corners, world [m]: the start, then the end of every segment; a
    polynomial mission's points (multilift_sim.missions)."""
    if scenario.mission.points:
        return [tuple(p) for p in scenario.mission.points]
    corners = [tuple(float(c) for c in scenario.mission.start)]
    previous_end = 0.0
    for segment in scenario.mission.segments:
        duration = segment.end_time - previous_end
        previous_end = segment.end_time
        last = corners[-1]
        corners.append(tuple(last[k] + segment.velocity[k] * duration for k in range(3)))
    return corners


def _rotate(q: Sequence[float], v: Sequence[float]) -> tuple[float, float, float]:
    """v rotated by the unit quaternion q = (x, y, z, w): R(q) v."""
    x, y, z, w = q
    # v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    cx, cy, cz = y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]
    return (v[0] + 2.0 * (w * cx + y * cz - z * cy),
            v[1] + 2.0 * (w * cy + z * cx - x * cz),
            v[2] + 2.0 * (w * cz + x * cy - y * cx))


def _compose(a: Sequence[float], b: Sequence[float]) -> list[float]:
    """The quaternion product a b, (x, y, z, w) each: rotate by b, then by a."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


# a marker CYLINDER's axis is its z: laid along the payload's x by a quarter turn about y
_ALONG_X = (0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5))


@dataclass
class MarkerSpec:
    """The values of one visualization_msgs/Marker (every field not here is zero or empty)."""
    ns: str
    id: int
    type: int
    position: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    orientation: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])
    scale: tuple[float, float, float] = (0.0, 0.0, 0.0)
    color: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])  # RGBA
    points: list[tuple[float, float, float]] = field(default_factory=list)
    action: int = ADD


def _rgba(rgb: Sequence[float], alpha: float = 1.0) -> list[float]:
    return [float(rgb[0]), float(rgb[1]), float(rgb[2]), float(alpha)]


def _static_specs(scenario: Scenario) -> list[MarkerSpec]:
    corners = mission_corners(scenario)
    specs = [MarkerSpec('mission_path', 0, LINE_STRIP, scale=(PATH_WIDTH, 0.0, 0.0),
                        color=_rgba(_PATH, 0.8),
                        points=[tuple(float(c) for c in corner) for corner in corners])]
    heights = [c[2] for c in corners] + [u.position[2] for u in scenario.uavs]
    longest = max(u.cable_length for u in scenario.uavs)
    bottom = min(heights) - longest - GUST_MARGIN
    top = max(heights) + GUST_MARGIN
    for k, gust in enumerate(scenario.gusts):
        diameter = float(2.0 * gust.gradient_distance)
        specs.append(MarkerSpec(
            'gust_zone', k, CYLINDER,
            position=[float(gust.center[0]), float(gust.center[1]), float(0.5 * (bottom + top))],
            scale=(diameter, diameter, float(top - bottom)), color=_rgba(_GUST, GUST_ALPHA)))
    return specs + obstacle_specs(scenario)


def obstacle_specs(scenario: Scenario) -> list[MarkerSpec]:
    """The `world.obstacles` as markers, ns `obstacle`, id k: each its type's `outline` (none
    without a `world:` section)."""
    if scenario.world is None:
        return []
    from multilift_sim.obstacles import OBSTACLE_TYPES
    types = {'cube': CUBE, 'cylinder': CYLINDER, 'sphere': SPHERE}
    specs = []
    for k, obstacle in enumerate(scenario.world.obstacles):
        shape, size = OBSTACLE_TYPES[obstacle.type].outline(obstacle.half)
        half_yaw = 0.5 * obstacle.yaw
        specs.append(MarkerSpec(
            'obstacle', k, types[shape], position=[float(c) for c in obstacle.center],
            orientation=[0.0, 0.0, math.sin(half_yaw), math.cos(half_yaw)],
            scale=tuple(float(s) for s in size), color=_rgba(_OBSTACLE, OBSTACLE_ALPHA)))
    return specs


def _cable_points(start: tuple[float, float, float], end: tuple[float, float, float],
                  taut: bool) -> list[tuple[float, float, float]]:
    """The LINE_LIST points of a cable from `start` to `end`: CABLE_SEGMENTS segments end to
    end when taut, each half its length (a dashed line) when slack."""
    fill = 1.0 if taut else 0.5
    (x, y, z), (dx, dy, dz) = start, (end[0] - start[0], end[1] - start[1], end[2] - start[2])
    points = []
    for k in range(CABLE_SEGMENTS):
        for s in (k / CABLE_SEGMENTS, (k + fill) / CABLE_SEGMENTS):
            points.append((x + s * dx, y + s * dy, z + s * dz))
    return points


def _chain_points(start: tuple[float, float, float], nodes: Sequence[Sequence[float]],
                  end: tuple[float, float, float]) -> list[tuple[float, float, float]]:
    """The LINE_LIST points of a heavy cable: its N links, from `start` through its inner
    `nodes` (N - 1, 3) [m] to `end`."""
    path = [start] + [(float(p[0]), float(p[1]), float(p[2])) for p in nodes] + [end]
    return [point for a, b in zip(path[:-1], path[1:]) for point in (a, b)]


class FormationScene:
    """The marker specs of one scenario, in MarkerArray order: per UAV body, heading, cable;
    then the payload, the mission path and the gust zones. `update` rewrites the moving parts."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        weight = scenario.payload.mass * scenario.simulation.gravity  # [N]
        self.reference_tension = weight / scenario.n_uavs  # [N]
        self.bodies, self.headings, self.cables = [], [], []
        for i, uav in enumerate(scenario.uavs):
            arm = float(uav.vehicle.arm_length)  # [m]
            rgb = _LEADER if i == 0 else _FOLLOWER
            self.bodies.append(MarkerSpec('uav', i + 1, CYLINDER,
                                          scale=(BODY_DIAMETER_ARMS * arm,
                                                 BODY_DIAMETER_ARMS * arm, BODY_HEIGHT),
                                          color=_rgba(rgb)))
            self.headings.append(MarkerSpec('uav_heading', i + 1, ARROW,
                                            scale=(2.0 * arm, 0.25 * arm, 0.25 * arm),
                                            color=_rgba(rgb)))
            links = scenario.cable['links'] if scenario.cable_model == 'chain' else 0
            self.cables.append(MarkerSpec(
                'cable', i + 1, LINE_LIST, scale=(CABLE_WIDTH, 0.0, 0.0),
                color=_rgba(tension_color(0.0, self.reference_tension)),
                points=[(0.0, 0.0, 0.0)] * (2 * (links or CABLE_SEGMENTS))))
        payload = scenario.payload
        self.attach_points = payload.attach_points  # a rigid body's, payload frame [m]
        # where each cable holds its UAV, body FLU [m] (None: every cable at its UAV's centre)
        self.uav_attach = ([tuple(u.attach_point) for u in scenario.uavs]
                           if any(any(u.attach_point) for u in scenario.uavs) else None)
        if payload.type == 'rigid_body' and payload.shape == 'box':
            self.payload = MarkerSpec('payload', 0, CUBE, scale=tuple(payload.size),
                                      color=_rgba(_PAYLOAD))
        elif payload.type == 'rigid_body':  # a cylinder along its x axis
            length, radius = payload.size
            self.payload = MarkerSpec('payload', 0, CYLINDER,
                                      scale=(2.0 * radius, 2.0 * radius, length),
                                      color=_rgba(_PAYLOAD))
        else:
            self.payload = MarkerSpec('payload', 0, SPHERE, scale=(PAYLOAD_DIAMETER,) * 3,
                                      color=_rgba(_PAYLOAD))
        self.specs = ([m for trio in zip(self.bodies, self.headings, self.cables)
                       for m in trio] + [self.payload] + _static_specs(scenario))

    @property
    def n_uavs(self) -> int:
        return len(self.bodies)

    def update(self, uav_positions: Sequence[Sequence[float]],
               uav_euler: Sequence[Sequence[float]], payload_position: Sequence[float],
               tensions: Sequence[float], taut: Sequence[bool] | None = None,
               payload_orientation: Sequence[float] | None = None,
               chain_points: Sequence | None = None) -> list[MarkerSpec]:
        """Write one tick's formation into the specs (UAV positions [m] and ZYX Euler angles
        [rad], payload position [m], cable tensions [N], which cables are taut: None for
        all; a rigid payload's orientation (x, y, z, w); heavy cables' inner nodes (n, N - 1,
        3) [m], world, or None); returns `specs`."""
        n = self.n_uavs
        if len(uav_positions) != n or len(tensions) != n:
            raise ValueError(f'formation_markers: scenario {self.scenario.name} has {n} UAVs, '
                             f'got a snapshot of {len(uav_positions)} and {len(tensions)} '
                             'tensions')
        payload = (float(payload_position[0]), float(payload_position[1]),
                   float(payload_position[2]))
        self.payload.position[:] = payload
        ends = [payload] * n  # where each cable holds the payload, world [m]
        if self.attach_points is not None:
            q = (0.0, 0.0, 0.0, 1.0) if payload_orientation is None else tuple(
                float(v) for v in payload_orientation)
            self.payload.orientation[:] = (_compose(q, _ALONG_X)
                                           if self.payload.type == CYLINDER else list(q))
            ends = [tuple(p + r for p, r in zip(payload, _rotate(q, b)))
                    for b in self.attach_points]
        if taut is None:
            taut = [True] * n
        for i, (position, euler, tension, is_taut, end, body, heading, cable) in enumerate(zip(
                uav_positions, uav_euler, tensions, taut, ends, self.bodies, self.headings,
                self.cables)):
            xyz = (float(position[0]), float(position[1]), float(position[2]))
            body.position[:] = xyz
            body.orientation[:] = quaternion(euler)
            heading.position[:] = xyz
            heading.orientation[:] = body.orientation
            top = xyz if self.uav_attach is None else tuple(  # the cable's hold on the UAV
                p + r for p, r in zip(xyz, _rotate(body.orientation, self.uav_attach[i])))
            points = (_cable_points(top, end, bool(is_taut)) if chain_points is None
                      else _chain_points(top, chain_points[i], end))
            if len(points) != len(cable.points):  # a chain's markers need its nodes
                raise ValueError(f'formation_markers: cable {i + 1} has {len(cable.points)} '
                                 f'points, got {len(points)}')
            cable.points[:] = points
            cable.color[:3] = tension_color(float(tension), self.reference_tension)
        return self.specs
