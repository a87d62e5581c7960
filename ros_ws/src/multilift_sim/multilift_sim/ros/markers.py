"""`/visualization/markers` content: the formation as a visualization_msgs/MarkerArray.

Pure message building (no node, no publisher): `formation_markers(snapshot, tensions, scenario,
stamp)` turns one simulator `Snapshot` into markers in the `world` frame (z up, metres) that RViz
and Foxglove's 3-D panel draw:

- ns `uav`, id i (1 = leader), CYLINDER: the UAV body, a disc BODY_DIAMETER_ARMS arm lengths
  across and BODY_HEIGHT thick, at the UAV's pose;
- ns `uav_heading`, id i, ARROW: the body x axis (front), 2 arm lengths long;
- ns `cable`, id i, LINE_STRIP: UAV i's centre of mass to the payload, coloured by tension;
- ns `payload`, id 0, SPHERE: the payload, PAYLOAD_DIAMETER across;
- ns `mission_path`, id 0, LINE_STRIP: the leader's reference path through the corners of
  `scenario.mission` (start, then the end of each segment);
- ns `gust_zone`, id k (from 0), CYLINDER: where gust k blows, radius H (its gradient distance)
  about its centre, spanning the heights the payload can reach (height does not matter to a
  gust, seed Eq. 2.55), translucent.

Cable colour: tension T [N] against the static share of the payload weight per cable,
T_ref = m_p g / n: blue at T <= 0+ (slack), green at T_ref, red at 2 T_ref and above; a negative
tension (the rigid rod in compression, which the model reports) is magenta.

Cost: making a Marker message in rclpy is what costs (about 60 us each), so a
`FormationMarkers` builder makes its markers once and afterwards only writes poses, points,
colours and stamps into them: 0.04 ms per call for five UAVs (measured; 1.2 ms when made anew).
The array returned is therefore rewritten by the next call for the same scenario: publish (or
serialize) it first. Publish-rate decimation is the caller's business.
"""

from __future__ import annotations

import math
from typing import Sequence

from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from multilift_sim.kinematics import quaternion_from_euler
from multilift_sim.ros.common import WORLD_FRAME, stamp_from_ns
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import Snapshot

PAYLOAD_DIAMETER = 0.3  # [m] drawn size of the payload (the model's payload is a point mass)
BODY_DIAMETER_ARMS = 2.6  # UAV disc diameter in arm lengths
BODY_HEIGHT = 0.06  # [m] UAV disc thickness
CABLE_WIDTH = 0.03  # [m] line width of a cable
PATH_WIDTH = 0.05  # [m] line width of the mission path
GUST_ALPHA = 0.15  # opacity of a gust zone
GUST_MARGIN = 1.0  # [m] a gust zone reaches this far above and below the payload's heights

_LEADER = (0.95, 0.55, 0.05)  # orange
_FOLLOWER = (0.15, 0.45, 0.95)  # blue
_PAYLOAD = (0.35, 0.35, 0.35)
_PATH = (0.1, 0.7, 0.2)
_GUST = (0.55, 0.8, 1.0)
_COMPRESSION = (0.9, 0.1, 0.9)


def _color(rgb: Sequence[float], alpha: float = 1.0) -> ColorRGBA:
    return ColorRGBA(r=float(rgb[0]), g=float(rgb[1]), b=float(rgb[2]), a=float(alpha))


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


