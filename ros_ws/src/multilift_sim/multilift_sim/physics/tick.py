"""The physics' half of a control tick, compiled once for every caller: formation b of a batch
under the rotor commands its controllers gave, integrated over the control period, the
scenario's events of the new tick applied, and seed Algorithm 1's check (lines 10-13).

The one implementation of that half: the simulator node and `run_headless` step it as a
batch of one (`simulation.FormationSimulator`), the engine (`multilift_control.engine`),
campaigns and the learning environments as batches of B. `a` holds what a run does not
change and `m` what a tick changes (`multilift_sim.tick_arrays.PhysicsArrays` and
`PhysicsMemory`, or the engine's arrays, which carry the same fields); their slots are named
in `physics.layout` and `statistics.layout`. Units: SI, world frame z up.
"""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.actuators import actuated_period
from multilift_sim.physics.allocation import rotor_wrenches
from multilift_sim.physics.events import apply_events, held_commands
from multilift_sim.physics.formation_dae import air_velocity, residuals, solve
from multilift_sim.physics.attitude import quaternion_norm_error
from multilift_sim.physics.clearance import measure as measure_clearance
from multilift_sim.physics.layout import (CABLE_COLUMNS, FORMATION_CHAIN_LINKS, MEASURED_COLUMNS,
                                          SENSED_COLUMNS,
                                          FORMATION_ELASTIC,
                                          FORMATION_PRESCRIBED, FORMATION_TIME, FORMATION_WIND,
                                          FORMATION_WINCH, REEL_LENGTH, STATUS_CONTACT,
                                          STATUS_FINISHED, STATUS_QUATERNION,
                                          STATUS_NOT_FINITE, STATUS_OFF_CONSTRAINT,
                                          STATUS_OFF_RATE, STATUS_RUNNING,
                                          WORLD_CHECKED, WORLD_RECORD_CONTACT, WRENCH_COLUMNS)
from multilift_sim.physics.state_slots import (attitude_slot, payload_slot, rates_slot,
                                               uav_attitude_slot)
from multilift_sim.physics.measurement import measured_states
from multilift_sim.physics.prescribed import prescribe_state
from multilift_sim.estimators.estimation import estimated
from multilift_sim.physics.cable_sensing import cable_truths
from multilift_sim.physics.chain_cables import reeled_chain_residuals
from multilift_sim.physics.winch import period_uavs, reel_end
from multilift_sim.sensors.sensing import sensed_states
from multilift_sim.statistics.estimation import run_add_estimation
from multilift_sim.statistics.accumulators import (quaternion_fault, run_add_commands,
                                                   run_add_compression, run_add_gust_speed,
                                                   run_add_chains, run_add_reel, run_add_ropes,
                                                   run_add_slack,
                                                   run_add_tensions,
                                                   run_add_thrust_margin, run_check)
from multilift_sim.statistics.layout import (CHECK_G, CHECK_G_DOT, CHECK_NON_FINITE,
                                             CHECK_QUATERNION)


@jit
def period_wind(formation, series, tick, out):
    """The air's velocity everywhere over the period from `tick` [m/s], world, into out (3,):
    the steady wind (a formation's scalars, FORMATION_WIND) plus the tick's unsteady wind
    (series (ticks + 1, 3), `schedules.wind_series`; (0, 3): none, the steady wind as it is).
    The one place the wind is composed: the physics (`period_formation`), the simulator's
    `wind` and the bags' /formation/wind (`period_winds`) call it; a gust's 1-cosine field
    adds to it at a point (formation_dae.air_velocity)."""
    for j in range(3):
        out[j] = formation[FORMATION_WIND + j]
    if series.shape[0]:
        for j in range(3):
            out[j] += series[tick, j]


@jit
def period_winds(formation, series, out):
    """`period_wind` of every tick into out (ticks + 1, 3) [m/s], world."""
    for tick in range(out.shape[0]):
        period_wind(formation, series, tick, out[tick])


@jit
def period_formation(constants, series, tick):
    """A formation's scalars (FORMATION_*) for the period from `tick`, their wind
    `period_wind`'s; the `constants` themselves when the air is steady (series (0, 3)).
    (Arrays, not the batch's tuples: a call that takes those counts every array's
    reference in and out, a microsecond a tick.)"""
    if series.shape[0] == 0:
        return constants
    formation = constants.copy()
    period_wind(constants, series, tick, formation[FORMATION_WIND:FORMATION_WIND + 3])
    return formation


