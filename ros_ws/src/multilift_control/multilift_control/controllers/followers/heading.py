"""The turning follower (`formation.reorganize: heading`, issue 34, the `window` scenario): the
seed's virtual-constraint follower (`virtual_constraints`, Ch. 3) whose linear rows' horizontal
targets, r_1 - r_i in x and y, turn about the leader with the leader's heading: by psi_1 -
psi_1(0), its measured yaw from its start (wrapped to (-pi, pi]), so a mission's yaw (the
`waypoints` source's `yaw`) turns the whole formation, as a formation passing a window
narrower than its width turns to pass it edge on. The heights (z rows) stay. The targets move
as the leader turns, which the law treats as constant within a tick (its rates do not feed
the targets' own rate forward): turn slowly against the formation's gains.

Its constants are the seed follower's FOLLOWER_* then HEADING_LEADER_START_YAW (laws.layout),
its memory and matrices the seed follower's."""
from __future__ import annotations

import math

import numpy as np

from multilift_control.controllers.followers import virtual_constraints
from multilift_control.laws import jit
from multilift_control.laws import layout as slots
from multilift_sim.scenario import Scenario

NAME = 'heading'
KEYS = ()  # its key is the formation section's (formation.reorganize)


def arrays(scenario: Scenario, index: int
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(constants, memory at t = 0, P, Q) of follower `index` (from 1): the seed follower's,
    its constants extended by the leader's start yaw [rad]."""
    constants, memory, p, q = virtual_constraints.arrays(scenario, index)
    own = np.empty(slots.HEADING_SIZE)
    own[:len(constants)] = constants
    own[slots.HEADING_LEADER_START_YAW] = scenario.uavs[0].yaw
    return own, memory, p, q


@jit
def turned_targets(rows, targets, turn):
    """The targets (m,) [m] of the linear rows (laws.layout ROW_*) with each pair of x and y
    rows of one UAV pair turned by `turn` [rad] about world z; others as they are."""
    turned = targets.copy()
    c, s = math.cos(turn), math.sin(turn)
    for k in range(rows.shape[0]):
        if rows[k, slots.ROW_AXIS] != 0:
            continue
        for j in range(rows.shape[0]):
            if rows[j, slots.ROW_AXIS] == 1 and rows[j, slots.ROW_FIRST] == rows[
                    k, slots.ROW_FIRST] and rows[j, slots.ROW_SECOND] == rows[k, slots.ROW_SECOND]:
                turned[k] = c * targets[k] - s * targets[j]
                turned[j] = s * targets[k] + c * targets[j]
    return turned


# each follower turns the targets itself, then its terms
shared = virtual_constraints.nothing_shared


@jit
def answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
           targets, law_p, law_q, terms, speeds, saturated, setpoint, errors, rates):
    """Follower `index`'s tick at t [s]: the targets turned by the leader's heading since its
    start (states[0]'s yaw), then the seed follower's answer to them
    (`virtual_constraints.answer_moved`: it writes speeds, saturated, setpoint, errors and
    rates); returns the collective thrust asked [N]."""
    turn = states[0, slots.UAV_EULER + 2] - constants[slots.HEADING_LEADER_START_YAW]
    turn = math.atan2(math.sin(turn), math.cos(turn))
    kept = turned_targets(rows, targets, turn)
    return virtual_constraints.answer_moved(constants, memory, cascade, mixer, index, t,
                                            states, vectors, masses, rows, kept, law_p, law_q,
                                            speeds, saturated, setpoint, errors, rates)
