"""The seed's follower (`control.follower: virtual_constraints`, the default; seed §3.2, Eq.
3.8-3.13): virtual-constraint forces that keep the formation's rows of g_vc and the leader's
altitude, flown through the cascade's attitude loop and mixer. The law and its departures
from the print: `multilift_control.formation.FormationFollower` (which builds these arrays)
and `laws.follower`.

Its constants are laws.layout's FOLLOWER_* slots, its memory FOLLOWER_INTEGRAL, _LAST_T,
_LIFT, _YAW; its matrices a linear formation's P (3, m) and Q (3, 3n) (zeros for nonlinear
rows, which solve each tick)."""
from __future__ import annotations

import numpy as np

from multilift_control.formation import FormationFollower
from multilift_control.laws import jit
from multilift_control.laws.follower import follower_update, formation_terms
from multilift_sim.scenario import Scenario

NAME = 'virtual_constraints'
KEYS = ()  # its gains: formation.alpha_vc, beta_vc and the control section's shared keys


def arrays(scenario: Scenario, index: int
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(constants, memory at t = 0, P, Q) of follower `index` (from 1)."""
    follower = FormationFollower.from_scenario(scenario, index)
    n = scenario.n_uavs
    m = follower.constraints.rows.shape[0]
    p, q = ((follower.law_p, follower.law_q) if follower.law_p.shape == (3, m)
            else (np.zeros((3, m)), np.zeros((3, 3 * n))))
    return follower.constants, follower.memory.copy(), p, q


shared = formation_terms  # what every follower's law of a tick shares, computed once


@jit
def answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
           targets, law_p, law_q, terms, speeds, saturated, setpoint, errors, rates):
    """Follower `index`'s tick at t [s] (`follower_update`; terms: the tick's `shared`): rotor
    speeds [rad/s] and saturation into speeds, saturated, roll, pitch, yaw [rad] into
    setpoint, its rows of g_vc [m or m^2] and their rates into errors, rates; returns the
    collective thrust asked [N]."""
    s, sat, attitude, thrust, own_errors, own_rates = follower_update(
        constants, masses, rows, targets, law_p, law_q, index, memory, t, states, vectors,
        terms, cascade, mixer)
    for k in range(s.shape[0]):
        speeds[k] = s[k]
        saturated[k] = sat[k]
    for k in range(3):
        setpoint[k] = attitude[k]
    for k in range(own_errors.shape[0]):
        errors[k] = own_errors[k]
        rates[k] = own_rates[k]
    return thrust


@jit
def answer_moved(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
                 moved, law_p, law_q, speeds, saturated, setpoint, errors, rates):
    """`answer` to targets `moved` (m,) [m or m^2] other than the formation's (a follower part
    that moves them: heading, thrust_margin): their terms (`formation_terms`) first."""
    terms = formation_terms(constants, masses, rows, moved, states, vectors)
    return answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
                  moved, law_p, law_q, terms, speeds, saturated, setpoint, errors, rates)


@jit
def nothing_shared(constants, masses, rows, targets, states, vectors):
    """The `shared` of a part whose followers move the targets themselves (`answer_moved`
    computes their terms): nothing, 0.0."""
    return 0.0
