"""The leader's mission reference: the seed's piecewise-constant velocity segments (§4.2), world
frame, and their prefilter (not in the seed: `MissionPath`'s docstring), or a piecewise
polynomial (issue 34: `mission.type` waypoints or file, multilift_sim.missions)."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (FORM_POLYNOMIAL, MISSION_FINAL, MISSION_FORM,
                                           MISSION_OMEGA, MISSION_SHAPED, MISSION_START,
                                           PIECE_AXES, PIECE_COEFFICIENTS, PIECE_END_TIME,
                                           PIECE_ORDER, PIECE_START_TIME,
                                           REFERENCE_ACCELERATION, REFERENCE_POSITION,
                                           REFERENCE_SIZE, REFERENCE_VELOCITY, REFERENCE_YAW,
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
def polynomial_reference(mission, pieces, t, out):
    """A piecewise polynomial's reference at t [s] into `out` (REFERENCE_* slots, world: [m],
    [m/s], [m/s^2], yaw [rad]): piece k's p(t - t_k) and its first two derivatives by Horner's
    rule; before the first piece its start, after the last its end, at rest (derivatives 0).
    pieces (k, PIECE_SIZE); no piece: MISSION_START."""
    for slot in range(REFERENCE_SIZE):
        out[slot] = 0.0
    count = pieces.shape[0]
    if count == 0:
        for axis in range(3):
            out[REFERENCE_POSITION + axis] = mission[MISSION_START + axis]
        return out
    k, held = 0, True
    local = 0.0
    if t >= pieces[count - 1, PIECE_END_TIME]:
        k = count - 1
        local = pieces[k, PIECE_END_TIME] - pieces[k, PIECE_START_TIME]
    elif t > pieces[0, PIECE_START_TIME]:
        held = False
        while pieces[k, PIECE_END_TIME] <= t:  # the piece holding t
            k += 1
        local = t - pieces[k, PIECE_START_TIME]
    for axis in range(PIECE_AXES):
        first = PIECE_COEFFICIENTS + axis * PIECE_ORDER
        position, velocity, acceleration = 0.0, 0.0, 0.0
        for j in range(PIECE_ORDER - 1, -1, -1):
            c = pieces[k, first + j]
            acceleration = acceleration * local + 2.0 * velocity
            velocity = velocity * local + position
            position = position * local + c
        if axis == 3:
            out[REFERENCE_YAW] = position
        else:
            out[REFERENCE_POSITION + axis] = position
            if not held:
                out[REFERENCE_VELOCITY + axis] = velocity
                out[REFERENCE_ACCELERATION + axis] = acceleration
    return out


@jit
def mission_reference(mission, segments, steps, t):
    """The reference at t [s]: (REFERENCE_SIZE,) position [m], velocity [m/s], acceleration
    [m/s^2], world. With MISSION_OMEGA = omega = 1/tau > 0 each horizontal velocity step dv_k
    at t_k (`steps`, (k, STEP_SIZE)) passes a critically damped second-order filter, in closed
    form: v(t) = sum_k dv_k s(t - t_k), s(x) = 1 - (1 + omega x) e^(-omega x); the position is
    its integral, the acceleration omega^2 x e^(-omega x) dv_k. omega = 0: `raw_reference`, or
    with MISSION_SHAPED the shaped steps unfiltered, s(x) = 1 (the acceleration their
    impulses, 0 between them). MISSION_FORM FORM_POLYNOMIAL: `polynomial_reference` of the
    pieces in `segments`' place."""
    if mission[MISSION_FORM] == FORM_POLYNOMIAL:
        return polynomial_reference(mission, segments, t, np.empty(REFERENCE_SIZE))
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
