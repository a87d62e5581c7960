"""The taut event of a slack cable, located within the RK4 step (`cable_model: slack`,
slack_cables.slack_step calls it): the guard g_i / l_i^2 of the slack cables on the RK4 map,
its crossing bracketed by the step's ends or by the peak of a cubic Hermite interpolant, then
found by Illinois regula falsi. World frame, SI; arguments as in formation_dae and
slack_cables, the slots `physics.layout`'s.
"""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.formation_dae import residuals, rk4_step
from multilift_sim.physics.layout import (
    SLACK_BRACKET, SLACK_CROSSING, SLACK_END, SLACK_EVENT, SLACK_G_DOT_END, SLACK_G_END,
    SLACK_MULTIPLIERS, SLACK_SNAPPING, SLACK_VALUE, SLACK_VALUE_BRACKET, SLACK_WATCHED,
    UAV_LENGTH_SQ)

# The taut event is located to |g_i| <= EVENT_TOLERANCE l_i^2 (|r_p - r_i| within 5e-13 l_i of
# l_i), in at most EVENT_ITERATIONS RK4 sub-steps (one or two in practice).
EVENT_TOLERANCE = 1e-12
EVENT_ITERATIONS = 40


# --------------------------------------------------------------------- the taut event
# Event location for hybrid systems: integrate, test the guard (here g_i = |r_p - r_i|^2
# - l_i^2 of each slack cable) at the step's ends, and when it changed sign find its
# zero in the step on the integrator's own map, apply the jump there and restart (Shampine
# & Thompson, "Event location for ordinary differential equations", Comput. Math. Appl. 39,
# 2000). RotorTM, this model's reference, does the same with its ODE solver's event
# function (|x_L - x_Q| - l, terminal, direction +1: slackToTaut / cooperativeGuard passed
# as ode45's Events, arplaboratory/RotorTM), then applies its inelastic collision map.
@jit
def hermite_polynomial(h, p0, m0, p1, m1, s):
    """The cubic Hermite interpolant of values p0, p1 and slopes m0, m1 at t = 0, h, at
    s = t / h."""
    a = 2.0 * (p0 - p1) + h * (m0 + m1)
    b = 3.0 * (p1 - p0) - h * (2.0 * m0 + m1)
    return ((a * s + b) * s + h * m0) * s + p0


@jit
def hermite_root(h, p0, m0, p1, m1):
    """The first t in (0, h] where the interpolant (p0 < 0) reaches 0 (h if none): bisection
    on the first of its monotone pieces (split at its stationary points) that ends >= 0."""
    a = 2.0 * (p0 - p1) + h * (m0 + m1)
    b = 3.0 * (p1 - p0) - h * (2.0 * m0 + m1)
    first, second = stationary_points(a, b, h * m0)
    ends = (min(first, second), max(first, second), 1.0)
    lo = 0.0
    for hi in ends:
        if not lo < hi <= 1.0:
            continue
        if hermite_polynomial(h, p0, m0, p1, m1, hi) >= 0.0:
            for _ in range(200):
                middle = 0.5 * (lo + hi)
                if not lo < middle < hi:
                    break
                if hermite_polynomial(h, p0, m0, p1, m1, middle) >= 0.0:
                    hi = middle
                else:
                    lo = middle
            return h * hi
        lo = hi
    return h


@jit
def stationary_points(a, b, c):
    """The real roots in (0, 1) of 3 a s^2 + 2 b s + c (the slope of a s^3 + b s^2 + c s + d),
    -1.0 for each missing one."""
    first = second = -1.0
    if a == 0.0:
        if b != 0.0:
            first = -c / (2.0 * b)
    else:
        discriminant = b * b - 3.0 * a * c
        if discriminant >= 0.0:
            root = math.sqrt(discriminant)
            first, second = (-b - root) / (3.0 * a), (-b + root) / (3.0 * a)
    if not 0.0 < first < 1.0:
        first = -1.0
    if not 0.0 < second < 1.0:
        second = -1.0
    return first, second


@jit
def hermite_peak(h, p0, m0, p1, m1):
    """(t, value) of the interpolant's highest point in (0, h) (slope + at 0, - at h)."""
    a = 2.0 * (p0 - p1) + h * (m0 + m1)
    b = 3.0 * (p1 - p0) - h * (2.0 * m0 + m1)
    first, second = stationary_points(a, b, h * m0)
    best, value = -1.0, -math.inf
    for s in (first, second):
        if s > 0.0:
            here = hermite_polynomial(h, p0, m0, p1, m1, s)
            if here > value:
                best, value = s, here
    if best < 0.0:
        return 0.5 * h, hermite_polynomial(h, p0, m0, p1, m1, 0.5)
    return h * best, value


