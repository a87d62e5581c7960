"""Rotor actuators: each rotor's speed follows its command through a first-order lag with a
rate limit (issue 21; the seed's rotors answer at once), and its thrust and drag moment scale
by an effectiveness in [0, 1] (`allocation.rotor_wrenches`):

    d omega / dt = clip((omega_c - omega) / tau_m, -rate_max, rate_max)

with the command omega_c held over a control period (seed Algorithm 1). tau_m = 0: no lag (the
speed moves at the rate limit, or jumps without one). The rows of `actuators` (n,
ACTUATOR_COLUMNS) and the rotors' speeds (n, rotors) [rad/s] are `physics.layout`'s.

Within a control period the DAE's RK4 steps hold their wrenches (`formation_dae.rk4_step`), so
a lagging rotor enters each step with the speed whose square is the step's mean of omega^2
(Simpson's rule on the exact lag, `rotor_speed_at`, at the step's start, middle and end):
thrust and moment go as omega^2, so each step's impulse is the lag's to fourth order in the
step (docs/actuators.md). Instant rotors (every UAV's tau_m = 0, no rate limit) take the one
wrench of the command over the whole period, the seed's model to the bit.
"""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.allocation import rotor_wrenches
from multilift_sim.physics.formation_dae import integrate_period as rigid_period
from multilift_sim.physics.layout import (ACTUATOR_RATE_LIMIT, ACTUATOR_TIME_CONSTANT,
                                          FORMATION_SUBSTEPS,
                                          WRENCH_COLUMNS)
from multilift_sim.physics.slack_cables import integrate_period as slack_period


@jit
def rotor_speed_at(start, command, time_constant, rate_limit, s):
    """The exact solution omega(s) [rad/s] of the lag from omega(0) = start under a held
    command [rad/s]: time_constant tau_m [s] (0: none), rate_limit [rad/s^2] (inf: none),
    s [s] >= 0. While the gap |omega_c - omega| exceeds tau_m rate_max the rotor ramps at the
    rate limit; below it the gap decays as exp(-s / tau_m)."""
    gap = command - start
    if gap == 0.0:
        return command
    sign = 1.0 if gap > 0.0 else -1.0
    size = abs(gap)
    if time_constant <= 0.0:
        if not math.isfinite(rate_limit) or s * rate_limit >= size:
            return command
        return start + sign * rate_limit * s
    knee = time_constant * rate_limit  # the gap where the lag's rate equals the limit
    if size > knee:
        ramp_time = (size - knee) / rate_limit
        if s <= ramp_time:
            return start + sign * rate_limit * s
        return command - sign * knee * math.exp(-(s - ramp_time) / time_constant)
    return command - gap * math.exp(-s / time_constant)


@jit
def rotor_speeds_at(rotors, commands, actuators, s, out):
    """Every rotor's speed (n, rotors) [rad/s] at s [s] from `rotors` under `commands` (both
    (n, rotors) [rad/s]) into out (which may be rotors): `rotor_speed_at` with UAV i's row
    of `actuators`."""
    n, count = commands.shape
    for i in range(n):
        time_constant = actuators[i, ACTUATOR_TIME_CONSTANT]
        rate_limit = actuators[i, ACTUATOR_RATE_LIMIT]
        for r in range(count):
            out[i, r] = rotor_speed_at(rotors[i, r], commands[i, r], time_constant, rate_limit,
                                       s)


@jit
def held_speeds(rotors, commands, actuators, start, h, out):
    """The speeds (n, rotors) [rad/s] an RK4 step of h [s] from s = start [s] holds, into
    out: sqrt of the step's mean of omega^2 by Simpson's rule on the lag from `rotors`."""
    n, count = commands.shape
    for i in range(n):
        time_constant = actuators[i, ACTUATOR_TIME_CONSTANT]
        rate_limit = actuators[i, ACTUATOR_RATE_LIMIT]
        for r in range(count):
            begin = rotor_speed_at(rotors[i, r], commands[i, r], time_constant, rate_limit,
                                   start)
            middle = rotor_speed_at(rotors[i, r], commands[i, r], time_constant, rate_limit,
                                    start + 0.5 * h)
            end = rotor_speed_at(rotors[i, r], commands[i, r], time_constant, rate_limit,
                                 start + h)
            out[i, r] = math.sqrt((begin * begin + 4.0 * middle * middle + end * end) / 6.0)


@jit
def instant(actuators):
    """Whether every rotor reaches its command at once (no lag, no rate limit)."""
    for i in range(actuators.shape[0]):
        if actuators[i, ACTUATOR_TIME_CONSTANT] > 0.0 or math.isfinite(
                actuators[i, ACTUATOR_RATE_LIMIT]):
            return False
    return True


@jit
def substeps(formation):
    """RK4 sub-steps per physics step of a formation (its FORMATION_SUBSTEPS, at least 1)."""
    return max(1, int(formation[FORMATION_SUBSTEPS]))


@jit
def actuated_period(x, commands, rotors, actuators, effectiveness, allocation, uavs, gusts,
                    formation, taut, released, slack, dt, steps):
    """One control period of `steps` RK4 steps of dt [s] from state x under rotor `commands`
    (n, rotors) [rad/s] held, through the actuators: the DAE of rigid cables, or of cables
    that go slack (`slack`; taut (n,) bool updated, a `released` (n,) bool cable never taut
    again). `rotors` (n, rotors) holds each rotor's
    speed [rad/s] at x (NaN: never commanded, it starts at its first command) and is moved to
    the period's end; with instant rotors (`instant`) it is not kept (they are their
    commands). Each of the `steps` physics steps is taken as FORMATION_SUBSTEPS (k >= 1) RK4
    steps of dt / k (`substeps`): the same period k times finer, for a part that needs a
    faster rate than the physics' (k = 1: dt itself, to the bit). Returns (the state at the
    end, the multipliers [N/m] at x, g [m^2] and g_dot [m^2/s] at the end); x is not
    written."""
    n, count = commands.shape
    wrenches = np.empty((n, WRENCH_COLUMNS))
    k = substeps(formation)
    h = dt / k          # dt / 1.0 is dt: one sub-step leaves every bit as it was
    if instant(actuators):  # the rotors are their commands (`rotors` not kept)
        rotor_wrenches(allocation, commands, effectiveness, wrenches)
        if slack:
            return slack_period(x, wrenches, uavs, gusts, formation, taut, released, h,
                                steps * k)
        return rigid_period(x, wrenches, uavs, gusts, formation, taut, h, steps * k)
    for i in range(n):
        for r in range(count):
            if math.isnan(rotors[i, r]):
                rotors[i, r] = commands[i, r]
    speeds = np.empty((n, count))
    state = x.copy()
    first = np.zeros(n)
    g = np.zeros(n)
    g_dot = np.zeros(n)
    one = np.int64(1)  # not the literal 1: the periods compiled once for both paths' int64
    for step in range(steps * k):
        held_speeds(rotors, commands, actuators, step * h, h, speeds)
        rotor_wrenches(allocation, speeds, effectiveness, wrenches)
        if slack:
            state, multipliers, g, g_dot = slack_period(state, wrenches, uavs, gusts,
                                                        formation, taut, released, h, one)
        else:
            state, multipliers, g, g_dot = rigid_period(state, wrenches, uavs, gusts,
                                                        formation, taut, h, one)
        if step == 0:
            first[:] = multipliers
    rotor_speeds_at(rotors, commands, actuators, steps * dt, rotors)
    return state, first, g, g_dot
