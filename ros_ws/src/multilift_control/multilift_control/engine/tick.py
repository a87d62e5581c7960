"""The compiled control tick of a formation and the loop over ticks and formations.

`formation_tick` is seed Algorithm 1 for one tick of formation b, in the order of the ROS graph
(the controllers' answers, as `multilift_control.runtime.answer_tick` gives them, then the
physics' half, `multilift_sim.physics.tick.advance`, which the simulator node steps as a
batch of one); `run_ticks` runs
up to `ticks` ticks of each of the B formations in one call. Every equation is a call into the
laws (`multilift_control.laws`) or the physics (`multilift_sim.physics`); the arrays are
`engine.arrays`' and their slots the layouts'.
"""
import math

import numpy as np

from multilift_control.controllers import compiled as controllers
from multilift_control.engine.arrays import RUNNING
from multilift_control.laws import jit
from multilift_control.laws.cascade import attitude_command
from multilift_control.laws.follower import lift_vectors
from multilift_control.laws.links import heard_formation
from multilift_control.laws.layout import REFERENCE_POSITION, REFERENCE_SIZE, UAV_POSITION
from multilift_control.laws.mixer import collective_thrust
from multilift_control.laws.reference import mission_reference
from multilift_sim.estimators.published import (ESTIMATE_COLUMNS, ESTIMATE_LINEAR,
                                                ESTIMATE_POSITION)
from multilift_sim.physics import tick as physics
from multilift_sim.physics.layout import REEL_LENGTH
from multilift_sim.physics.measurement import payload_position, payload_velocity
from multilift_sim.statistics.accumulators import formation_error_add, tracking_add
from multilift_sim.tick_arrays import PhysicsArrays, PhysicsMemory

# how many of the engine's fields are the physics' (they come first: engine.arrays._joined)
PHYSICS_ARRAY_FIELDS = len(PhysicsArrays._fields)
PHYSICS_MEMORY_FIELDS = len(PhysicsMemory._fields)

# the registered controllers' compiled dispatchers (multilift_control.controllers.compiled),
# rebound when a registry changes (controllers.compiled.refresh)
leader_answer = controllers.dispatchers().leader_answer
followers_answer = controllers.dispatchers().followers_answer
follower_answer = controllers.dispatchers().follower_answer


@jit(inline=True)
def physics_view(a, m):
    """The physics' own tuples (PhysicsArrays, PhysicsMemory) over the engine's arrays a and
    memory m: the compiled physics is then the one the simulator node steps, compiled once for
    both (a FormationArrays would be another type to numba, and its code compiled again)."""
    return PhysicsArrays(*a[:PHYSICS_ARRAY_FIELDS]), PhysicsMemory(*m[:PHYSICS_MEMORY_FIELDS])


@jit(inline=True)  # into formation_tick: no call passing the batch's tuples
def answer_formation(a, m, b, t, states, speeds, saturated, setpoints, thrust, reference,
                     errors, rates):
    """Every controller's answer to formation b's measured `states` (n, UAV_STATE_SIZE) at t
    [s], into speeds, saturated (n, rotors: a UAV's past its rotor count untouched, 0 and
    False), setpoints (n, 3), thrust (n,), reference (REFERENCE_SIZE,: NaN without one),
    errors and rates (n, rows: NaN past a follower's own): the leader's part first, then the
    thrust book (the leader's thrust to this state, the followers' to the previous one), then
    the followers' part (what their laws share, once), whose thrusts the book then notes."""
    n = states.shape[0]
    # a UAV's slots past its rotor count: 0 and False, whatever another formation left
    for i in range(n):
        for k in range(a.rotor_counts[b, i], speeds.shape[1]):
            speeds[i, k] = 0.0
            saturated[i, k] = False
    count = a.rotor_counts[b, 0]
    if m.payload_estimator_memory.shape[1]:  # the payload's estimate (payload_estimator:)
        estimate = m.payload_estimator_memory[b, 0]
        payload_at = estimate[ESTIMATE_POSITION:ESTIMATE_POSITION + 3]
        payload_moving = estimate[ESTIMATE_LINEAR:ESTIMATE_LINEAR + 3]  # world (point payload)
    else:
        payload_at, payload_moving = payload_position(m.state[b], n), payload_velocity(
            m.state[b], n)
    thrust[0] = leader_answer(
        a.leader_law[b], a.leader[b], m.leader_memory[b], a.cascade[b, 0],
        m.mixers[b, 0, :count], a.mission[b], a.segments[b], a.mission_steps[b], t, states,
        payload_at, payload_moving, speeds[0, :count], saturated[0, :count], setpoints[0],
        reference)
    if not math.isnan(reference[REFERENCE_POSITION]):
        tracking_add(m.tracking[b], reference[REFERENCE_POSITION:REFERENCE_POSITION + 3],
                     states[0, UAV_POSITION:UAV_POSITION + 3])
    thrusts = m.thrusts[b]
    thrusts[0] = collective_thrust(a.thrust_coefficients[b, 0], speeds[0])
    if a.link.shape[1]:  # each follower on what it hears of the leader (`comms:`)
        heard, heard_thrusts = np.empty_like(states), np.empty(n)
        for i in range(1, n):
            heard_formation(a.link[b], a.link_delivered[b, i], m.link_memory[b, i], m.tick[b],
                            i, states, thrusts, heard, heard_thrusts)
            count, rows_i = a.rotor_counts[b, i], a.own_rows[b, i]
            thrust[i] = follower_answer(
                a.follower_law[b], i, a.follower[b, i], m.follower_memory[b, i],
                a.cascade[b, i], m.mixers[b, i, :count], t, heard,
                lift_vectors(heard, heard_thrusts), a.masses[b], a.rows[b], m.targets[b],
                a.law_p[b, i], a.law_q[b, i], speeds[i, :count], saturated[i, :count],
                setpoints[i], errors[i, :rows_i], rates[i, :rows_i])
    else:
        followers_answer(a.follower_law[b], a.follower[b], m.follower_memory[b], a.cascade[b],
                         m.mixers[b], a.rotor_counts[b], a.own_rows[b], t, states,
                         lift_vectors(states, thrusts), a.masses[b], a.rows[b], m.targets[b],
                         a.law_p[b], a.law_q[b], speeds, saturated, setpoints, thrust, errors,
                         rates)
    for i in range(1, n):
        formation_error_add(m.formation_errors[b, i], errors[i, :a.own_rows[b, i]])
        thrusts[i] = collective_thrust(a.thrust_coefficients[b, i], speeds[i])