@jit
def timed_formation(formation, t):
    """The scalars at time t [s] (FORMATION_TIME) where some UAV's motion is prescribed
    (physics.prescribed: its drive is a function of time) or a cable reeled
    (physics.winch), a copy (the constants are not written); else `formation` itself."""
    if formation[FORMATION_PRESCRIBED] == 0.0 and formation[FORMATION_WINCH] == 0.0:
        return formation
    timed = formation.copy()
    timed[FORMATION_TIME] = t
    return timed


@jit
def stop_quaternion(a, m, b, body):
    """Formation b stopped as STATUS_QUATERNION: body `body` (UAV i, or n the rigid payload)
    in worst_cable, its quaternion's | |q| - 1 | in worst_value."""
    n = a.uavs.shape[1]
    m.status[b], m.worst_cable[b] = STATUS_QUATERNION, body
    m.worst_value[b] = quaternion_norm_error(
        m.state[b], uav_attitude_slot(n, body) if body < n else attitude_slot(n))


@jit(inline=True)  # into advance and start: a call passing the batch's tuples counts every array's
# reference in and out (`kernels.plain_reference_counts`)
def check(a, m, b):
    """Algorithm 1, lines 10-13, at formation b's current state (its g, g_dot), the run's
    figures accumulated (`statistics.accumulators.run_check`, then the gust at the payload):
    its status becomes STATUS_NOT_FINITE, _QUATERNION (the body in worst_cable: UAV i, or n
    the rigid payload; its | |q| - 1 | in worst_value), _OFF_CONSTRAINT or _OFF_RATE (the cable in
    worst_cable, its |g| or |g_dot|
    in worst_value) when Algorithm 1 stops it."""
    t = m.tick[b] * a.period_ns[b] * 1e-9
    x = m.state[b]
    status, cable = run_check(m.run[b], x, m.g[b], m.g_dot[b], m.taut[b], a.tolerances[b, 0],
                              a.tolerances[b, 1], t, m.tick[b], a.swing_every[b], a.reach[b])
    if status == CHECK_NON_FINITE:
        m.status[b] = STATUS_NOT_FINITE
        return
    if status == CHECK_QUATERNION:  # the body in worst_cable, | |q| - 1 | in worst_value
        stop_quaternion(a, m, b, cable)
        return
    payload = payload_slot(a.uavs.shape[1])
    gust_x, gust_y, gust_z = air_velocity(x[payload], x[payload + 1], a.gusts[b])
    m.gust[b, 0], m.gust[b, 1], m.gust[b, 2] = gust_x, gust_y, gust_z
    if a.gusts.shape[1]:
        run_add_gust_speed(m.run[b], math.sqrt(gust_x * gust_x + gust_y * gust_y
                                               + gust_z * gust_z))
    if status == CHECK_G:
        m.status[b], m.worst_cable[b], m.worst_value[b] = STATUS_OFF_CONSTRAINT, cable, abs(
            m.g[b, cable])
    elif status == CHECK_G_DOT:
        m.status[b], m.worst_cable[b], m.worst_value[b] = STATUS_OFF_RATE, cable, abs(
            m.g_dot[b, cable])


@jit(inline=True)  # into advance and start, as check
def clearance_check(a, m, b):
    """The clearances of formation b's current state (`physics.clearance.measure`) where its
    world is checked (WORLD_CHECKED: a `world:` section or vehicle.radius; else nothing, not
    even a call's cost): the least of each kind and the first contact into its memory; a
    contact stops it as STATUS_CONTACT unless world.on_contact is record."""
    if a.world[b, WORLD_CHECKED] == 0.0 or m.status[b] != STATUS_RUNNING:
        return
    touched = measure_clearance(a.world[b], a.obstacles[b], a.uav_radii[b], a.uavs[b],
                                m.state[b], m.tick[b] * a.period_ns[b] * 1e-9, m.clearance[b],
                                m.contact[b])
    if touched and a.world[b, WORLD_RECORD_CONTACT] == 0.0:
        m.status[b] = STATUS_CONTACT


