"""The reorganising follower (`formation.reorganize: thrust_margin`, issue 35 item 2): the
seed's virtual-constraint follower (`virtual_constraints`, Ch. 3) whose formation's horizontal
offsets move online so that the UAVs' thrust margins stay even, or above
`formation.thrust_margin_floor` (`laws.reorganize`: the statics of Eq. 2.73 at the formation's
apparent gravity, a rate-limited gradient step within `formation.min_spacing`, `max_spread`,
`max_offset_rate`). The scenario's parse picks it when `formation.reorganize` is
`thrust_margin`; every follower computes the same step (its memory keeps its copy).

Its constants are the seed follower's FOLLOWER_* then the REORGANIZE_* slots (laws.layout),
its memory FOLLOWER_* then REORGANIZE_ACCELERATION and REORGANIZE_SHIFT; its matrices the
linear rows' P and Q (it flies linear and V formations only)."""
from __future__ import annotations

import numpy as np

from multilift_control.controllers.followers import virtual_constraints
from multilift_control.laws import jit
from multilift_control.laws.follower import follower_update, formation_terms
from multilift_control.laws.layout import (REORGANIZE_FILTER_TIME, REORGANIZE_FLOOR,
                                           REORGANIZE_GAIN, REORGANIZE_MAX_RATE,
                                           REORGANIZE_MAX_SPREAD, REORGANIZE_MIN_SPACING,
                                           REORGANIZE_PAYLOAD_MASS, REORGANIZE_RADIUS,
                                           REORGANIZE_SHIFT,
                                           REORGANIZE_UAV_LARGEST, REORGANIZE_UAV_LENGTH,
                                           REORGANIZE_UAV_MASS, REORGANIZE_UAV_SIZE,
                                           REORGANIZE_UAVS)
from multilift_control.laws.reorganize import reorganize
from multilift_sim.scenario import Scenario
from multilift_sim.start import formation_start

NAME = 'thrust_margin'
KEYS = ()  # its keys are the formation section's (formation.reorganize and its limits)
GAIN = 25.0         # offset rate per unit of the cost's gradient [m^2/s]
FILTER_TIME = 1.0   # the apparent gravity's low-pass time constant [s]


def arrays(scenario: Scenario, index: int
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(constants, memory at t = 0, P, Q) of follower `index` (from 1): the seed follower's,
    extended by the REORGANIZE_* slots."""
    constants, memory, p, q = virtual_constraints.arrays(scenario, index)
    f, n = scenario.formation, scenario.n_uavs
    extra = np.empty(REORGANIZE_UAVS - len(constants) + REORGANIZE_UAV_SIZE * n)
    own = np.concatenate([constants, extra])
    own[REORGANIZE_PAYLOAD_MASS] = scenario.payload.mass
    own[REORGANIZE_MIN_SPACING] = f.min_spacing
    own[REORGANIZE_MAX_SPREAD] = f.max_spread
    own[REORGANIZE_MAX_RATE] = f.max_offset_rate
    own[REORGANIZE_FLOOR] = f.thrust_margin_floor
    own[REORGANIZE_GAIN] = GAIN
    own[REORGANIZE_FILTER_TIME] = FILTER_TIME
    uavs, payload = formation_start(scenario)  # where the formation hangs at the start
    own[REORGANIZE_RADIUS] = float(np.mean(np.hypot(*(uavs[:, :2] - payload[:2]).T)))
    for j, uav in enumerate(scenario.uavs):
        row = REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j
        own[row + REORGANIZE_UAV_MASS] = uav.vehicle.mass
        own[row + REORGANIZE_UAV_LARGEST] = uav.vehicle.max_thrust
        own[row + REORGANIZE_UAV_LENGTH] = uav.cable_length
    rows = p.shape[1]
    extended = np.zeros(REORGANIZE_SHIFT + rows)  # the acceleration and the shift start at 0
    extended[:len(memory)] = memory
    return own, extended, p, q


@jit
def shared(constants, masses, rows, targets, states, vectors):
    """Nothing shared: each follower steps its own copy of the shift, then its terms."""
    return 0.0


@jit
def answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
           targets, law_p, law_q, terms, speeds, saturated, setpoint, errors, rates):
    """Follower `index`'s tick at t [s]: the formation's step (`laws.reorganize.reorganize`),
    then the seed follower's tick (`follower_update`) to the moved targets; writes as
    `virtual_constraints.answer` and returns the collective thrust asked [N]."""
    kept = reorganize(constants, memory, t, masses, rows, targets, vectors)
    own_terms = formation_terms(constants, masses, rows, kept, states, vectors)
    s, sat, attitude, thrust, own_errors, own_rates = follower_update(
        constants, masses, rows, kept, law_p, law_q, index, memory, t, states, vectors,
        own_terms, cascade, mixer)
    for k in range(s.shape[0]):
        speeds[k] = s[k]
        saturated[k] = sat[k]
    for k in range(3):
        setpoint[k] = attitude[k]
    for k in range(own_errors.shape[0]):
        errors[k] = own_errors[k]
        rates[k] = own_rates[k]
    return thrust