@jit
def tell_controllers(a, m, b, first):
    """The controllers told at once of the events of formation b from row `first` on (those
    the physics' tick just applied), as their kinds' reactions say (`multilift_control.
    reactions`): a UAV's mixer reallocated (`faults.fault_mixers`, `faults.mixer_uavs`: a
    rotor's fault); the formation's new offsets along `faults.target_schedule` (a cable's
    release), whose rows take effect at their tick."""
    for k in range(first, m.next_event[b]):
        if a.mixer_uavs[b, k] >= 0:
            m.mixers[b, a.mixer_uavs[b, k]] = a.fault_mixers[b, k]
    schedule = a.target_schedule[b]
    while m.next_target[b] < schedule.shape[0] and schedule[m.next_target[b], 0] <= m.tick[b]:
        m.targets[b, :] = schedule[m.next_target[b], 1:]
        m.next_target[b] += 1


@jit(inline=True)  # into formation_tick and run_commanded
def advance_formation(a, m, b, speeds, saturated, tension):
    """Formation b under rotor `speeds` (n, rotors) [rad/s] commanded over the control period
    (`multilift_sim.physics.tick.advance`: the physics' half, the one implementation), then
    its controllers told of the new tick's events (`tell_controllers`); the tension [N] into
    tension. The second half of a tick, whoever answered."""
    first = m.next_event[b]
    own, memory = physics_view(a, m)
    physics.advance(own, memory, b, speeds, saturated, tension)
    # only when there is something to tell: a call taking the batch's tuples counts every
    # array's reference in and out (a microsecond a tick)
    if m.next_event[b] > first or m.next_target[b] < a.target_schedule.shape[1]:
        tell_controllers(a, m, b, first)


@jit(inline=True)  # into run_ticks, its one caller: numba optimises the whole tick once
def formation_tick(a, m, b, states, speeds, saturated, setpoints, thrust, reference, errors,
                   rates, tension):
    """One control tick of formation b: measure (`measure`), answer, hold the speeds over the
    control period (RK4), then check; the tension T_i = 2 l_i lambda_i [N] at the tick into
    tension."""
    t = m.tick[b] * a.period_ns[b] * 1e-9
    own, memory = physics_view(a, m)
    physics.measure(own, memory, b, states)
    if a.controlled[b]:
        answer_formation(a, m, b, t, states, speeds, saturated, setpoints, thrust, reference,
                         errors, rates)
    else:  # every UAV's motion prescribed (physics.prescribed): no controller, no command
        speeds[:] = 0.0
        saturated[:] = False
        setpoints[:] = math.nan
        thrust[:] = 0.0
        reference[:] = math.nan
        errors[:] = math.nan
        rates[:] = math.nan
    advance_formation(a, m, b, speeds, saturated, tension)


@jit
def measure_all(a, m, states):
    """What every formation's controllers receive (B, n, UAV_STATE_SIZE) at its current tick
    (`measure`)."""
    own, memory = physics_view(a, m)
    for b in range(m.state.shape[0]):
        physics.measure(own, memory, b, states[b])


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
        if m.status[b] != RUNNING or not a.controlled[b]:
            continue
        t = m.tick[b] * a.period_ns[b] * 1e-9
        answer_formation(a, m, b, t, states[b], speeds[b], saturated[b], setpoints, thrust,
                         reference, errors, rates)


@jit
def mission_references(a, t, out):
    """Every formation's mission reference (B, REFERENCE_SIZE) at its time t (B,) [s]
    (`laws.reference.mission_reference`; a formation without a mission: NaN)."""
    for b in range(t.shape[0]):
        if not a.leader_tracks[b]:
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
    """Each formation b with which[b] at its initial state, before its first tick: the
    physics' start (`multilift_sim.physics.tick.start`: residuals, events, check) and its
    controllers told of the events at t = 0."""
    own, memory = physics_view(a, m)
    physics.start(own, memory, which)
    for b in range(m.state.shape[0]):
        if which[b]:
            tell_controllers(a, m, b, np.int64(0))  # int64: one compiled signature


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
    speeds = np.zeros((n, rotors))  # a UAV's slots past its rotor count stay 0 and False
    saturated = np.zeros((n, rotors), dtype=np.bool_)
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
                for i in range(n):
                    record.cable_length[k, b, i] = m.reel[b, i, REEL_LENGTH]
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
                if record.estimate.shape[3]:  # every UAV's estimate as published
                    record.estimate[k, b] = m.estimator_memory[b, 0, :, :ESTIMATE_COLUMNS]
                if record.payload_estimate.shape[2]:  # the payload's, as published
                    record.payload_estimate[k, b] = m.payload_estimator_memory[
                        b, 0, :ESTIMATE_COLUMNS]
            flown[b] += 1
    return flown
