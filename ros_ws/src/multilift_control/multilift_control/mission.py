"""The leader's mission path (seed §4.2): piecewise-constant velocity segments, world frame."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multilift_sim.scenario import MissionConfig


@dataclass(frozen=True)
class Reference:
    """What the leader tracks at one instant, world frame."""
    position: np.ndarray      # [m]
    velocity: np.ndarray      # [m/s]
    acceleration: np.ndarray  # [m/s^2]


class MissionPath:
    """Position reference integrated from the mission's velocity segments.

    Velocity steps from one segment to the next (the seed's path has corners); the reference
    acceleration is zero everywhere but at the corners. After the last segment it holds still.
    """

    def __init__(self, mission: MissionConfig):
        self._start = np.asarray(mission.start, dtype=float)
        self._ends = np.array([s.end_time for s in mission.segments], dtype=float)
        self._velocities = np.array([s.velocity for s in mission.segments], dtype=float)
        self._velocities = self._velocities.reshape(-1, 3)
        starts = np.concatenate(([0.0], self._ends[:-1])) if len(self._ends) else np.zeros(0)
        durations = self._ends - starts
        self._starts = starts
        # position at the start of each segment
        steps = self._velocities * durations[:, None]
        self._origins = self._start + np.concatenate((np.zeros((1, 3)), np.cumsum(steps, 0)))[:-1] \
            if len(steps) else np.zeros((0, 3))
        self._final = self._start + steps.sum(axis=0) if len(steps) else self._start

    def __call__(self, t: float) -> Reference:
        """The reference at simulated time t [s]."""
        zero = np.zeros(3)
        if len(self._ends) == 0 or t < 0.0:
            return Reference(self._start.copy(), zero, zero.copy())
        k = int(np.searchsorted(self._ends, t, side='right'))
        if k >= len(self._ends):
            return Reference(self._final.copy(), zero, zero.copy())
        velocity = self._velocities[k]
        position = self._origins[k] + velocity * (t - self._starts[k])
        return Reference(position, velocity.copy(), zero.copy())
