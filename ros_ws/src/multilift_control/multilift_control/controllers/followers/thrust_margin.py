"""The reorganising follower (`formation.reorganize: thrust_margin`, issue 35 item 2): the
seed's virtual-constraint follower (`virtual_constraints`, Ch. 3) whose formation's horizontal
offsets move online so that the UAVs' thrust margins stay even, or above
`formation.thrust_margin_floor` (`laws.reorganize`: the statics of Eq. 2.73 at the formation's
apparent gravity, a rate-limited gradient step within `formation.min_spacing`, `max_spread`,
`max_offset_rate`). The scenario's parse picks it when `formation.reorganize` is
`thrust_margin`; every follower computes the same step (its memory keeps its copy), from
`formation.start_places` when the file gives them. Its altitude loop feeds forward the
weight its thrust carries at hover in the geometry it flies (`laws.reorganize.hover_mass`),
not the seed's even share; its virtual constraints count each UAV's static cable pull in f of
Eq. 3.9 (`laws.reorganize.static_pulls`, `laws.follower.loaded_terms`: a UAV tilted to hold
its cable is not accelerating; a point payload's, whose formation starts at rest:
`scenario.reorganize.starts_at_rest`), and its altitude loop damps z_1_dot - z_i_dot
(FOLLOWER_LEADER_CLIMB: the seed's follower lags 0.25-0.29 m behind the leader in v3_mixed's
climb, and 0.2 m of lag empties UAV 3's cable by the statics). Its `answer` also flies
`cable_forces` (REORGANIZE_MODE says which step).

Its constants are the seed follower's FOLLOWER_* then the REORGANIZE_* slots (laws.layout),
its memory FOLLOWER_* then REORGANIZE_ACCELERATION and REORGANIZE_SHIFT; its matrices the
linear rows' P and Q (it flies linear and V formations only)."""
from __future__ import annotations

import dataclasses

import numpy as np

from multilift_control.controllers.followers import virtual_constraints
from multilift_control.formation import FormationFollower
from multilift_control.laws import jit
from multilift_control.laws import layout as slots
from multilift_control.laws.cable_forces import allocate, allocated_statics
from multilift_control.laws.follower import loaded_terms
from multilift_control.laws.reorganize import (hover_mass, hover_statics, reorganize,
                                              static_pulls, target_places)
from multilift_sim.scenario import Scenario
from multilift_sim.scenario.reorganize import starts_at_rest
from multilift_sim.start import formation_start

NAME = 'thrust_margin'
KEYS = ()  # its keys are the formation section's (formation.reorganize and its limits)
GAIN = 25.0         # offset rate per unit of the cost's gradient [m^2/s]
FILTER_TIME = 1.0   # the apparent gravity's low-pass time constant [s]
# cable_forces': its places follow the apparent gravity's tilt, which a gust on the payload
# gives the lifts (v3_mixed's UAV 3 least margin 5.06 % at 0.3 s against 4.95 % at 1 s, the
# allocation's least tension at 0.27 of the even share; at 0.3 of it 4.85-4.87 % at 0.1-0.5 s)
ALLOCATION_FILTER_TIME = 0.3


