"""The leader's mission path: the arrays of the compiled reference (`laws.reference`) built from
the scenario's mission source (multilift_sim.missions: the seed's velocity segments, §4.2, or a
piecewise polynomial), world frame."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from multilift_control import laws
from multilift_control.laws.layout import (FORM_POLYNOMIAL, FORM_VELOCITY_SEGMENTS,
                                           MISSION_FINAL, MISSION_FORM, MISSION_OMEGA,
                                           MISSION_SHAPED, MISSION_SIZE, MISSION_START,
                                           PIECE_AXES, PIECE_COEFFICIENTS, PIECE_END_TIME,
                                           PIECE_ORDER, PIECE_SIZE, PIECE_START_TIME,
                                           REFERENCE_ACCELERATION, REFERENCE_POSITION,
                                           REFERENCE_VELOCITY, REFERENCE_YAW,
                                           SEGMENT_END_TIME, SEGMENT_ORIGIN, SEGMENT_SIZE,
                                           SEGMENT_START_TIME, SEGMENT_VELOCITY, STEP_DV,
                                           STEP_SIZE, STEP_TIME)
from multilift_control.laws.reference import mission_reference
from multilift_sim.missions import FORMS, source_of
from multilift_sim.scenario import MissionConfig


@dataclass(frozen=True)
class Reference:
    """What the leader tracks at one instant, world frame."""
    position: np.ndarray      # [m]
    velocity: np.ndarray      # [m/s]
    acceleration: np.ndarray  # [m/s^2]
    yaw: float = 0.0          # heading [rad]

    @classmethod
    def of(cls, row: np.ndarray) -> Reference:
        """The reference in a law's REFERENCE_* slots."""
        return cls(row[REFERENCE_POSITION:REFERENCE_POSITION + 3],
                   row[REFERENCE_VELOCITY:REFERENCE_VELOCITY + 3],
                   row[REFERENCE_ACCELERATION:REFERENCE_ACCELERATION + 3],
                   float(row[REFERENCE_YAW]))


