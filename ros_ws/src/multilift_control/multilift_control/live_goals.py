"""Live goals and paths for the leader (`scripts/multilift run SCENARIO --live`, issue 34).

The leader holds the start of its mission (the reference at t = 0) until a goal or a path
arrives; each one replaces the mission from the control tick of its stamp on (the first tick
at or after it, in simulated time), starting from where the reference then is:

- a goal (a position, world [m], and optionally a yaw [rad]) is reached on the rest-to-rest
  minimum-snap polynomial (`missions.polynomials.minimum_snap` through two points), its
  duration the shortest within `mission.max_speed` and `mission.max_acceleration`; then held;
- a path (positions with times [s], simulated time, after the stamp) is followed in time: the
  minimum-snap polynomial from the reference at the stamp through its points, held at the last.

A new reference starts at rest: a goal that replaces one still being flown steps the
reference's velocity (as the seed's segments do at their corners). The points are the tracked
point's (`mission.tracks`: the leader, or the payload, then flown at its offset as
MissionPath does). ROS messages are read in `multilift_control.ros.live_input`; this module
has no rclpy. Not in the seed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from multilift_control.controllers import tracked_offset
from multilift_control.mission import MissionPath
from multilift_sim.missions.polynomials import minimum_snap, polynomial_mission
from multilift_sim.scenario import MissionConfig


@dataclass(frozen=True)
class LiveTarget:
    """A goal (one point) or a path (points with times), as received: `stamp` [s] the tick it
    takes effect at (simulated time), `times` (k,) [s] (a goal: empty, its time found from the
    limits), `points` (k, 3) world [m], `yaws` (k,) [rad] (NaN: keep the current yaw)."""
    stamp: float
    points: np.ndarray
    yaws: np.ndarray
    times: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def kind(self) -> str:
        return 'goal' if len(self.times) == 0 else 'path'


# The rest-to-rest minimum-snap polynomial from 0 to 1 over a time of 1,
# s = 35 t^4 - 84 t^5 + 70 t^6 - 20 t^7, peaks at |s'| = 35/16 (t = 1/2) and
# |s''| = 84 sqrt(5) / 25 (t = 1/2 -+ sqrt(5)/10): a distance D flown in T peaks at
# UNIT_SPEED_PEAK D / T [m/s] and UNIT_ACCELERATION_PEAK D / T^2 [m/s^2]
UNIT_SPEED_PEAK = 35.0 / 16.0
UNIT_ACCELERATION_PEAK = 84.0 * math.sqrt(5.0) / 25.0


def goal_duration(distance: float, max_speed: float, max_acceleration: float) -> float:
    """The shortest time [s] of the rest-to-rest minimum-snap move over `distance` [m] within
    `max_speed` [m/s] and `max_acceleration` [m/s^2] (at least one control-sized 0.1 s)."""
    return max(0.1, UNIT_SPEED_PEAK * distance / max_speed,
               math.sqrt(UNIT_ACCELERATION_PEAK * distance / max_acceleration))


def target_mission(mission: MissionConfig, target: LiveTarget, position: np.ndarray,
                   yaw: float) -> MissionConfig:
    """The polynomial mission flying `target` from `position` (3,) [m] and `yaw` [rad], the
    tracked point's reference at target.stamp, with `mission`'s type and limits."""
    if target.kind == 'goal':
        distance = float(np.linalg.norm(target.points[0] - position))
        times = np.array([0.0, goal_duration(distance, mission.max_speed,
                                             mission.max_acceleration)]) + target.stamp
    else:
        times = np.concatenate(([target.stamp], target.times))
    table = np.zeros((len(times), 4))
    table[0, :3], table[0, 3] = position, yaw
    table[1:, :3] = target.points
    for k in range(1, len(times)):  # NaN yaw: the previous point's
        given = target.yaws[k - 1]
        table[k, 3] = table[k - 1, 3] if math.isnan(given) else given
    config = polynomial_mission(times, table, minimum_snap(times, table))
    return replace(config, type='waypoints', tracks=mission.tracks,
                   max_speed=mission.max_speed, max_acceleration=mission.max_acceleration)


def check_target(target: LiveTarget) -> str | None:
    """Why `target` cannot be flown (one line), or None."""
    if not (np.all(np.isfinite(target.points)) and target.points.shape[1:] == (3,)
            and len(target.points)):
        return 'its positions must be finite (x, y, z) and at least one'
    if target.kind == 'path':
        if len(target.times) != len(target.points):
            return 'each pose needs its stamp'
        previous = np.concatenate(([target.stamp], target.times[:-1]))
        if np.any(~np.isfinite(target.times)) or np.any(target.times <= previous):
            return (f'its poses\' stamps must increase after the path\'s own '
                    f'({target.stamp:.3f} s)')
    return None


class LiveMission:
    """The mission of `leader` (a controllers.LeaderController of `scenario`) under live
    targets: its path holds the mission's start (the reference at t = 0) until the first target
    takes effect (`apply`), then flies each; the positions are the tracked point's, moved to
    the leader's as its MissionPath moves them (controllers.tracked_offset)."""

    def __init__(self, leader, scenario):
        self.leader = leader
        self.mission = scenario.mission
        self.offset = tracked_offset(scenario)
        first = leader.path(0.0)
        self.pending: list[LiveTarget] = []
        self.applied: list[LiveTarget] = []
        hold = LiveTarget(0.0, self._tracked(first.position)[None, :], np.array([first.yaw]),
                          np.array([1.0]))
        self._fly(hold, first)

    def _tracked(self, position) -> np.ndarray:
        """The tracked point's position [m] for the leader's reference `position`."""
        return np.asarray(position, dtype=float) - (0.0 if self.offset is None else self.offset)

    def _fly(self, target: LiveTarget, reference) -> None:
        mission = target_mission(self.mission, target, self._tracked(reference.position),
                                 reference.yaw)
        self.leader.path = MissionPath(mission, offset=self.offset)

    def offer(self, target: LiveTarget) -> str | None:
        """Queue `target` (None) or say why it is ignored (one line)."""
        why = check_target(target)
        if why is None:
            self.pending.append(target)
            self.pending.sort(key=lambda x: x.stamp)
        return why

    def apply(self, t: float) -> list[LiveTarget]:
        """Take every queued target stamped at or before t [s] in stamp order (each replaces the
        one before), from the reference at t (a late one starts at t); the ones taken."""
        taken = [x for x in self.pending if x.stamp <= t]
        self.pending = [x for x in self.pending if x.stamp > t]
        for target in taken:
            now = replace(target, stamp=t)
            if target.kind == 'path':
                keep = target.times > t
                if not keep.any():  # all of it in the past: nothing left to follow
                    continue
                now = replace(now, points=target.points[keep], yaws=target.yaws[keep],
                              times=target.times[keep])
            self._fly(now, self.leader.path(t))
            self.applied.append(now)
        return taken
