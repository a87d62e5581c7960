"""The compiled control tick of a formation and the loop over ticks and formations.

`formation_tick` is seed Algorithm 1 for one tick of formation b, in the order of the ROS graph
(`multilift_control.runtime.answer_tick`, then `FormationSimulator.advance`); `run_ticks` runs
up to `ticks` ticks of each of the B formations in one call. Every equation is a call into the
laws (`multilift_control.laws`) or the physics (`multilift_sim.physics`); the arrays are
`engine.arrays`' and their slots the layouts'.
"""
import math

import numpy as np

from multilift_control.engine.arrays import (FINISHED, MODE_CASCADE, NOT_FINITE, OFF_CONSTRAINT,
                                             OFF_RATE, RUNNING)
from multilift_control.laws import jit
from multilift_control.laws.cascade import attitude_command, leader_update
from multilift_control.laws.follower import follower_update, formation_terms, lift_vectors
from multilift_control.laws.layout import REFERENCE_POSITION, REFERENCE_SIZE, UAV_POSITION
from multilift_control.laws.mixer import collective_thrust
from multilift_control.laws.reference import mission_reference
from multilift_sim.physics.actuators import actuated_period
from multilift_sim.physics.events import apply_events, held_commands
from multilift_sim.physics.formation_dae import air_velocity, residuals
from multilift_sim.physics.layout import (EVENT_KIND, EVENT_UAV, FORMATION_WIND,
                                          KIND_ROTOR_EFFECTIVENESS)
from multilift_sim.physics.measurement import (measured_states, payload_position,
                                               payload_velocity)
from multilift_sim.physics.sensors import sensed_states
from multilift_sim.statistics.accumulators import (formation_error_add, run_add_commands,
                                                   run_add_gust_speed, run_add_slack,
                                                   run_add_tensions, run_check, tracking_add)
from multilift_sim.statistics.layout import CHECK_G, CHECK_G_DOT, CHECK_NON_FINITE


@jit
def answer_formation(a, m, b, t, states, speeds, saturated, setpoints, thrust, reference,
                     errors, rates):
    """Every controller's answer to formation b's measured `states` (n, UAV_STATE_SIZE) at t
    [s], into speeds, saturated (n, rotors), setpoints (n, 3), thrust (n,), reference
    (REFERENCE_SIZE,: NaN without one), errors and rates (n, rows: NaN past a follower's own):
    the leader first, then the thrust book (the leader's thrust to this state, the followers'
    to the previous one), then the followers (what their laws share, once: `formation_terms`),
    whose thrusts the book then notes."""
    n = states.shape[0]
    if a.leader_mode[b] == MODE_CASCADE:
        s, sat, setpoint, lift, ref = leader_update(
            a.cascade[b, 0], m.mixers[b, 0], m.cascade_memory[b, 0], a.mission[b],
            a.segments[b], a.mission_steps[b], t, states, payload_position(m.state[b], n),
            payload_velocity(m.state[b], n))
        for k in range(REFERENCE_SIZE):
            reference[k] = ref[k]
        tracking_add(m.tracking[b], ref[REFERENCE_POSITION:REFERENCE_POSITION + 3],
                     states[0, UAV_POSITION:UAV_POSITION + 3])
    else:  # constant rotor speed: the same command every tick, no reference
        s, sat = a.constant_speeds[b], a.constant_saturated[b]
        setpoint = np.zeros(3)
        lift = collective_thrust(a.thrust_coefficients[b, 0], s)
        for k in range(REFERENCE_SIZE):
            reference[k] = math.nan
    speeds[0, :] = s
    saturated[0, :] = sat
    setpoints[0, :] = setpoint
    thrust[0] = lift
    thrusts = m.thrusts[b]
    thrusts[0] = collective_thrust(a.thrust_coefficients[b, 0], speeds[0])
    vectors = lift_vectors(states, thrusts)
    # what every follower's law shares, once (O(n)), then each follower's own step; the
    # constants of any follower (the last; n = 1: the unused row 0)
    terms = formation_terms(a.follower[b, n - 1], a.masses[b], a.rows[b], m.targets[b], states,
                            vectors)
    for i in range(1, n):
        s, sat, setpoint, lift, own_errors, own_rates = follower_update(
            a.follower[b, i], a.masses[b], a.rows[b], m.targets[b], a.law_p[b, i],
            a.law_q[b, i], i, m.follower_memory[b, i], t, states, vectors, terms,
            a.cascade[b, i], m.mixers[b, i])
        speeds[i, :] = s
        saturated[i, :] = sat
        setpoints[i, :] = setpoint
        thrust[i] = lift
        for k in range(own_errors.shape[0]):
            errors[i, k] = own_errors[k]
            rates[i, k] = own_rates[k]
        formation_error_add(m.formation_errors[b, i], own_errors)
    for i in range(1, n):
        thrusts[i] = collective_thrust(a.thrust_coefficients[b, i], speeds[i])