class MissionPath:
    """Position reference integrated from the mission's velocity segments
    (`laws.reference.mission_reference`).

    Velocity steps from one segment to the next (the seed's path has corners); the reference
    acceleration is zero everywhere but at the corners. After the last segment it holds still.

    With `mission.reference_filter_time` tau > 0 (not in the seed: a documented departure, the
    reference prefilter of a cascade's outer loop) each horizontal velocity step dv at t_k passes a
    critically damped second-order filter with omega = 1/tau, in closed form:
    v(t) = sum_k dv_k s(t - t_k), s(x) = 1 - (1 + omega x) e^(-omega x); the acceleration
    omega^2 x e^(-omega x) peaks at omega dv / e and is continuous, and the position (the
    integral) rounds the corners and ends where the raw path ends. tau = 0: the raw path.

    With a `shaper` ((time [periods], share), ...) of multilift_sim.scenario.INPUT_SHAPERS
    (`control.payload_feedback.input_shaping`, issue 20; not in the seed) and the pendulum's
    `period` T [s], each step dv_k becomes share_j dv_k at t_k + time_j T (an input shaper,
    Singer & Seering 1990): an undamped pendulum of period T driven by the reference's
    acceleration is left at rest after the last impulse, whatever the filter after it.

    `mission`, `segments`, `steps`: the law's arrays (MISSION_*, SEGMENT_*, STEP_* slots).

    A source of the `polynomial` form (`mission.type` waypoints, file): `segments` holds its
    pieces (PIECE_* slots), `steps` is empty, MISSION_FORM is FORM_POLYNOMIAL; no filter, no
    shaper (validation refuses them).

    With `offset` (3,) [m], world, every position of the path is moved by it (the velocities
    and accelerations are the path's): `mission.tracks: payload`, whose path is the payload's,
    flown by the leader at its offset from the payload at the formation's hanging rest
    (`controllers.tracked_offset`).
    """

    def __init__(self, mission: MissionConfig,
                 shaper: tuple[tuple[float, float], ...] = ((0.0, 1.0),), period: float = 0.0,
                 offset: np.ndarray | None = None):
        if offset is not None:
            mission = shifted(mission, np.asarray(offset, dtype=float))
        form = FORMS.index(source_of(mission).FORM)
        if form == FORM_POLYNOMIAL:
            self._polynomial(mission)
        else:
            self._segments(mission, shaper, period)
        self.mission[MISSION_FORM] = float(form)
        self._law = laws.runnable(mission_reference)

    def _polynomial(self, mission: MissionConfig) -> None:
        coefficients = np.asarray(mission.coefficients, dtype=float).reshape(
            len(mission.coefficients), PIECE_AXES, -1)
        knots = np.asarray(mission.knots, dtype=float)
        self.mission = np.zeros(MISSION_SIZE)
        self.mission[MISSION_START:MISSION_START + 3] = mission.points[0]
        self.mission[MISSION_FINAL:MISSION_FINAL + 3] = mission.points[-1]
        self.segments = np.zeros((len(coefficients), PIECE_SIZE))
        self.segments[:, PIECE_START_TIME] = knots[:-1]
        self.segments[:, PIECE_END_TIME] = knots[1:]
        for axis in range(PIECE_AXES):
            first = PIECE_COEFFICIENTS + axis * PIECE_ORDER
            self.segments[:, first:first + coefficients.shape[2]] = coefficients[:, axis]
        self.steps = np.zeros((0, STEP_SIZE))

    def _segments(self, mission: MissionConfig, shaper: tuple[tuple[float, float], ...],
                  period: float) -> None:
        tau = float(mission.reference_filter_time)
        start = np.asarray(mission.start, dtype=float)
        ends = np.array([s.end_time for s in mission.segments], dtype=float)
        velocities = np.array([s.velocity for s in mission.segments], dtype=float).reshape(-1, 3)
        starts = np.concatenate(([0.0], ends[:-1])) if len(ends) else np.zeros(0)
        # position at the start of each segment
        steps = velocities * (ends - starts)[:, None]
        origins = start + np.concatenate((np.zeros((1, 3)), np.cumsum(steps, 0)))[:-1] \
            if len(steps) else np.zeros((0, 3))
        self.mission = np.empty(MISSION_SIZE)
        self.mission[MISSION_START:MISSION_START + 3] = start
        self.mission[MISSION_FINAL:MISSION_FINAL + 3] = (start + steps.sum(axis=0)
                                                         if len(steps) else start)
        self.mission[MISSION_OMEGA] = 1.0 / tau if tau > 0.0 else 0.0
        self.mission[MISSION_SHAPED] = 1.0 if len(shaper) > 1 else 0.0
        self.mission[MISSION_FORM] = float(FORM_VELOCITY_SEGMENTS)
        self.segments = np.empty((len(ends), SEGMENT_SIZE))
        self.segments[:, SEGMENT_START_TIME] = starts
        self.segments[:, SEGMENT_END_TIME] = ends
        self.segments[:, SEGMENT_VELOCITY:SEGMENT_VELOCITY + 3] = velocities
        self.segments[:, SEGMENT_ORIGIN:SEGMENT_ORIGIN + 3] = origins
        # velocity steps (the first from rest at t = 0, the last the stop after the last
        # segment) for the filtered reference
        self.steps = np.zeros((len(ends) + 1 if len(ends) else 0, STEP_SIZE))
        if len(ends):
            self.steps[:, STEP_TIME] = np.append(starts, ends[-1])
            self.steps[:, STEP_DV:STEP_DV + 3] = np.vstack((
                np.diff(np.vstack((np.zeros((1, 3)), velocities)), axis=0), -velocities[-1]))
        if len(shaper) > 1 and len(self.steps):  # each step as the shaper's impulses
            shaped = []
            for delay, share in shaper:
                part = self.steps.copy()
                part[:, STEP_TIME] += delay * period
                part[:, STEP_DV:STEP_DV + 3] *= share
                shaped.append(part)
            shaped = np.vstack(shaped)
            self.steps = shaped[np.argsort(shaped[:, STEP_TIME], kind='stable')]

    def __call__(self, t: float) -> Reference:
        """The reference at simulated time t [s]."""
        return Reference.of(self._law(self.mission, self.segments, self.steps, float(t)))


def shifted(mission: MissionConfig, offset: np.ndarray) -> MissionConfig:
    """`mission` with every position moved by `offset` (3,) [m], world: its start and, for a
    polynomial, each piece's constant term and its points."""
    coefficients = np.array(mission.coefficients, dtype=float).reshape(
        len(mission.coefficients), PIECE_AXES, -1)
    if len(coefficients):
        coefficients[:, :3, 0] += offset
    return replace(
        mission, start=tuple(float(v) for v in np.add(mission.start, offset)),
        coefficients=tuple(tuple(tuple(float(c) for c in axis) for axis in piece)
                           for piece in coefficients),
        points=tuple(tuple(float(v) for v in np.add(p, offset)) for p in mission.points))