@jit
def guard(x, wrenches, uavs, gusts, formation, taut, tau, watched, out, value, work, cables,
          multipliers):
    """f(tau) = max_i g_i(RK4(x, tau)) / l_i^2 over the `watched` cables; the RK4 state into
    out, every g_i / l_i^2 into value."""
    rk4_step(x, wrenches, uavs, gusts, formation, taut, tau, out, multipliers, work, cables)
    residuals(out, uavs, value, multipliers)
    f = -math.inf
    for i in range(uavs.shape[0]):
        value[i] /= uavs[i, UAV_LENGTH_SQ]
        if watched[i] and value[i] > f:
            f = value[i]
    return f


@jit
def taut_event(x, wrenches, uavs, gusts, formation, taut, released, h, g, g_dot, states, values,
               flags, work, cables):
    """The first time tau in (0, h] at which a slack cable (not `released`: (n,) bool, the
    cables let go of for good), shorter than l_i at x, reaches
    l_i on the RK4 sub-step from x, or -1.0: the state there into states[SLACK_EVENT], which
    cables snap into flags[SLACK_SNAPPING]. g, g_dot (n,) at x; states[SLACK_END] and
    values[SLACK_G_END], values[SLACK_G_DOT_END] the RK4 step of h and its residuals.

    The guard is f(tau) = max_i g_i(RK4(x, tau)) / l_i^2 over those cables. A crossing is
    bracketed by the step's ends, or, for a cable that goes out and back within the step,
    by the peak of the cubic Hermite interpolant of g_i (from g_i, g_dot_i at both ends).
    The first iterate is the interpolant's root, then Illinois regula falsi (Dowell &
    Jarratt, BIT 11, 1971) on the RK4 map until |f| <= EVENT_TOLERANCE."""
    n = uavs.shape[0]
    watched, crossing = flags[SLACK_WATCHED], flags[SLACK_CROSSING]
    g1, g_dot1 = values[SLACK_G_END], values[SLACK_G_DOT_END]
    x_tau, x_hi = states[SLACK_EVENT], states[SLACK_BRACKET]
    value, value_hi = values[SLACK_VALUE], values[SLACK_VALUE_BRACKET]
    multipliers = values[SLACK_MULTIPLIERS]
    any_watched = any_crossing = False
    f_lo = f_hi = -math.inf
    for i in range(n):
        scale = uavs[i, UAV_LENGTH_SQ]
        watched[i] = not taut[i] and not released[i] and g[i] / scale < 0.0
        crossing[i] = watched[i] and g1[i] / scale >= 0.0
        any_watched = any_watched or watched[i]
        any_crossing = any_crossing or crossing[i]
        if watched[i]:
            f_lo = max(f_lo, g[i] / scale)
            f_hi = max(f_hi, g1[i] / scale)
    if not any_watched:
        return -1.0
    if any_crossing:
        hi = h
        x_hi[:] = states[SLACK_END]
        for i in range(n):
            value_hi[i] = g1[i] / uavs[i, UAV_LENGTH_SQ]
    else:  # out and back within the step: the interpolant's peak
        hi = math.inf
        for i in range(n):
            scale = uavs[i, UAV_LENGTH_SQ]
            crossing[i] = watched[i] and g_dot[i] / scale > 0.0 and g_dot1[i] / scale < 0.0
            if crossing[i]:
                t, peak = hermite_peak(h, g[i] / scale, g_dot[i] / scale, g1[i] / scale,
                                       g_dot1[i] / scale)
                if peak >= 0.0:
                    hi = min(hi, t)
        if hi == math.inf:
            return -1.0
        f_hi = guard(x, wrenches, uavs, gusts, formation, taut, hi, watched, x_hi, value_hi,
                     work, cables, multipliers)
        if f_hi < 0.0:
            return -1.0
    guess = math.inf
    for i in range(n):
        if crossing[i]:
            scale = uavs[i, UAV_LENGTH_SQ]
            guess = min(guess, hermite_root(h, g[i] / scale, g_dot[i] / scale, g1[i] / scale,
                                            g_dot1[i] / scale))
    lo = 0.0
    tau, f_tau = hi, f_hi
    x_tau[:] = x_hi
    value[:] = value_hi
    side = 0
    for k in range(EVENT_ITERATIONS):
        if abs(f_tau) <= EVENT_TOLERANCE or hi - lo <= 1e-15 * h:
            break
        if k == 0 and lo < guess < hi:
            tau = guess
        else:
            tau = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        f_tau = guard(x, wrenches, uavs, gusts, formation, taut, tau, watched, x_tau, value,
                      work, cables, multipliers)
        if f_tau >= 0.0:  # the crossing is in [lo, tau]
            hi, f_hi = tau, f_tau
            x_hi[:] = x_tau
            value_hi[:] = value
            if side == 1:
                f_lo *= 0.5
            side = 1
        else:
            lo, f_lo = tau, f_tau
            if side == -1:
                f_hi *= 0.5
            side = -1
    if abs(f_tau) > EVENT_TOLERANCE:  # not converged (not seen): the bracket's far end
        tau = hi
        x_tau[:] = x_hi
        value[:] = value_hi
    snapping = flags[SLACK_SNAPPING]
    for i in range(n):
        snapping[i] = watched[i] and value[i] >= -EVENT_TOLERANCE
    return tau