@jit
def check(a, m, b):
    """Algorithm 1, lines 10-13, at formation b's current state (its g, g_dot), the run's
    figures accumulated (`statistics.accumulators.run_check`, then the gust at the payload, as
    `FormationSimulator._check`): its status becomes NOT_FINITE, OFF_CONSTRAINT or OFF_RATE
    (the cable in worst_cable, its |g| or |g_dot| in worst_value) when Algorithm 1 stops it."""
    t = m.tick[b] * a.period_ns[b] * 1e-9
    x = m.state[b]
    status, cable = run_check(m.run[b], x, m.g[b], m.g_dot[b], m.taut[b], a.tolerances[b, 0],
                              a.tolerances[b, 1], t, m.tick[b], a.swing_every[b], a.reach[b])
    if status == CHECK_NON_FINITE:
        m.status[b] = NOT_FINITE
        return
    payload = 6 * a.uavs.shape[1]
    gust_x, gust_y, gust_z = air_velocity(x[payload], x[payload + 1], a.gusts[b])
    m.gust[b, 0], m.gust[b, 1], m.gust[b, 2] = gust_x, gust_y, gust_z
    if a.gusts.shape[1]:
        run_add_gust_speed(m.run[b], math.sqrt(gust_x * gust_x + gust_y * gust_y
                                               + gust_z * gust_z))
    if status == CHECK_G:
        m.status[b], m.worst_cable[b], m.worst_value[b] = OFF_CONSTRAINT, cable, abs(
            m.g[b, cable])
    elif status == CHECK_G_DOT:
        m.status[b], m.worst_cable[b], m.worst_value[b] = OFF_RATE, cable, abs(
            m.g_dot[b, cable])


@jit
def events(a, m, b):
    """The scenario's events of formation b's current tick: in the physics
    (`physics.events.apply_events`), and the controllers told of a fault at once (a rotor's:
    its UAV's mixer reallocated, `faults.fault_mixers`; a cable's release: the formation's new
    offsets, on their way along `faults.target_schedule`)."""
    first = m.next_event[b]
    m.next_event[b] = apply_events(a.events[b], first, m.tick[b], m.effectiveness[b], m.taut[b],
                                   m.released[b], m.silent_until[b])
    for k in range(first, m.next_event[b]):
        if int(a.events[b, k, EVENT_KIND]) == KIND_ROTOR_EFFECTIVENESS:
            m.mixers[b, int(a.events[b, k, EVENT_UAV])] = a.fault_mixers[b, k]
    schedule = a.target_schedule[b]
    while m.next_target[b] < schedule.shape[0] and schedule[m.next_target[b], 0] <= m.tick[b]:
        m.targets[b, :] = schedule[m.next_target[b], 1:]
        m.next_target[b] += 1


