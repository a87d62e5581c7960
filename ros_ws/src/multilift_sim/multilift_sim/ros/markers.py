"""`/visualization/markers` content: the formation as a visualization_msgs/MarkerArray.

Pure message building (no node, no publisher): `formation_markers(snapshot, tensions, scenario,
stamp)` turns one simulator `Snapshot` into markers in the `world` frame that RViz and
Foxglove's 3-D panel draw. What each marker is, where and in which colour is computed by
multilift_sim.wire.scene (`FormationScene`, see its docstring), which the headless bag packs
too;
this module copies those values into rclpy messages.

Cost: making a Marker message in rclpy is what costs (about 60 us each), so a
`FormationMarkers` builder makes its markers once and afterwards only writes poses, points,
colours and stamps into them: 0.04 ms per call for five UAVs (measured; 1.2 ms when made anew).
The array returned is therefore rewritten by the next call for the same scenario: publish (or
serialize) it first. Publish-rate decimation is the caller's business.
"""

from __future__ import annotations

from typing import Sequence

from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from multilift_sim.ros.common import WORLD_FRAME, stamp_from_ns
from multilift_sim.scenario import Scenario
from multilift_sim.wire.scene import (BODY_DIAMETER_ARMS, BODY_HEIGHT,  # noqa: F401
                                      CABLE_WIDTH, GUST_ALPHA, GUST_MARGIN, PATH_WIDTH,
                                      PAYLOAD_DIAMETER, FormationScene, MarkerSpec,
                                      mission_corners, tension_color)
from multilift_sim.simulation import Snapshot


def _point(xyz: Sequence[float]) -> Point:
    return Point(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def _marker(spec: MarkerSpec) -> Marker:
    marker = Marker()
    marker.header.frame_id = WORLD_FRAME
    marker.ns = spec.ns
    marker.id = spec.id
    marker.type = spec.type
    marker.action = spec.action
    p, o = marker.pose.position, marker.pose.orientation
    p.x, p.y, p.z = spec.position
    o.x, o.y, o.z, o.w = spec.orientation
    marker.scale.x, marker.scale.y, marker.scale.z = spec.scale
    r, g, b, a = spec.color
    marker.color = ColorRGBA(r=r, g=g, b=b, a=a)
    marker.lifetime = Duration()  # forever, replaced by the next array
    marker.points = [_point(xyz) for xyz in spec.points]
    return marker


class FormationMarkers:
    """The MarkerArray of one scenario, its Marker messages made once and then rewritten."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.scene = FormationScene(scenario)
        self.reference_tension = self.scene.reference_tension
        self._all = [_marker(spec) for spec in self.scene.specs]
        n = self.scene.n_uavs
        # the moving markers: per UAV body, heading, cable; then the payload
        self._moving = list(zip(self._all[:3 * n + 1], self.scene.specs[:3 * n + 1]))

    def build(self, snapshot: Snapshot, tensions: Sequence[float], stamp: Time | int,
              taut: Sequence[bool] | None = None) -> MarkerArray:
        """The array for `snapshot` with cable `tensions` [N] (one per UAV) and `taut` flags
        (None: all taut), every marker stamped `stamp` (builtin_interfaces/Time or [ns]);
        rewritten by the next call."""
        if not isinstance(stamp, Time):
            stamp = stamp_from_ns(int(stamp))
        self.scene.update([u.position for u in snapshot.uavs], [u.euler for u in snapshot.uavs],
                          snapshot.payload_position, tensions, taut,
                          None if snapshot.payload_attitude is None
                          else snapshot.payload_attitude[0], snapshot.chain_points)
        for marker in self._all:
            marker.header.stamp = stamp
        for marker, spec in self._moving:
            p, o = marker.pose.position, marker.pose.orientation
            p.x, p.y, p.z = spec.position
            o.x, o.y, o.z, o.w = spec.orientation
            c = marker.color
            c.r, c.g, c.b = spec.color[:3]
            for point, xyz in zip(marker.points, spec.points):
                point.x, point.y, point.z = xyz
        return MarkerArray(markers=self._all)


_builders: dict[int, FormationMarkers] = {}


def formation_markers(snapshot: Snapshot, tensions: Sequence[float], scenario: Scenario,
                      stamp: Time | int, taut: Sequence[bool] | None = None) -> MarkerArray:
    """Markers of the formation at `snapshot` (see the module docstring), frame `world`.

    `tensions`: cable tension per UAV [N] (as /formation/state's cable_tension); `taut`: per
    cable (None: all taut; a slack cable is dashed); `stamp`: the
    header stamp of every marker, a builtin_interfaces/Time or an int [ns]. The builder
    (`FormationMarkers`) is cached on the scenario object's identity, so the array is rewritten
    by the next call with the same scenario: publish it before calling again.
    """
    builder = _builders.get(id(scenario))
    if builder is None or builder.scenario is not scenario:
        builder = FormationMarkers(scenario)
        _builders.clear()  # one scenario per process in practice; never grow without bound
        _builders[id(scenario)] = builder
    return builder.build(snapshot, tensions, stamp, taut)