def mode_arrays(scenario: Scenario, index: int, mode: float
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(constants, memory at t = 0, P, Q) of follower `index` (from 1) stepping by `mode`
    (slots.REORGANIZE_GRADIENT or _ALLOCATE): the seed follower's, extended by the
    REORGANIZE_* slots."""
    constants, memory, p, q = virtual_constraints.arrays(scenario, index)
    f, n = scenario.formation, scenario.n_uavs
    extra = np.empty(slots.REORGANIZE_UAVS - len(constants) + slots.REORGANIZE_UAV_SIZE * n)
    own = np.concatenate([constants, extra])
    own[slots.FOLLOWER_LEADER_CLIMB] = 1.0  # no lag in the climb (module docstring)
    own[slots.REORGANIZE_PAYLOAD_MASS] = scenario.payload.mass
    own[slots.REORGANIZE_MIN_SPACING] = f.min_spacing
    own[slots.REORGANIZE_MAX_SPREAD] = f.max_spread
    own[slots.REORGANIZE_MAX_RATE] = f.max_offset_rate
    own[slots.REORGANIZE_FLOOR] = f.thrust_margin_floor
    own[slots.REORGANIZE_GAIN] = GAIN
    own[slots.REORGANIZE_FILTER_TIME] = (ALLOCATION_FILTER_TIME
                                         if mode == slots.REORGANIZE_ALLOCATE else FILTER_TIME)
    uavs, payload = formation_start(scenario)  # where the formation hangs at the start
    own[slots.REORGANIZE_DEPTH] = float(np.mean(uavs[:, 2]) - payload[2])  # a level start
    own[slots.REORGANIZE_MODE] = mode
    own[slots.REORGANIZE_AT_REST] = float(starts_at_rest(scenario))
    rigid = scenario.payload.type == 'rigid_body'  # its statics: laws.rigid_statics
    own[slots.REORGANIZE_RIGID] = float(rigid)
    for j, uav in enumerate(scenario.uavs):
        row = slots.REORGANIZE_UAVS + slots.REORGANIZE_UAV_SIZE * j
        own[row + slots.REORGANIZE_UAV_MASS] = uav.vehicle.mass
        own[row + slots.REORGANIZE_UAV_LARGEST] = uav.vehicle.max_thrust
        own[row + slots.REORGANIZE_UAV_LENGTH] = uav.cable_length
        attach = slice(row + slots.REORGANIZE_UAV_ATTACH, row + slots.REORGANIZE_UAV_ATTACH + 3)
        own[attach] = scenario.payload.attach_points[j] if rigid else (0.0, 0.0, 0.0)
    follower = FormationFollower.from_scenario(scenario, index)
    rows, targets = follower.constraints.rows, follower.constraints.targets
    extended = np.zeros(slots.REORGANIZE_SHIFT + len(targets))  # the acceleration: 0
    extended[:len(memory)] = memory
    if f.start_places:  # the shift starts where the formation does: places - targets' places
        start = uavs - uavs[0]
        for k, row in enumerate(rows):
            axis = row[slots.ROW_AXIS]
            if row[slots.ROW_FIRST] == 0 and 0 <= axis < 2:
                extended[slots.REORGANIZE_SHIFT + k] = -start[row[slots.ROW_SECOND], axis] \
                    - targets[k]
    return own, extended, p, q


def arrays(scenario: Scenario, index: int
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(constants, memory at t = 0, P, Q) of follower `index` (from 1): the gradient's step."""
    return mode_arrays(scenario, index, slots.REORGANIZE_GRADIENT)


# each follower steps its own copy of the shift, then its terms
shared = virtual_constraints.nothing_shared


@jit
def answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
           targets, law_p, law_q, terms, speeds, saturated, setpoint, errors, rates):
    """Follower `index`'s tick at t [s]: the formation's step (`laws.reorganize.reorganize`, or
    `laws.cable_forces.allocate` in REORGANIZE_ALLOCATE mode), then the seed follower's answer
    to the moved targets (`virtual_constraints.answer`: it writes speeds, saturated, setpoint,
    errors and rates) with the statics of the places flown in its law: the altitude loop
    feeds forward `hover_mass`, Eq. 3.9's f holds each UAV's `static_pulls`
    (`laws.follower.loaded_terms`) where a point payload's statics hold (REORGANIZE_AT_REST:
    the formation started at rest; a rigid body's cables do not meet at a point: none); the
    statics solved once (`hover_statics`, or `laws.cable_forces.allocated_statics`: the
    allocation's tensions where four cables or more leave them open); in REORGANIZE_ALLOCATE
    mode its altitude loop's offset from the leader follows the height allocated (the seed's
    altitude loop holds z_1 + FOLLOWER_ALTITUDE_OFFSET whatever its z row asks); returns the
    collective thrust asked [N]."""
    allocating = constants[slots.REORGANIZE_MODE] == slots.REORGANIZE_ALLOCATE
    if allocating:
        kept = allocate(constants, memory, t, masses, rows, targets, vectors)
    else:
        kept = reorganize(constants, memory, t, masses, rows, targets, vectors)
    places = target_places(rows, kept, np.zeros(kept.shape[0]), vectors.shape[0])
    tensions, units, found = (allocated_statics(constants, places) if allocating
                              else hover_statics(constants, places))  # once a tick
    trimmed = constants.copy()
    trimmed[slots.FOLLOWER_HOVER_MASS] = hover_mass(constants, tensions, units, found, index)
    if allocating:  # its altitude loop flies the height allocated (n = 2, a tilted plane)
        trimmed[slots.FOLLOWER_ALTITUDE_OFFSET] += places[index, 2] - target_places(
            rows, targets, np.zeros(kept.shape[0]), vectors.shape[0])[index, 2]
    pulls = (static_pulls(constants, tensions, units, found, masses)
             if constants[slots.REORGANIZE_AT_REST] else np.zeros((vectors.shape[0], 3)))
    loaded = loaded_terms(trimmed, masses, rows, kept, states, vectors, pulls)
    return virtual_constraints.answer(trimmed, memory, cascade, mixer, index, t, states,
                                      vectors, masses, rows, kept, law_p, law_q, loaded, speeds,
                                      saturated, setpoint, errors, rates)


def hover_places(scenario: Scenario, seconds: float = 60.0, dt: float = 0.01) -> np.ndarray:
    """The followers' places from the leader (n - 1, 2) [m] the formation's step (`reorganize`
    or, for cable_forces, `allocate`) reaches at hover from the geometry's places: the step
    iterated `seconds` [s] at `dt` [s] with every UAV's lift m_i g e_z (no acceleration). What
    `formation.start_places` gives to start at the hover equilibrium of the geometry flown."""
    mode = (slots.REORGANIZE_ALLOCATE if scenario.formation.reorganize == 'cable_forces'
            else slots.REORGANIZE_GRADIENT)
    fixed = dataclasses.replace(scenario, formation=dataclasses.replace(
        scenario.formation, start_places=()))
    constants, memory, _, _ = mode_arrays(fixed, 1, mode)
    follower = FormationFollower.from_scenario(fixed, 1)
    rows, targets = follower.constraints.rows, follower.constraints.targets
    masses = follower.masses
    lifts = np.zeros((len(masses), 3))
    lifts[:, 2] = masses * scenario.simulation.gravity
    step = allocate if mode == slots.REORGANIZE_ALLOCATE else reorganize
    for tick in range(int(round(seconds / dt))):
        step(constants, memory, tick * dt, masses, rows, targets, lifts)
        memory[slots.FOLLOWER_LAST_T] = tick * dt  # follower_update's advance
    kept = targets + memory[slots.REORGANIZE_SHIFT:slots.REORGANIZE_SHIFT + len(targets)]
    return target_places(rows, kept, np.zeros(len(kept)), len(masses))[1:, :2]
