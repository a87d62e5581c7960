"""The reorganising follower (`formation.reorganize: thrust_margin`, issue 35 item 2): the
seed's virtual-constraint follower (`virtual_constraints`, Ch. 3) whose formation's horizontal
offsets move online so that the UAVs' thrust margins stay even, or above
`formation.thrust_margin_floor` (`laws.reorganize`: the statics of Eq. 2.73 at the formation's
apparent gravity, a rate-limited gradient step within `formation.min_spacing`, `max_spread`,
`max_offset_rate`). The scenario's parse picks it when `formation.reorganize` is
`thrust_margin`; every follower computes the same step (its memory keeps its copy). Its
`answer` also flies `cable_forces` (REORGANIZE_MODE says which step).

Its constants are the seed follower's FOLLOWER_* then the REORGANIZE_* slots (laws.layout),
its memory FOLLOWER_* then REORGANIZE_ACCELERATION and REORGANIZE_SHIFT; its matrices the
linear rows' P and Q (it flies linear and V formations only)."""
from __future__ import annotations

import numpy as np

from multilift_control.controllers.followers import virtual_constraints
from multilift_control.laws import jit
from multilift_control.laws import layout as slots
from multilift_control.laws.reorganize import allocate, reorganize
from multilift_sim.scenario import Scenario
from multilift_sim.start import formation_start

NAME = 'thrust_margin'
KEYS = ()  # its keys are the formation section's (formation.reorganize and its limits)
GAIN = 25.0         # offset rate per unit of the cost's gradient [m^2/s]
FILTER_TIME = 1.0   # the apparent gravity's low-pass time constant [s]


def mode_arrays(scenario: Scenario, index: int, mode: float
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(constants, memory at t = 0, P, Q) of follower `index` (from 1) stepping by `mode`
    (slots.REORGANIZE_GRADIENT or _ALLOCATE): the seed follower's, extended by the
    REORGANIZE_* slots."""
    constants, memory, p, q = virtual_constraints.arrays(scenario, index)
    f, n = scenario.formation, scenario.n_uavs
    extra = np.empty(slots.REORGANIZE_UAVS - len(constants) + slots.REORGANIZE_UAV_SIZE * n)
    own = np.concatenate([constants, extra])
    own[slots.REORGANIZE_PAYLOAD_MASS] = scenario.payload.mass
    own[slots.REORGANIZE_MIN_SPACING] = f.min_spacing
    own[slots.REORGANIZE_MAX_SPREAD] = f.max_spread
    own[slots.REORGANIZE_MAX_RATE] = f.max_offset_rate
    own[slots.REORGANIZE_FLOOR] = f.thrust_margin_floor
    own[slots.REORGANIZE_GAIN] = GAIN
    own[slots.REORGANIZE_FILTER_TIME] = FILTER_TIME
    uavs, payload = formation_start(scenario)  # where the formation hangs at the start
    own[slots.REORGANIZE_RADIUS] = float(np.mean(np.hypot(*(uavs[:, :2] - payload[:2]).T)))
    own[slots.REORGANIZE_MODE] = mode
    for j, uav in enumerate(scenario.uavs):
        row = slots.REORGANIZE_UAVS + slots.REORGANIZE_UAV_SIZE * j
        own[row + slots.REORGANIZE_UAV_MASS] = uav.vehicle.mass
        own[row + slots.REORGANIZE_UAV_LARGEST] = uav.vehicle.max_thrust
        own[row + slots.REORGANIZE_UAV_LENGTH] = uav.cable_length
    rows = p.shape[1]
    extended = np.zeros(slots.REORGANIZE_SHIFT + rows)  # the acceleration, the shift: 0
    extended[:len(memory)] = memory
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
    `allocate` in REORGANIZE_ALLOCATE mode), then the seed follower's answer to the moved
    targets (`virtual_constraints.answer_moved`: it writes speeds, saturated, setpoint, errors
    and rates); returns the collective thrust asked [N]."""
    if constants[slots.REORGANIZE_MODE] == slots.REORGANIZE_ALLOCATE:
        kept = allocate(constants, memory, t, masses, rows, targets, vectors)
    else:
        kept = reorganize(constants, memory, t, masses, rows, targets, vectors)
    return virtual_constraints.answer_moved(constants, memory, cascade, mixer, index, t,
                                            states, vectors, masses, rows, kept, law_p, law_q,
                                            speeds, saturated, setpoint, errors, rates)