@jit
def advance(a, m, b, speeds, saturated, tension):
    """Formation b under rotor `speeds` (n, rotors) [rad/s] (`saturated`: which are at a
    limit; a smaller UAV's padded with zeros) commanded over the control period (a silent
    controller's held: `physics.events.held_commands`; RK4 through the rotors' actuators:
    `physics.actuators`), the events of the new tick applied (`physics.events`), then checked
    (`check`); the tension T_i = 2 l_i lambda_i [N] at the tick it started from into
    tension. The second half of a tick, whoever answered. A state whose quaternion is no
    attitude (`statistics.accumulators.quaternion_fault`: set from outside; the model's own
    stay unit) is not integrated: the formation stops as STATUS_QUATERNION."""
    n = speeds.shape[0]
    body = quaternion_fault(m.state[b], n)
    if body >= 0:  # a state given from outside that no attitude is: not integrated (the
        stop_quaternion(a, m, b, body)  # step's renormalisation would hide it), stopped
        tension[:] = 0.0
        return
    period = a.period_ns[b] * 1e-9
    if a.estimator_models.shape[1]:  # the estimates of this tick against its state
        run_add_estimation(m.run[b], m.state[b], m.estimator_memory[b, 0],
                           m.payload_estimator_memory[b].reshape(-1))
    held_commands(speeds, saturated, m.tick[b], m.silent_until[b], m.held[b],
                  m.held_saturated[b])
    run_add_commands(m.run[b], m.held[b], m.held_saturated[b], period)
    run_add_thrust_margin(m.run[b], m.held[b], m.effectiveness[b], a.allocation[b],
                          a.rotor_speed_max[b])
    t0 = m.tick[b] * a.period_ns[b] * 1e-9
    formation = timed_formation(period_formation(a.formation[b], a.wind_series[b], m.tick[b]),
                                t0)
    # the UAVs' rows, with each reel's motion over the period where winches reel (physics.winch)
    uavs = period_uavs(a.uavs[b], m.reel[b], formation, t0, period)
    state, multipliers, g, g_dot = actuated_period(
        m.state[b], m.held[b], m.rotors[b], a.actuators[b], m.effectiveness[b], a.allocation[b],
        uavs, a.gusts[b], formation, m.taut[b], m.released[b], a.slack[b],
        a.physics_dt[b], a.physics_steps[b])
    for i in range(n):  # l_i at the tick (a reeled cable's now)
        tension[i] = 2.0 * m.reel[b, i, REEL_LENGTH] * multipliers[i]
        m.cable_tension[b, i] = tension[i]
    run_add_tensions(m.run[b], tension)
    run_add_compression(m.run[b], tension, period)
    if formation[FORMATION_ELASTIC] != 0.0:  # each rope's stretch and tension at the tick
        run_add_ropes(m.run[b], m.state[b], m.reel[b, :, REEL_LENGTH], tension)
    if formation[FORMATION_CHAIN_LINKS] != 0.0:  # each chain's sag (elastic: stretch) at the
        # tick
        run_add_chains(m.run[b], m.state[b], a.uavs[b],
                       int(formation[FORMATION_CHAIN_LINKS]) - 1, m.reel[b, :, REEL_LENGTH],
                       tension)
    if formation[FORMATION_WINCH] != 0.0:  # the reels at the new tick, g, g_dot of the
        # reeled lengths there
        reel_end(uavs, m.reel[b], (m.tick[b] + 1) * a.period_ns[b] * 1e-9, g, g_dot)
        if formation[FORMATION_CHAIN_LINKS] != 0.0:  # the worst links against l_i(t) / N
            reeled_chain_residuals(state, uavs, int(formation[FORMATION_CHAIN_LINKS]) - 1,
                                   m.reel[b], g, g_dot)
        run_add_reel(m.run[b], m.reel[b], a.cable_lengths[b])
    if a.slack[b]:
        run_add_slack(m.run[b], m.taut[b], period)
    if formation[FORMATION_PRESCRIBED] != 0.0:
        # the driven UAVs put back on their drives at the new tick (no drift; the payload
        # keeps what it integrated against them): physics.prescribed
        prescribe_state(state, n, formation, (m.tick[b] + 1) * a.period_ns[b] * 1e-9)
        residuals(state, a.uavs[b], g, g_dot)
    m.state[b, :] = state
    m.g[b, :] = g
    m.g_dot[b, :] = g_dot
    m.tick[b] += 1
    m.next_event[b] = apply_events(a.events[b], m.next_event[b], m.tick[b], m.effectiveness[b],
                                   m.taut[b], m.released[b], m.silent_until[b], m.reel[b])
    check(a, m, b)
    clearance_check(a, m, b)
    if m.status[b] == STATUS_RUNNING and m.tick[b] >= a.tick_count[b]:
        m.status[b] = STATUS_FINISHED