@jit
def advance_formation(a, m, b, speeds, saturated, tension):
    """Formation b under rotor `speeds` (n, rotors) [rad/s] (`saturated`: which are at a
    limit) commanded over the control period (a silent controller's held: `physics.events`;
    RK4, the rotors through their actuators:
    `physics.actuators`), the events of the new tick applied (`physics.events`), then
    checked; the tension T_i = 2 l_i lambda_i
    [N] at the tick into tension. The second half of a tick, whoever answered."""
    n = speeds.shape[0]
    period = a.period_ns[b] * 1e-9
    held_commands(speeds, saturated, m.tick[b], m.silent_until[b], m.held[b],
                  m.held_saturated[b])
    run_add_commands(m.run[b], m.held[b], m.held_saturated[b], period)
    formation = a.formation[b]
    if a.wind_series.shape[1]:  # the steady wind plus the tick's unsteady wind, over the period
        formation = formation.copy()
        for j in range(3):
            formation[FORMATION_WIND + j] += a.wind_series[b, m.tick[b], j]
    state, multipliers, g, g_dot = actuated_period(
        m.state[b], m.held[b], m.rotors[b], a.actuators[b], m.effectiveness[b], a.allocation[b],
        a.uavs[b], a.gusts[b], formation, m.taut[b], m.released[b], a.slack[b],
        a.physics_dt[b], a.physics_steps[b])
    for i in range(n):
        tension[i] = 2.0 * a.cable_lengths[b, i] * multipliers[i]
    run_add_tensions(m.run[b], tension)
    if a.slack[b]:
        run_add_slack(m.run[b], m.taut[b], period)
    m.state[b, :] = state
    m.g[b, :] = g
    m.g_dot[b, :] = g_dot
    m.tick[b] += 1
    events(a, m, b)
    check(a, m, b)
    if m.status[b] == RUNNING and m.tick[b] >= a.tick_count[b]:
        m.status[b] = FINISHED


@jit
def measure(a, m, b, states):
    """What formation b's controllers receive of its UAVs at its current tick, into states
    (n, UAV_STATE_SIZE): the measured states (seed Eq. 2.7), with `sensors:` as its sensors
    deliver them (`physics.sensors.sensed_states`)."""
    measured_states(m.state[b], states.shape[0], states)
    if a.sensor_errors.shape[1]:
        sensed_states(states, m.tick[b], a.sensor_errors[b], a.sensor_delivered[b],
                      a.sensor_every[b], a.sensor_latency[b], m.sensor_history[b],
                      m.sensor_seen[b])


@jit
def formation_tick(a, m, b, states, speeds, saturated, setpoints, thrust, reference, errors,
                   rates, tension):
    """One control tick of formation b: measure (`measure`), answer, hold the speeds over the
    control period (RK4), then check; the tension T_i = 2 l_i lambda_i [N] at the tick into
    tension."""
    t = m.tick[b] * a.period_ns[b] * 1e-9
    measure(a, m, b, states)
    answer_formation(a, m, b, t, states, speeds, saturated, setpoints, thrust, reference,
                     errors, rates)
    advance_formation(a, m, b, speeds, saturated, tension)


@jit
def measure_all(a, m, states):
    """What every formation's controllers receive (B, n, UAV_STATE_SIZE) at its current tick
    (`measure`)."""
    for b in range(m.state.shape[0]):
        measure(a, m, b, states[b])


@jit
def answer_all(a, m, states, speeds, saturated):
    """The scenario's own controllers' answers (speeds, saturated: (B, n, rotors)) to every
    running formation's measured `states` (B, n, UAV_STATE_SIZE) at its current tick, as a
    tick gives them (their memories and the run's tracking figures advance with it)."""
    n = a.uavs.shape[1]
    rows = m.targets.shape[1]
    setpoints = np.empty((n, 3))
    thrust = np.empty(n)
    reference = np.empty(REFERENCE_SIZE)
    errors = np.full((n, max(rows, 1)), math.nan)
    rates = np.full((n, max(rows, 1)), math.nan)
    for b in range(m.state.shape[0]):
        if m.status[b] != RUNNING:
            continue
        t = m.tick[b] * a.period_ns[b] * 1e-9
        answer_formation(a, m, b, t, states[b], speeds[b], saturated[b], setpoints, thrust,
                         reference, errors, rates)


