"""The arrays of B formations the compiled tick reads and writes, named once (the engine's
layout). Every field has the batch axis first; the formations of one batch share their shapes
(n UAVs, rotors per UAV, gusts, mission segments, virtual-constraint rows), not their values.

They are built from each scenario through the objects the per-process runtime uses (the
physics' `constant_arrays`, `MissionLeader`, `FormationFollower`, `ThrustBook`), so a
formation's numbers have one source. Units: SI, world frame z up (docs/conventions.md).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from multilift_control.controllers import LEADER_CONTROLLERS, ConstantRotorSpeed, MissionLeader
from multilift_control.faults import fault_mixers, target_schedule
from multilift_control.formation import FormationFollower
from multilift_control.laws.layout import (FOLLOWER_GRAVITY, FOLLOWER_MEMORY_SIZE,
                                           FOLLOWER_SIZE, FOLLOWER_TWO_ALPHA, REFERENCE_SIZE,
                                           ROW_SIZE, UAV_STATE_SIZE)
from multilift_control.runtime import ThrustBook
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import actuator_array, constant_arrays
from multilift_sim.physics.layout import UAV_MASS
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import cable_reach, initial_state, swing_sampling
from multilift_sim.schedules import event_array, sensor_arrays, wind_series
from multilift_sim.statistics import (FormationErrorStatistics, RunStatistics,
                                     TrackingStatistics)

# A leader's `control.mode` -> its code in `FormationArrays.leader_mode`: the index in the one
# registry of leader controllers (multilift_control.controllers.LEADER_CONTROLLERS)
LEADER_MODES = tuple(LEADER_CONTROLLERS)
MODE_CASCADE = LEADER_MODES.index('cascade')
MODE_CONSTANT = LEADER_MODES.index('constant_rotor_speed')

# `FormationMemory.status` of a formation
RUNNING = 0        # ticks left
FINISHED = 1       # reached its duration (the state at t_max is the last)
NOT_FINITE = 2     # stopped: the state became non-finite (Algorithm 1)
OFF_CONSTRAINT = 3  # stopped: a taut cable's |g| left constraint_tolerance (Algorithm 1)
OFF_RATE = 4       # stopped: a taut cable's |g_dot| left constraint_rate_tolerance


class FormationArrays(NamedTuple):
    """What does not change during a run, for B formations (first axis)."""
    # physics (multilift_sim.physics.layout slots)
    uavs: np.ndarray              # (B, n, UAV_COLUMNS)
    gusts: np.ndarray             # (B, k, GUST_COLUMNS)
    formation: np.ndarray         # (B, FORMATION_SCALARS)
    allocation: np.ndarray        # (B, n, 4, rotors): wrench per omega^2 (seed Eq. 2.14)
    actuators: np.ndarray         # (B, n, ACTUATOR_COLUMNS): each UAV's rotor lag and rate limit
    cable_lengths: np.ndarray     # (B, n) [m]
    slack: np.ndarray             # (B,) bool: cable_model slack (else rigid)
    events: np.ndarray            # (B, k, EVENT_COLUMNS): the scenario's events in time order
    wind_series: np.ndarray       # (B, ticks + 1 or 0, 3): the unsteady wind by tick [m/s]
    state_size: np.ndarray        # (B,) int: the state's length (a rigid payload adds its attitude)
    # what the controllers receive (`sensors:`; simulation.SensorArrays, physics.sensors)
    sensor_errors: np.ndarray     # (B, S or 0, n, MEASURED_COLUMNS): each sample's error
    sensor_delivered: np.ndarray  # (B, S or 0, n) bool: whether the sample arrives
    sensor_every: np.ndarray      # (B,) int: control ticks between two samples
    sensor_latency: np.ndarray    # (B,) int: control ticks from a sample to its arrival
    # time and Algorithm 1's tolerances
    physics_dt: np.ndarray        # (B,) [s]
    physics_steps: np.ndarray     # (B,) int: RK4 steps per control period
    period_ns: np.ndarray         # (B,) int: the control period [ns]
    tick_count: np.ndarray        # (B,) int: control periods of the run
    tolerances: np.ndarray        # (B, 2): |g| [m^2], |g_dot| [m^2/s]
    swing_every: np.ndarray       # (B,) int: the payload swing sampled every this many ticks
    reach: np.ndarray             # (B, n) [m]: each cable's reach for the swing's equilibrium
    # the leader (multilift_control.laws.layout slots)
    leader_mode: np.ndarray       # (B,) int: MODE_*
    cascade: np.ndarray           # (B, n, CASCADE_SIZE): every UAV's cascade constants
    fault_mixers: np.ndarray      # (B, k, rotors, MIXER_SIZE): faults.fault_mixers
    target_schedule: np.ndarray   # (B, S, 1 + m): (tick, targets) rows, faults.target_schedule
    mission: np.ndarray           # (B, MISSION_SIZE)
    segments: np.ndarray          # (B, s, SEGMENT_SIZE)
    mission_steps: np.ndarray     # (B, s + 1 or 0, STEP_SIZE)
    constant_speeds: np.ndarray   # (B, rotors) [rad/s]: MODE_CONSTANT's command
    constant_saturated: np.ndarray  # (B, rotors) bool
    # the followers (rows 1..n-1 of the per-UAV fields; row 0 unused)
    follower: np.ndarray          # (B, n, FOLLOWER_SIZE)
    masses: np.ndarray            # (B, n): M_f,r [kg]
    rows: np.ndarray              # (B, m, ROW_SIZE) int: the rows of g_vc
    law_p: np.ndarray             # (B, n, 3, m): a linear follower's P (zeros otherwise)
    law_q: np.ndarray             # (B, n, 3, 3n): its Q
    own_rows: np.ndarray          # (B, n) int: how many rows of g_vc involve UAV i
    thrust_coefficients: np.ndarray  # (B, n) [N s^2/rad^2]


class FormationMemory(NamedTuple):
    """What a tick changes, for B formations (first axis)."""
    state: np.ndarray             # (B, state_size): the formation state at the current tick
    taut: np.ndarray              # (B, n) bool: which cables are taut
    rotors: np.ndarray            # (B, n, rotors): rotor speeds [rad/s], NaN before a command
    effectiveness: np.ndarray     # (B, n, rotors): each rotor's share of its thrust, in [0, 1]
    released: np.ndarray          # (B, n) bool: the cables let go of for good (events)
    next_event: np.ndarray        # (B,) int: the row of the next event to come
    silent_until: np.ndarray      # (B, n) int: the first tick a silent controller is heard
    held: np.ndarray              # (B, n, rotors): the commands applied last [rad/s] (NaN: none)
    held_saturated: np.ndarray    # (B, n, rotors) bool: their saturation flags
    tick: np.ndarray              # (B,) int: control periods flown
    status: np.ndarray            # (B,) int: RUNNING, FINISHED or why it stopped
    worst_cable: np.ndarray       # (B,) int: the cable of a stop (from 0)
    worst_value: np.ndarray       # (B,): its |g| or |g_dot|
    g: np.ndarray                 # (B, n): g at the current tick [m^2]
    g_dot: np.ndarray             # (B, n): g_dot at the current tick [m^2/s]
    mixers: np.ndarray            # (B, n, rotors, MIXER_SIZE): every UAV's, faults reallocated
    targets: np.ndarray           # (B, m): the rows' targets, after the releases so far
    next_target: np.ndarray       # (B,) int: the row of target_schedule to come
    cascade_memory: np.ndarray    # (B, n, CASCADE_MEMORY_SIZE)
    follower_memory: np.ndarray   # (B, n, FOLLOWER_MEMORY_SIZE)
    thrusts: np.ndarray           # (B, n): the thrust book u_T,j [N]
    gust: np.ndarray              # (B, 3): the air velocity at the payload [m/s], world
    sensor_history: np.ndarray    # (B, latency + 1, n, MEASURED_COLUMNS): the last exact states
    sensor_seen: np.ndarray       # (B, n, MEASURED_COLUMNS): what the controllers hold (NaN: none)
    run: np.ndarray               # (B, run_size(n)): the run's figures (statistics RUN_*)
    tracking: np.ndarray          # (B, TRACKING_SIZE): the leader's tracking error
    formation_errors: np.ndarray  # (B, n, FORMATION_SIZE): each follower's (row 0 unused)


class TickRecord(NamedTuple):
    """What ticks leave for a bag: (ticks, B, ...) each; a tick's row k holds the state at the
    tick and the answers to it, and the tension of the integration that starts there."""
    states: np.ndarray            # (ticks, B, state_size): 2(6n + 3), + 7 with a rigid payload
    measured: np.ndarray          # (ticks, B, n, UAV_STATE_SIZE)
    speeds: np.ndarray            # (ticks, B, n, rotors) [rad/s]
    saturated: np.ndarray         # (ticks, B, n, rotors) bool
    setpoints: np.ndarray         # (ticks, B, n, 3) [rad]
    thrust: np.ndarray            # (ticks, B, n) [N]
    reference: np.ndarray         # (ticks, B, REFERENCE_SIZE): NaN without one
    errors: np.ndarray            # (ticks, B, n, rows): a follower's rows of g_vc, NaN after
    rates: np.ndarray             # (ticks, B, n, rows)
    tension: np.ndarray           # (ticks, B, n) [N]
    g: np.ndarray                 # (ticks, B, n) [m^2]
    g_dot: np.ndarray             # (ticks, B, n) [m^2/s]
    taut: np.ndarray              # (ticks, B, n) bool, at the tick's start
    gust: np.ndarray              # (ticks, B, 3): the air velocity at the payload [m/s], world


def not_flown(scenario: Scenario) -> str | None:
    """Why the engine does not fly `scenario` as FormationSimulator does, or None: it flies the
    seed's DAE (`simulation.integrator: baumgarte`, rigid or slack cables) with one rotor
    count for every UAV (the others go tick by tick: `headless.run_headless`)."""
    if scenario.simulation.integrator != 'baumgarte':
        return f'simulation.integrator is {scenario.simulation.integrator!r}, not baumgarte'
    rotor_counts = {u.vehicle.n_rotors for u in scenario.uavs}
    if len(rotor_counts) != 1:
        return f'UAVs of {len(rotor_counts)} rotor counts {sorted(rotor_counts)}'
    return None


def engine_flies(scenario: Scenario) -> bool:
    """Whether the engine flies `scenario` (`not_flown`)."""
    return not_flown(scenario) is None


def _formation_fields(scenario: Scenario) -> tuple[dict, dict]:
    """One formation's (FormationArrays fields, FormationMemory fields), without the batch
    axis."""
    n = scenario.n_uavs
    sim = scenario.simulation
    why = not_flown(scenario)
    if why is not None:
        raise ValueError(f'{scenario.name}: the engine does not fly it: {why}')
    params = scenario.formation_params()
    uavs, gusts, formation = constant_arrays(params)
    # the leader's cascade and path (a constant-speed leader: the ones it would fly, unused)
    mission_leader = MissionLeader(scenario, 0)
    path = mission_leader.path
    constant = ConstantRotorSpeed(scenario, 0).output
    followers = [FormationFollower.from_scenario(scenario, i) for i in range(1, n)]
    if len({(f.constants[FOLLOWER_GRAVITY], f.constants[FOLLOWER_TWO_ALPHA])
            for f in followers}) > 1:  # the tick computes their shared terms once
        raise ValueError(f'{scenario.name}: the followers differ in gravity or alpha_vc')
    cascades = [mission_leader.cascade] + [f.cascade for f in followers]
    rows = followers[0].constraints.rows if followers else np.zeros((0, ROW_SIZE), np.int64)
    m = rows.shape[0]
    follower = np.zeros((n, FOLLOWER_SIZE))
    follower_memory = np.zeros((n, FOLLOWER_MEMORY_SIZE))
    law_p, law_q = np.zeros((n, 3, m)), np.zeros((n, 3, 3 * n))
    own_rows = np.zeros(n, dtype=np.int64)
    for i, f in enumerate(followers, start=1):
        follower[i], follower_memory[i], own_rows[i] = f.constants, f.memory, len(f.rows)
        if f.law_p.shape == (3, m):  # linear rows (else the law solves each tick)
            law_p[i], law_q[i] = f.law_p, f.law_q
    model = FormationModel(params)
    sensors = sensor_arrays(scenario)
    sensor_history, sensor_seen = sensors.memory()
    arrays = dict(
        uavs=uavs, gusts=gusts, formation=formation, allocation=model.allocation,
        actuators=actuator_array(params),
        cable_lengths=np.array([u.cable_length for u in scenario.uavs], dtype=float),
        slack=scenario.cable_model == 'slack', events=event_array(scenario),
        wind_series=wind_series(scenario), state_size=initial_state(scenario).size,
        sensor_errors=sensors.errors, sensor_delivered=sensors.delivered,
        sensor_every=sensors.every, sensor_latency=sensors.latency,
        physics_dt=1.0 / sim.physics_rate, physics_steps=sim.physics_steps_per_tick,
        period_ns=int(round(1e9 / sim.control_rate)), tick_count=sim.tick_count,
        tolerances=np.array([sim.constraint_tolerance, sim.constraint_rate_tolerance]),
        swing_every=swing_sampling(n), reach=cable_reach(scenario),
        leader_mode=LEADER_MODES.index(scenario.control.mode),
        cascade=np.stack([c.constants for c in cascades]),
        fault_mixers=fault_mixers(scenario), target_schedule=target_schedule(scenario),
        mission=path.mission, segments=path.segments, mission_steps=path.steps,
        constant_speeds=np.asarray(constant.rotor_speeds, dtype=float),
        constant_saturated=np.asarray(constant.saturated, dtype=bool),
        follower=follower,
        masses=followers[0].masses if followers else np.array([uavs[0, UAV_MASS]]),
        rows=np.ascontiguousarray(rows, dtype=np.int64),
        law_p=law_p, law_q=law_q, own_rows=own_rows,
        thrust_coefficients=np.array([u.vehicle.thrust_coefficient for u in scenario.uavs],
                                     dtype=float))
    memory = dict(
        state=initial_state(scenario), taut=np.ones(n, dtype=bool), rotors=model.rotors,
        effectiveness=model.effectiveness, released=model.released, next_event=0,
        silent_until=np.zeros(n, dtype=np.int64),
        held=np.full(model.rotors.shape, math.nan),
        held_saturated=np.zeros(model.rotors.shape, dtype=bool), tick=0, status=RUNNING,
        worst_cable=0, worst_value=0.0, g=np.zeros(n), g_dot=np.zeros(n),
        mixers=np.stack([c.mixer.rows for c in cascades]),
        targets=followers[0].constraints.targets if followers else np.zeros(0), next_target=0,
        cascade_memory=np.stack([c.memory for c in cascades]),
        follower_memory=follower_memory,
        thrusts=np.array(ThrustBook(scenario).thrusts, dtype=float), gust=np.zeros(3),
        sensor_history=sensor_history, sensor_seen=sensor_seen,
        run=RunStatistics(n).run, tracking=TrackingStatistics().acc,
        formation_errors=np.stack([FormationErrorStatistics().acc for _ in range(n)]))
    return arrays, memory


def _stacked(name: str, values: list) -> np.ndarray:
    shapes = {np.shape(v) for v in values}
    if len(shapes) != 1:
        raise ValueError(f'the formations of a batch differ in the shape of {name}: '
                         f'{sorted(shapes)} (one batch: the same n, rotors, gusts, mission '
                         'segments and formation rows)')
    return np.ascontiguousarray(np.stack([np.asarray(v) for v in values]))


def _shape_key(fields: tuple[dict, dict]) -> tuple:
    arrays, memory = fields
    shared = tuple(float(arrays[name]) for name in ('physics_dt', 'physics_steps', 'period_ns'))
    return (shared, tuple(np.shape(v) for v in arrays.values()),
            tuple(np.shape(v) for v in memory.values()))


def shape_groups(scenarios: Sequence[Scenario]) -> list[list[int]]:
    """The scenarios' indices grouped into batches the engine can fly together (the same
    shapes of every array, control and physics rates), in order of first appearance."""
    groups: dict[tuple, list[int]] = {}
    for index, scenario in enumerate(scenarios):
        try:
            key = _shape_key(_formation_fields(scenario))
        except Exception:  # noqa: BLE001 - a batch of its own, whose flight says what failed
            key = ('alone', index)
        groups.setdefault(key, []).append(index)
    return list(groups.values())


def batch_arrays(scenarios: Sequence[Scenario]) -> tuple[FormationArrays, FormationMemory]:
    """The arrays of `scenarios` (B >= 1 of the same shape): (constants, initial memory)."""
    if not scenarios:
        raise ValueError('a batch needs at least one scenario')
    fields = [_formation_fields(s) for s in scenarios]
    arrays = FormationArrays(**{name: _stacked(name, [f[0][name] for f in fields])
                                for name in FormationArrays._fields})
    memory = FormationMemory(**{name: _stacked(name, [f[1][name] for f in fields])
                                for name in FormationMemory._fields})
    for field in (arrays.physics_dt, arrays.physics_steps, arrays.period_ns):
        if len(set(field.tolist())) != 1:
            raise ValueError('the formations of a batch must share control_rate and '
                             'physics_rate')
    return arrays, memory


def empty_record(arrays: FormationArrays, ticks: int) -> TickRecord:
    """A TickRecord for `ticks` ticks of the batch (ticks = 0: nothing recorded)."""
    batch, n, _ = arrays.uavs.shape
    rotors = arrays.allocation.shape[-1]
    rows = int(arrays.own_rows.max())
    size = int(arrays.state_size[0])
    return TickRecord(
        states=np.empty((ticks, batch, size)),
        measured=np.empty((ticks, batch, n, UAV_STATE_SIZE)),
        speeds=np.empty((ticks, batch, n, rotors)),
        saturated=np.empty((ticks, batch, n, rotors), dtype=bool),
        setpoints=np.empty((ticks, batch, n, 3)), thrust=np.empty((ticks, batch, n)),
        reference=np.empty((ticks, batch, REFERENCE_SIZE)),
        errors=np.full((ticks, batch, n, rows), math.nan),
        rates=np.full((ticks, batch, n, rows), math.nan),
        tension=np.empty((ticks, batch, n)), g=np.empty((ticks, batch, n)),
        g_dot=np.empty((ticks, batch, n)), taut=np.empty((ticks, batch, n), dtype=bool),
        gust=np.empty((ticks, batch, 3)))
