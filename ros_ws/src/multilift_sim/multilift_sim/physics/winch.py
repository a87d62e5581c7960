"""Winches (`uavs[i].winch`, issue 32 item 3): a UAV's cable length l_i(t) is a state of its
reel, driven by a commanded reel rate (positive pays out) within a rate limit, an
acceleration limit and the min/max length stops.

Over one control period the reel heads from its rate v_0 for a target rate at the
acceleration limit a, then holds it: l(s) = l_0 + v_0 s + a s^2 / 2 until the target is
reached, then at the target (s from the period's start t_0). The target is the command clipped
to the rate limit and to the rate from which it can still brake at a onto the stop it moves
towards (`braking_rate`); a length beyond a stop by rounding is clamped (the reel at rest
there). The rows of a period (`reel_period`, a copy of the UAVs' constants rows) carry l_0,
v_0, t_0 and the target; every RK4 stage evaluates `reel_at` at its time (FORMATION_TIME).

With the seed's rigid cables the constraint becomes g_i = |d_i|^2 - l_i(t)^2 (Eq. 2.42 with a
moving length), g_dot_i = 2 d_i . d_i_dot - 2 l_i l_i_dot and g_ddot_i gains
-2 (l_i_dot^2 + l_i l_i_ddot): Baumgarte's row of Eq. 2.59-2.60 takes both (`reeled_cable`).
An elastic rope reels its rest length, its stiffness EA / l_i(t). World frame, SI units;
slots `physics.layout` UAV_WINCH_*, UAV_REEL_*, REEL_*.
"""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import (FORMATION_TIME, FORMATION_WINCH, REEL_COMMAND,
                                          REEL_LENGTH, REEL_RATE, UAV_LENGTH_SQ,
                                          UAV_REEL_LENGTH, UAV_REEL_RATE, UAV_REEL_START,
                                          UAV_REEL_TARGET, UAV_WINCH_ACCELERATION_LIMIT,
                                          UAV_WINCH_MAX_LENGTH, UAV_WINCH_MIN_LENGTH,
                                          UAV_WINCH_RATE_LIMIT)


@jit
def reel_at(uavs, i, t):
    """(l [m], l_dot [m/s], l_ddot [m/s^2]) of UAV i's cable at time t [s] of the period its
    row's UAV_REEL_* slots describe (a UAV without a winch: its length, at rest)."""
    s = t - uavs[i, UAV_REEL_START]
    length, rate = uavs[i, UAV_REEL_LENGTH], uavs[i, UAV_REEL_RATE]
    target = uavs[i, UAV_REEL_TARGET]
    change = target - rate
    limit = uavs[i, UAV_WINCH_ACCELERATION_LIMIT]
    if change == 0.0 or limit == 0.0:
        out, out_rate, out_acc = length + rate * s, rate, 0.0
    else:
        ramp = abs(change) / limit      # [s] to reach the target
        acc = limit if change > 0.0 else -limit
        if s < ramp:
            out, out_rate, out_acc = length + s * (rate + 0.5 * acc * s), rate + acc * s, acc
        else:
            out = length + ramp * (rate + 0.5 * acc * ramp) + target * (s - ramp)
            out_rate, out_acc = target, 0.0
    if uavs[i, UAV_WINCH_MAX_LENGTH] > 0.0:  # the stops (a winch's; none without one)
        if out > uavs[i, UAV_WINCH_MAX_LENGTH]:
            return uavs[i, UAV_WINCH_MAX_LENGTH], 0.0, 0.0
        if out < uavs[i, UAV_WINCH_MIN_LENGTH]:
            return uavs[i, UAV_WINCH_MIN_LENGTH], 0.0, 0.0
    return out, out_rate, out_acc


@jit
def braking_rate(room, acceleration, period):
    """The largest rate v [m/s] from which a reel that runs at v for a period [s] can still
    stop within `room` [m] braking at `acceleration` [m/s^2]: v T + v^2 / (2 a) = d. (Braking
    from where sqrt(2 a d) is reached, decided once a period, would be a period late: the
    rate would arrive at the stop still moving.)"""
    reach = acceleration * period
    return math.sqrt(reach * reach + 2.0 * acceleration * max(room, 0.0)) - reach


@jit
def reel_target(uavs, i, length, command, period):
    """The rate [m/s] UAV i's reel heads for over a period [s] from `length` [m] under
    `command` [m/s]: the command within the rate limit and within `braking_rate` of each stop,
    so that it brakes onto it at its acceleration limit; 0 without a winch."""
    limit = uavs[i, UAV_WINCH_RATE_LIMIT]
    if limit == 0.0:
        return 0.0
    target = min(max(command, -limit), limit)
    acceleration = uavs[i, UAV_WINCH_ACCELERATION_LIMIT]
    out_rate = braking_rate(uavs[i, UAV_WINCH_MAX_LENGTH] - length, acceleration, period)
    in_rate = braking_rate(length - uavs[i, UAV_WINCH_MIN_LENGTH], acceleration, period)
    return max(min(target, out_rate), -in_rate)


@jit
def reel_period(uavs, reel, t0, period):
    """The UAVs' constants rows for the period [s] from t0 [s] (a copy, the constants not
    written): each reel's length, rate and target from its memory `reel` (n, REEL_COLUMNS)."""
    rows = uavs.copy()
    for i in range(uavs.shape[0]):
        rows[i, UAV_REEL_START] = t0
        rows[i, UAV_REEL_LENGTH] = reel[i, REEL_LENGTH]
        rows[i, UAV_REEL_RATE] = reel[i, REEL_RATE]
        rows[i, UAV_REEL_TARGET] = reel_target(uavs, i, reel[i, REEL_LENGTH],
                                               reel[i, REEL_COMMAND], period)
    return rows


@jit
def period_uavs(uavs, reel, formation, t0, period):
    """The UAVs' constants rows a period [s] from t0 [s] is stepped with: `reel_period`'s where
    winches reel (FORMATION_WINCH), else `uavs` themselves."""
    if formation[FORMATION_WINCH] != 0.0:
        return reel_period(uavs, reel, t0, period)
    return uavs


@jit
def reel_end(rows, reel, t1, g, g_dot):
    """The reels' length and rate at the period's end t1 [s] into `reel` (n, REEL_COLUMNS)
    (`rows` the period's, `reel_period`), and the residuals g [m^2], g_dot [m^2/s] there,
    computed with the constant lengths, moved to the reeled ones (Eq. 2.42 with l_i(t1))."""
    for i in range(rows.shape[0]):
        length, rate, _ = reel_at(rows, i, t1)
        reel[i, REEL_LENGTH], reel[i, REEL_RATE] = length, rate
        g[i] += rows[i, UAV_LENGTH_SQ] - length * length
        g_dot[i] -= 2.0 * length * rate


@jit
def reeled_cable(uavs, formation, i):
    """(l_i^2 [m^2], l_i l_i_dot [m^2/s], l_i_dot^2 + l_i l_i_ddot [m^2/s^2]) of cable i at the
    stage's time (FORMATION_TIME): its length's terms in g, g_dot and g_ddot; (l_i^2, 0, 0),
    the constant length, without winches."""
    if formation[FORMATION_WINCH] == 0.0:
        return uavs[i, UAV_LENGTH_SQ], 0.0, 0.0
    length, rate, acc = reel_at(uavs, i, formation[FORMATION_TIME])
    return length * length, length * rate, rate * rate + length * acc