@jit
def start(a, m, which):
    """The residuals, events and check of each formation b with which[b] at its initial state
    (before its first tick)."""
    for b in range(m.state.shape[0]):
        if not which[b]:
            continue
        residuals(m.state[b], a.uavs[b], m.g[b], m.g_dot[b])
        m.next_event[b] = apply_events(a.events[b], m.next_event[b], m.tick[b],
                                       m.effectiveness[b], m.taut[b], m.released[b],
                                       m.silent_until[b], m.reel[b])
        check(a, m, b)
        clearance_check(a, m, b)
        if m.status[b] == STATUS_RUNNING and m.tick[b] >= a.tick_count[b]:
            m.status[b] = STATUS_FINISHED


@jit(inline=True)  # into its callers (the engine's tick, measure_all), as check
def measure(a, m, b, states):
    """What formation b's controllers receive of its UAVs at its current tick, into states
    (n, MEASURED_COLUMNS): the measured states (seed Eq. 2.7), with `sensors:` as its sensor
    models deliver them from the truth (the measured states and the cables', `physics.
    cable_sensing.cable_truths`; `sensors.sensing.sensed_states`), with `estimator:` as it
    estimates them, then with `payload_estimator:` the payload's estimate into its memory
    (both `estimators.estimation.estimated`); the same result however often it is called at
    one tick."""
    measured_states(m.state[b], states.shape[0], states)
    if a.sensor_models.shape[1]:
        truth = np.empty((states.shape[0], SENSED_COLUMNS))
        truth[:, :MEASURED_COLUMNS] = states[:, :MEASURED_COLUMNS]
        cable_truths(m.state[b], a.uavs[b], m.cable_tension[b], truth)
        sensed_states(a.sensor_models[b], a.sensor_constants[b], a.sensor_draws[b],
                      m.sensor_memory[b], m.tick[b], truth, states)
    if a.estimator_models.shape[1] or a.payload_estimator_models.shape[1]:
        estimated(a.estimator_models[b], a.estimator_constants[b],
                  a.payload_estimator_models[b], a.payload_estimator_constants[b],
                  m.sensor_memory[b], m.estimator_memory[b], m.payload_estimator_memory[b],
                  m.tick[b], states)


@jit
def tension_at(a, m, b, speeds, tension):
    """The cable tensions T_i = 2 l_i lambda_i [N] at formation b's current state under rotor
    `speeds` (n, rotors) [rad/s] held (the multipliers of the DAE's solve, as the first stage
    of `advance` computes them; a slack cable's 0, a taut one's not below 0), into tension
    (n,): the tension of a tick the run ends at, which no integration leaves."""
    n = speeds.shape[0]
    wrenches = np.empty((n, WRENCH_COLUMNS))
    rotor_wrenches(a.allocation[b], speeds, m.effectiveness[b], wrenches)
    x = m.state[b]
    acc = np.empty(x.shape[0] - rates_slot(n))  # q_ddot, then the attitude blocks' rates
    multipliers = np.empty(n)
    t = m.tick[b] * a.period_ns[b] * 1e-9
    formation = timed_formation(period_formation(a.formation[b], a.wind_series[b], m.tick[b]),
                                t)
    uavs = period_uavs(a.uavs[b], m.reel[b], formation, t, a.period_ns[b] * 1e-9)
    solve(x, wrenches, uavs, a.gusts[b], formation, m.taut[b], acc, multipliers,
          np.empty((n, CABLE_COLUMNS)))
    for i in range(n):
        value = multipliers[i]
        if a.slack[b]:
            value = max(value, 0.0) if m.taut[b, i] else 0.0
        tension[i] = 2.0 * m.reel[b, i, REEL_LENGTH] * value
