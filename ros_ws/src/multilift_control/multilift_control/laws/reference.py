"""The leader's mission reference (seed §4.2): piecewise-constant velocity segments, world
frame, and its prefilter (not in the seed: `MissionPath`'s docstring)."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (MISSION_FINAL, MISSION_OMEGA, MISSION_SHAPED,
                                           MISSION_START,
                                           REFERENCE_ACCELERATION, REFERENCE_POSITION,
                                           REFERENCE_SIZE, REFERENCE_VELOCITY,
                                           SEGMENT_END_TIME, SEGMENT_ORIGIN, SEGMENT_START_TIME,
                                           SEGMENT_VELOCITY, STEP_DV, STEP_TIME)


@jit
def raw_reference(mission, segments, t, out):
    """The seed's path at t [s] into `out` (REFERENCE_* slots, world: [m], [m/s], [m/s^2]):
    velocity steps at the corners, the acceleration zero; before t = 0 (or with no segment)
    the start, after the last segment the final position, at rest. mission: MISSION_* slots;
    segments (k, SEGMENT_SIZE)."""
    for slot in range(REFERENCE_SIZE):
        out[slot] = 0.0
    count = segments.shape[0]
    if count == 0 or t < 0.0:
        for axis in range(3):
            out[REFERENCE_POSITION + axis] = mission[MISSION_START + axis]
        return out
    k = 0  # bisect_right of t in the segments' ends
    while k < count and segments[k, SEGMENT_END_TIME] <= t:
        k += 1
    if k >= count:
        for axis in range(3):
            out[REFERENCE_POSITION + axis] = mission[MISSION_FINAL + axis]
        return out
    for axis in range(3):
        velocity = segments[k, SEGMENT_VELOCITY + axis]
        out[REFERENCE_POSITION + axis] = (segments[k, SEGMENT_ORIGIN + axis]
                                          + velocity * (t - segments[k, SEGMENT_START_TIME]))
        out[REFERENCE_VELOCITY + axis] = velocity
    return out


@jit
def mission_reference(mission, segments, steps, t):
    """The reference at t [s]: (REFERENCE_SIZE,) position [m], velocity [m/s], acceleration
    [m/s^2], world. With MISSION_OMEGA = omega = 1/tau > 0 each horizontal velocity step dv_k
    at t_k (`steps`, (k, STEP_SIZE)) passes a critically damped second-order filter, in closed
    form: v(t) = sum_k dv_k s(t - t_k), s(x) = 1 - (1 + omega x) e^(-omega x); the position is
    its integral, the acceleration omega^2 x e^(-omega x) dv_k. omega = 0: `raw_reference`, or
    with MISSION_SHAPED the shaped steps unfiltered, s(x) = 1 (the acceleration their
    impulses, 0 between them)."""
    out = raw_reference(mission, segments, t, np.empty(REFERENCE_SIZE))
    omega = mission[MISSION_OMEGA]
    if omega == 0.0 and mission[MISSION_SHAPED] == 0.0:
        return out
    # horizontal only: the vertical steps (the climb of §4.2) need collective thrust, not
    # tilt, and stay raw, so the follower's climb lag of Fig. 4.7 stays the seed's
    for axis in range(2):
        out[REFERENCE_POSITION + axis] = mission[MISSION_START + axis]
        out[REFERENCE_VELOCITY + axis] = 0.0
        out[REFERENCE_ACCELERATION + axis] = 0.0
    for k in range(steps.shape[0]):
        x = t - steps[k, STEP_TIME]
        if x <= 0.0:
            break
        if omega == 0.0:  # shaped raw steps
            moved, gained, pushed = x, 1.0, 0.0
        else:
            decay = math.exp(-omega * x)
            moved = x - (2.0 - (2.0 + omega * x) * decay) / omega
            gained = 1.0 - (1.0 + omega * x) * decay
            pushed = omega * omega * x * decay
        for axis in range(2):
            dv = steps[k, STEP_DV + axis]
            out[REFERENCE_POSITION + axis] += dv * moved
            out[REFERENCE_VELOCITY + axis] += dv * gained
            out[REFERENCE_ACCELERATION + axis] += dv * pushed
    return out