def _point(xyz: Sequence[float]) -> Point:
    return Point(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def _marker(ns: str, marker_id: int, kind: int) -> Marker:
    marker = Marker()
    marker.header.frame_id = WORLD_FRAME
    marker.ns = ns
    marker.id = marker_id
    marker.type = kind
    marker.action = Marker.ADD
    marker.pose.orientation.w = 1.0
    marker.lifetime = Duration()  # forever, replaced by the next array
    return marker


def mission_corners(scenario: Scenario) -> list[tuple[float, float, float]]:
    """The leader reference's corners, world [m]: the start, then the end of every segment."""
    corners = [tuple(float(c) for c in scenario.mission.start)]
    previous_end = 0.0
    for segment in scenario.mission.segments:
        duration = segment.end_time - previous_end
        previous_end = segment.end_time
        last = corners[-1]
        corners.append(tuple(last[k] + segment.velocity[k] * duration for k in range(3)))
    return corners


def _static_markers(scenario: Scenario) -> list[Marker]:
    corners = mission_corners(scenario)
    path = _marker('mission_path', 0, Marker.LINE_STRIP)
    path.scale.x = PATH_WIDTH
    path.color = _color(_PATH, 0.8)
    path.points = [_point(c) for c in corners]
    markers = [path]
    heights = [c[2] for c in corners] + [u.position[2] for u in scenario.uavs]
    longest = max(u.cable_length for u in scenario.uavs)
    bottom = min(heights) - longest - GUST_MARGIN
    top = max(heights) + GUST_MARGIN
    for k, gust in enumerate(scenario.gusts):
        zone = _marker('gust_zone', k, Marker.CYLINDER)
        zone.pose.position = _point((gust.center[0], gust.center[1], 0.5 * (bottom + top)))
        zone.scale.x = zone.scale.y = 2.0 * gust.gradient_distance
        zone.scale.z = top - bottom
        zone.color = _color(_GUST, GUST_ALPHA)
        markers.append(zone)
    return markers


class FormationMarkers:
    """The MarkerArray of one scenario, its Marker messages made once and then rewritten."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        weight = scenario.payload.mass * scenario.simulation.gravity  # [N]
        self.reference_tension = weight / scenario.n_uavs  # [N]
        self._bodies, self._headings, self._cables = [], [], []
        for i, uav in enumerate(scenario.uavs):
            arm = uav.vehicle.arm_length  # [m]
            rgb = _LEADER if i == 0 else _FOLLOWER
            body = _marker('uav', i + 1, Marker.CYLINDER)
            body.scale.x = body.scale.y = BODY_DIAMETER_ARMS * arm
            body.scale.z = BODY_HEIGHT
            body.color = _color(rgb)
            heading = _marker('uav_heading', i + 1, Marker.ARROW)
            heading.pose = body.pose  # the same pose object: written once per call
            heading.scale.x = 2.0 * arm
            heading.scale.y = heading.scale.z = 0.25 * arm
            heading.color = _color(rgb)
            cable = _marker('cable', i + 1, Marker.LINE_STRIP)
            cable.scale.x = CABLE_WIDTH
            cable.color = _color(tension_color(0.0, self.reference_tension))
            cable.points = [body.pose.position, Point()]
            self._bodies.append(body)
            self._headings.append(heading)
            self._cables.append(cable)
        self._payload = _marker('payload', 0, Marker.SPHERE)
        self._payload.scale.x = self._payload.scale.y = self._payload.scale.z = PAYLOAD_DIAMETER
        self._payload.color = _color(_PAYLOAD)
        for cable in self._cables:
            cable.points[1] = self._payload.pose.position
        self._static = _static_markers(scenario)
        self._all = ([m for trio in zip(self._bodies, self._headings, self._cables)
                      for m in trio] + [self._payload] + self._static)

    def build(self, snapshot: Snapshot, tensions: Sequence[float],
              stamp: Time | int) -> MarkerArray:
        """The array for `snapshot` with cable `tensions` [N] (one per UAV), every marker
        stamped `stamp` (builtin_interfaces/Time or [ns]); rewritten by the next call."""
        if not isinstance(stamp, Time):
            stamp = stamp_from_ns(int(stamp))
        n = len(self._bodies)
        if len(snapshot.uavs) != n or len(tensions) != n:
            raise ValueError(f'formation_markers: scenario {self.scenario.name} has {n} UAVs, '
                             f'got a snapshot of {len(snapshot.uavs)} and {len(tensions)} '
                             'tensions')
        for marker in self._all:
            marker.header.stamp = stamp
        p = self._payload.pose.position
        p.x, p.y, p.z = (float(c) for c in snapshot.payload_position)
        for uav, body, cable, tension in zip(snapshot.uavs, self._bodies, self._cables,
                                             tensions):
            position = body.pose.position
            position.x, position.y, position.z = (float(c) for c in uav.position)
            o = body.pose.orientation
            o.x, o.y, o.z, o.w = (float(c) for c in quaternion_from_euler(uav.euler))
            r, g, b = tension_color(float(tension), self.reference_tension)
            c = cable.color
            c.r, c.g, c.b = r, g, b
        return MarkerArray(markers=self._all)


_builders: dict[int, FormationMarkers] = {}


def formation_markers(snapshot: Snapshot, tensions: Sequence[float], scenario: Scenario,
                      stamp: Time | int) -> MarkerArray:
    """Markers of the formation at `snapshot` (see the module docstring), frame `world`.

    `tensions`: cable tension per UAV [N] (as /formation/state's cable_tension); `stamp`: the
    header stamp of every marker, a builtin_interfaces/Time or an int [ns]. The builder
    (`FormationMarkers`) is cached on the scenario object's identity, so the array is rewritten
    by the next call with the same scenario: publish it before calling again.
    """
    builder = _builders.get(id(scenario))
    if builder is None or builder.scenario is not scenario:
        builder = FormationMarkers(scenario)
        _builders.clear()  # one scenario per process in practice; never grow without bound
        _builders[id(scenario)] = builder
    return builder.build(snapshot, tensions, stamp)
