"""`mission.type: waypoints`: positions with times, world [m] (z up) at [s], joined by the
minimum-snap polynomial (Mellinger & Kumar 2011; `polynomials.minimum_snap`), continuous to
jerk (to the sixth derivative), at rest at the first and the last; an optional `yaw` [rad]
per waypoint (a waypoint without one keeps the previous one's, the first 0), joined the same
way. Before the first time the reference holds the first waypoint, after the last the last.

    mission:
      type: waypoints
      waypoints:
        - {time: 0.0, position: [0.0, 0.0, 1.0]}
        - {time: 4.0, position: [1.0, 0.5, 1.2], yaw: 0.3}
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from multilift_sim.missions.polynomials import minimum_snap, polynomial_mission
from multilift_sim.scenario.config import MissionConfig
from multilift_sim.scenario.reading import Section

NAME = 'waypoints'
FORM = 'polynomial'


def read(m: Section, start: tuple[float, float, float], folder: Path) -> MissionConfig:
    """`mission.waypoints`: at least 2, `time` [s] strictly increasing, `position` [m],
    optional `yaw` [rad]."""
    entries = m.sequence('waypoints')
    if len(entries) < 2:
        raise m.fail('waypoints', entries, 'must list at least 2 waypoints')
    times, points, yaws = [], [], []
    for i, entry in enumerate(entries):
        w = Section(entry, f'{m.key("waypoints")}[{i}]', m.where)
        previous = times[-1] if times else -np.inf
        times.append(w.number('time', ..., lambda t: t > previous,
                              f'must be > the previous waypoint\'s time ({previous:g} s)'))
        points.append(w.vector('position'))
        yaws.append(w.number('yaw', yaws[-1] if yaws else 0.0))
        w.done()
    table = np.column_stack((np.array(points), np.array(yaws)))
    return polynomial_mission(np.array(times), table, minimum_snap(np.array(times), table))
