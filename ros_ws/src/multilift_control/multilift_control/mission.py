"""The leader's mission path (seed §4.2): piecewise-constant velocity segments, world frame."""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np

from multilift_control.cascade import COMPILED_LAWS
from multilift_sim import kernels
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

    With `mission.reference_filter_time` tau > 0 (not in the seed: a documented departure, the
    reference prefilter of a cascade's outer loop) each horizontal velocity step dv at t_k passes a
    critically damped second-order filter with omega = 1/tau, in closed form:
    v(t) = sum_k dv_k s(t - t_k), s(x) = 1 - (1 + omega x) e^(-omega x); the acceleration
    omega^2 x e^(-omega x) peaks at omega dv / e and is continuous, and the position (the
    integral) rounds the corners and ends where the raw path ends. tau = 0: the raw path.
    """

    def __init__(self, mission: MissionConfig):
        self._tau = float(mission.reference_filter_time)
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

        # velocity steps (the first from rest at t = 0) for the filtered reference
        self._step_times = starts
        self._steps = np.diff(np.vstack((np.zeros((1, 3)), self._velocities)), axis=0) \
            if len(self._ends) else np.zeros((0, 3))
        if len(self._ends):  # the stop after the last segment
            self._step_times = np.append(starts, self._ends[-1])
            self._steps = np.vstack((self._steps, -self._velocities[-1]))
        self._end_list = self._ends.tolist()
        self._step_list = list(zip(self._step_times.tolist(), self._steps.tolist()))
        # _filtered compiled when the kernels are on (multilift_control._numba_laws)
        laws = kernels.compiled_module(COMPILED_LAWS)
        self._compiled_filtered = None if laws is None else laws.filtered_reference
        self._compiled_path = tuple(np.ascontiguousarray(a, dtype=float) for a in (
            self._start, self._step_times, self._steps.reshape(-1, 3), self._ends,
            self._velocities, self._origins.reshape(-1, 3), self._starts,
            np.asarray(self._final, dtype=float)))

    def __call__(self, t: float) -> Reference:
        """The reference at simulated time t [s]."""
        if self._tau > 0.0:
            if self._compiled_filtered is not None:  # _filtered's arithmetic, compiled
                out = self._compiled_filtered(float(t), 1.0 / self._tau, *self._compiled_path)
                return Reference(out[:3], out[3:6], out[6:])
            return self._filtered(t)
        return self._raw(t)

    def _raw(self, t: float) -> Reference:
        """The seed's path: velocity steps at the corners."""
        zero = np.zeros(3)
        if len(self._ends) == 0 or t < 0.0:
            return Reference(self._start.copy(), zero, zero.copy())
        k = bisect.bisect_right(self._end_list, t)
        if k >= len(self._ends):
            return Reference(self._final.copy(), zero, zero.copy())
        velocity = self._velocities[k]
        position = self._origins[k] + velocity * (t - self._starts[k])
        return Reference(position, velocity.copy(), zero.copy())

    def _filtered(self, t: float) -> Reference:
        """The reference after the critically damped prefilter (class docstring); in plain
        floats per axis (a handful of steps: numpy's per-call cost would dominate)."""
        w = 1.0 / self._tau
        position = self._start.tolist()
        velocity = [0.0, 0.0, 0.0]
        acceleration = [0.0, 0.0, 0.0]
        for t_k, dv in self._step_list:
            x = t - t_k
            if x <= 0.0:
                break
            decay = math.exp(-w * x)
            moved = x - (2.0 - (2.0 + w * x) * decay) / w
            gained = 1.0 - (1.0 + w * x) * decay
            pushed = w * w * x * decay
            for axis in (0, 1):  # horizontal only: see below
                position[axis] += dv[axis] * moved
                velocity[axis] += dv[axis] * gained
                acceleration[axis] += dv[axis] * pushed
        # horizontal only: the vertical steps (the climb of §4.2) need collective thrust, not
        # tilt, and stay raw, so the follower's climb lag of Fig. 4.7 stays the seed's
        raw = self._raw(t)
        position[2], velocity[2], acceleration[2] = (raw.position[2], raw.velocity[2],
                                                      raw.acceleration[2])
        return Reference(np.array(position), np.array(velocity), np.array(acceleration))