@jit
def mission_references(a, t, out):
    """Every formation's mission reference (B, REFERENCE_SIZE) at its time t (B,) [s]
    (`laws.reference.mission_reference`; a formation without a mission: NaN)."""
    for b in range(t.shape[0]):
        if a.leader_mode[b] != MODE_CASCADE:
            out[b, :] = math.nan
            continue
        out[b, :] = mission_reference(a.mission[b], a.segments[b], a.mission_steps[b], t[b])


@jit
def attitude_commands(a, m, states, setpoints, thrust, speeds, saturated):
    """Every UAV's rotor speeds and saturation (B, n, rotors) holding attitude `setpoints`
    (B, n, 3: roll, pitch, yaw [rad]) with collective `thrust` (B, n) [N] from its measured
    `states` (B, n, UAV_STATE_SIZE): each UAV's cascade inner half (`attitude_command`)."""
    for b in range(states.shape[0]):
        for i in range(states.shape[1]):
            s, sat = attitude_command(a.cascade[b, i], m.mixers[b, i], states[b, i],
                                      setpoints[b, i], thrust[b, i])
            speeds[b, i, :] = s
            saturated[b, i, :] = sat


@jit
def run_commanded(a, m, speeds, saturated, which, tension):
    """One control tick of every running formation b with which[b] under the given rotor
    speeds (B, n, rotors) [rad/s] (`advance_formation`); the tensions (B, n) [N] into
    tension."""
    for b in range(m.state.shape[0]):
        if which[b] and m.status[b] == RUNNING:
            advance_formation(a, m, b, speeds[b], saturated[b], tension[b])


@jit
def start(a, m, which):
    """The residuals, events and check of each formation b with which[b] at its initial state
    (before its first tick)."""
    for b in range(m.state.shape[0]):
        if not which[b]:
            continue
        residuals(m.state[b], a.uavs[b], m.g[b], m.g_dot[b])
        events(a, m, b)
        check(a, m, b)
        if m.status[b] == RUNNING and m.tick[b] >= a.tick_count[b]:
            m.status[b] = FINISHED


@jit
def run_ticks(a, m, ticks, record):
    """Up to `ticks` ticks of each running formation (fewer where one finishes or stops);
    `record` (engine.arrays.TickRecord) takes tick k of the call at row k when it has rows.
    Returns the ticks flown per formation (B,)."""
    batch = m.state.shape[0]
    n = a.uavs.shape[1]
    rotors = a.allocation.shape[3]
    recording = record.speeds.shape[0] > 0
    flown = np.zeros(batch, dtype=np.int64)
    states = np.empty((n, record.measured.shape[3]))
    speeds = np.empty((n, rotors))
    saturated = np.empty((n, rotors), dtype=np.bool_)
    setpoints = np.empty((n, 3))
    thrust = np.empty(n)
    reference = np.empty(REFERENCE_SIZE)
    errors = np.full((n, record.errors.shape[3]), math.nan)
    rates = np.full((n, record.errors.shape[3]), math.nan)
    tension = np.empty(n)
    for b in range(batch):
        for k in range(ticks):
            if m.status[b] != RUNNING:
                break
            if recording:
                record.states[k, b, :] = m.state[b]
                record.g[k, b, :] = m.g[b]
                record.g_dot[k, b, :] = m.g_dot[b]
                record.taut[k, b, :] = m.taut[b]
                record.gust[k, b, :] = m.gust[b]
            formation_tick(a, m, b, states, speeds, saturated, setpoints, thrust, reference,
                           errors, rates, tension)
            if recording:
                record.measured[k, b] = states
                record.speeds[k, b] = speeds
                record.saturated[k, b] = saturated
                record.setpoints[k, b] = setpoints
                record.thrust[k, b] = thrust
                record.reference[k, b] = reference
                record.errors[k, b] = errors
                record.rates[k, b] = rates
                record.tension[k, b] = tension
            flown[b] += 1
    return flown
