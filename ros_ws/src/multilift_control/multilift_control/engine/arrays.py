"""The arrays of B formations the compiled tick reads and writes, named once (the engine's
layout). Every field has the batch axis first; the formations of one batch share their shapes
(n UAVs, the most rotors of a UAV, gusts, mission segments, virtual-constraint rows, the
controllers' arrays), not their values.

They are built from each scenario by the physics' `multilift_sim.tick_arrays.physics_fields`
and by the controllers' parts (`multilift_control.controllers`: each part's `arrays`, the
vehicles' cascades, the formation's rows) and `ThrustBook`, as the per-process runtime builds
them, so a formation's numbers have one source. Units: SI, world frame z up
(docs/conventions.md).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from multilift_control.controllers import (FOLLOWER_CONTROLLERS, LEADER_CONTROLLERS,
                                           LeaderController, follower_part, formation_rows,
                                           law_index, leader_part, vehicle_cascade)
from multilift_control.faults import fault_mixers, mixer_uavs, target_schedule
from multilift_control.laws.layout import MIXER_SIZE, REFERENCE_SIZE, ROW_SIZE, UAV_STATE_SIZE
from multilift_control.runtime import ThrustBook
from multilift_sim.estimators.published import ESTIMATE_COLUMNS
from multilift_sim.links.radio import link_arrays
from multilift_sim.physics.layout import (STATUS_FINISHED, STATUS_NOT_FINITE,
                                          STATUS_OFF_CONSTRAINT, STATUS_OFF_RATE, STATUS_RUNNING)
from multilift_sim.scenario import Scenario
from multilift_sim.statistics import FormationErrorStatistics, TrackingStatistics
from multilift_sim.tick_arrays import PhysicsArrays, PhysicsMemory, physics_fields, stacked

# `FormationMemory.status` of a formation (multilift_sim.physics.layout STATUS_*)
RUNNING = STATUS_RUNNING
FINISHED = STATUS_FINISHED
NOT_FINITE = STATUS_NOT_FINITE
OFF_CONSTRAINT = STATUS_OFF_CONSTRAINT
OFF_RATE = STATUS_OFF_RATE


class ControlArrays(NamedTuple):
    """What the controllers keep constant during a run, for B formations (first axis):
    the engine's arrays after the physics' (`FormationArrays`). A UAV with fewer rotors than
    the formation's most has its rows padded: its rotors' slots past its count are never
    answered (their speeds 0, not saturated: what the physics pads its commands with)."""
    rotor_counts: np.ndarray      # (B, n) int: each UAV's rotors
    controlled: np.ndarray        # (B,) bool: whether its controllers answer (not when every
    #                               UAV's motion is prescribed: its commands stay 0, unused)
    cascade: np.ndarray           # (B, n, CASCADE_SIZE): every UAV's cascade constants
    fault_mixers: np.ndarray      # (B, k, rotors, MIXER_SIZE): faults.fault_mixers
    mixer_uavs: np.ndarray        # (B, k) int: the UAV each event's mixer is of (-1: none)
    target_schedule: np.ndarray   # (B, S, 1 + m): (tick, targets) rows, faults.target_schedule
    # the leader: its part (multilift_control.controllers) and the mission it may track
    leader_law: np.ndarray        # (B,) int: its part's index in LEADER_CONTROLLERS
    leader_tracks: np.ndarray     # (B,) bool: its part's TRACKS_MISSION
    leader: np.ndarray            # (B, its part's constants)
    mission: np.ndarray           # (B, MISSION_SIZE)
    segments: np.ndarray          # (B, s, SEGMENT_SIZE)
    mission_steps: np.ndarray     # (B, s + 1 or 0, STEP_SIZE)
    # the followers: their part (rows 1..n-1 of the per-UAV fields; row 0 unused)
    follower_law: np.ndarray      # (B,) int: their part's index in FOLLOWER_CONTROLLERS
    follower: np.ndarray          # (B, n, its constants)
    masses: np.ndarray            # (B, n): M_f,r [kg]
    rows: np.ndarray              # (B, m, ROW_SIZE) int: the rows of g_vc
    law_p: np.ndarray             # (B, n, 3, m): a follower's first matrix (linear VC: P)
    law_q: np.ndarray             # (B, n, 3, 3n): its second (linear VC: Q)
    own_rows: np.ndarray          # (B, n) int: how many rows of g_vc involve UAV i
    thrust_coefficients: np.ndarray  # (B, n) [N s^2/rad^2]
    # the followers' links from the leader (`comms:`, multilift_sim.links.radio): (B, 0) and
    # (B, n, 0) without
    link: np.ndarray              # (B, LINK_COLUMNS)
    link_delivered: np.ndarray    # (B, n, ticks + 1): 1.0 where follower i gets that packet


class ControlMemory(NamedTuple):
    """What a tick changes in the controllers, for B formations (first axis)."""
    mixers: np.ndarray            # (B, n, rotors, MIXER_SIZE): every UAV's, faults reallocated
    targets: np.ndarray           # (B, m): the rows' targets, after the releases so far
    next_target: np.ndarray       # (B,) int: the row of target_schedule to come
    leader_memory: np.ndarray     # (B, the leader part's memory)
    follower_memory: np.ndarray   # (B, n, the follower part's memory)
    thrusts: np.ndarray           # (B, n): the thrust book u_T,j [N]
    tracking: np.ndarray          # (B, TRACKING_SIZE): the leader's tracking error
    formation_errors: np.ndarray  # (B, n, FORMATION_SIZE): each follower's (row 0 unused)
    link_memory: np.ndarray       # (B, n, M): each follower's link (row 0 unused)


def _joined(name: str, *parts: type) -> type:
    """A NamedTuple of every field of `parts` in order (the physics' first, so the compiled
    `multilift_sim.physics.tick` reads the engine's arrays as its own)."""
    return NamedTuple(name, [field for part in parts for field in part.__annotations__.items()])


# What does not change during a run (PhysicsArrays, then ControlArrays), and what a tick
# changes (PhysicsMemory, then ControlMemory), for B formations
FormationArrays = _joined('FormationArrays', PhysicsArrays, ControlArrays)
FormationMemory = _joined('FormationMemory', PhysicsMemory, ControlMemory)


class TickRecord(NamedTuple):
    """What ticks leave for a bag: (ticks, B, ...) each; a tick's row k holds the state at the
    tick and the answers to it, and the tension of the integration that starts there."""
    states: np.ndarray            # (ticks, B, state_size): docs/conventions.md' x
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
    cable_length: np.ndarray      # (ticks, B, n) [m]: each cable's, reeled by a winch or not
    # (ticks, B, n, ESTIMATE_COLUMNS) each UAV's estimate as /uav{i}/estimate carries it
    # (estimators.published); (ticks, B, n, 0) without an estimator
    estimate: np.ndarray


def _padded(rows: np.ndarray, rotors: int) -> np.ndarray:
    """Mixer rows (k, MIXER_SIZE) padded with zero rows to `rotors`."""
    out = np.zeros((rotors, MIXER_SIZE))
    out[:rows.shape[0]] = rows
    return out


def formation_fields(scenario: Scenario) -> tuple[dict, dict]:
    """One formation's (FormationArrays fields, FormationMemory fields), without the batch
    axis: the physics' (`multilift_sim.tick_arrays.physics_fields`), then the controllers'
    (their parts' arrays, `multilift_control.controllers`)."""
    n = scenario.n_uavs
    arrays, memory = physics_fields(scenario)
    counts = np.array([u.vehicle.n_rotors for u in scenario.uavs], dtype=np.int64)
    rotors = int(counts.max())
    leader = leader_part(scenario)
    path = LeaderController(scenario).path  # the mission (unused by a leader without one)
    leader_constants, leader_memory = (np.asarray(a, dtype=float)
                                       for a in leader.arrays(scenario, 0))
    cascades = [vehicle_cascade(scenario, i) for i in range(n)]
    masses, constraints = formation_rows(scenario)
    rows = constraints.rows if n > 1 else np.zeros((0, ROW_SIZE), dtype=np.int64)
    follower = follower_part(scenario)
    built = [follower.arrays(scenario, i) for i in range(1, n)]
    size, memory_size = ((len(built[0][0]), len(built[0][1])) if built else (0, 0))
    m = rows.shape[0]
    follower_constants = np.zeros((n, size))
    follower_memory = np.zeros((n, memory_size))
    law_p, law_q = np.zeros((n, 3, m)), np.zeros((n, 3, 3 * n))
    own_rows = np.zeros(n, dtype=np.int64)
    for i, (constants, own_memory, p, q) in enumerate(built, start=1):
        follower_constants[i], follower_memory[i] = constants, own_memory
        if p is not None:  # a part without matrices leaves them zeros
            law_p[i], law_q[i] = p, q
        own_rows[i] = len(constraints.rows_of(i))
    link, delivered, link_memory = link_arrays(scenario.comms, n, scenario.simulation.tick_count)
    arrays.update(
        link=link, link_delivered=delivered,
        rotor_counts=counts, controlled=scenario.controlled,
        cascade=np.stack([c.constants for c in cascades]),
        fault_mixers=fault_mixers(scenario), mixer_uavs=mixer_uavs(scenario),
        target_schedule=target_schedule(scenario),
        leader_law=law_index(LEADER_CONTROLLERS, leader.NAME),
        leader_tracks=bool(leader.TRACKS_MISSION), leader=leader_constants,
        mission=path.mission, segments=path.segments, mission_steps=path.steps,
        follower_law=law_index(FOLLOWER_CONTROLLERS, follower.NAME),
        follower=follower_constants, masses=masses,
        rows=np.ascontiguousarray(rows, dtype=np.int64),
        law_p=law_p, law_q=law_q, own_rows=own_rows,
        thrust_coefficients=np.array([u.vehicle.thrust_coefficient for u in scenario.uavs],
                                     dtype=float))
    memory.update(
        mixers=np.stack([_padded(c.mixer.rows, rotors) for c in cascades]),
        targets=constraints.targets if n > 1 else np.zeros(0), next_target=0,
        leader_memory=leader_memory, follower_memory=follower_memory,
        thrusts=np.array(ThrustBook(scenario).thrusts, dtype=float),
        tracking=TrackingStatistics().acc,
        formation_errors=np.stack([FormationErrorStatistics().acc for _ in range(n)]),
        link_memory=link_memory)
    return arrays, memory


def _shape_key(fields: tuple[dict, dict]) -> tuple:
    arrays, memory = fields
    shared = tuple(float(arrays[name]) for name in ('physics_dt', 'physics_steps', 'period_ns'))
    return (shared, tuple(np.shape(v) for v in arrays.values()),
            tuple(np.shape(v) for v in memory.values()))


Fields = tuple[dict, dict]  # formation_fields' (arrays, memory) of one formation


def shape_groups(scenarios: Sequence[Scenario]) -> list[tuple[list[int], list[Fields] | None]]:
    """The scenarios' indices grouped into batches the engine can fly together (the same
    shapes of every array, control and physics rates), in order of first appearance, each
    with its formations' fields (for `batch_arrays`, built once; None for a scenario whose
    fields raise: a batch of its own, whose flight says what failed)."""
    groups: dict[tuple, tuple[list[int], list[Fields] | None]] = {}
    for index, scenario in enumerate(scenarios):
        try:
            fields = formation_fields(scenario)
            key = _shape_key(fields)
        except Exception:  # noqa: BLE001 - a batch of its own, whose flight says what failed
            groups[('alone', index)] = ([index], None)
            continue
        groups.setdefault(key, ([], []))[0].append(index)
        groups[key][1].append(fields)
    return list(groups.values())


def batch_arrays(scenarios: Sequence[Scenario], fields: Sequence[Fields] | None = None
                 ) -> tuple[FormationArrays, FormationMemory]:
    """The arrays of `scenarios` (B >= 1 of the same shape): (constants, initial memory);
    `fields` their formation_fields if built already (a scenario given B times is built
    once: the stacking copies)."""
    if not scenarios:
        raise ValueError('a batch needs at least one scenario')
    if fields is None:
        built: dict[int, Fields] = {}
        for s in scenarios:
            if id(s) not in built:
                built[id(s)] = formation_fields(s)
        fields = [built[id(s)] for s in scenarios]
    arrays = FormationArrays(**{name: stacked(name, [f[0][name] for f in fields])
                                for name in FormationArrays._fields})
    memory = FormationMemory(**{name: stacked(name, [f[1][name] for f in fields])
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
        gust=np.empty((ticks, batch, 3)), cable_length=np.empty((ticks, batch, n)),
        estimate=np.empty((ticks, batch, n, ESTIMATE_COLUMNS if
                           arrays.estimator_models.shape[1] else 0)))
