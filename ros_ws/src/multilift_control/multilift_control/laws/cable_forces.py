"""Cable-force allocation (`formation.reorganize: cable_forces`, issue 35 item 3): each tick
the share of the payload's apparent weight each cable should carry so that every UAV flies at
the same share of its largest thrust (`load_shares`, closed form), the places where level
cables pull those shares (`allocated_places`: the triangle of forces), and the followers'
step towards them (`allocate`), rate limited and within the spacing and spread limits of
`laws.reorganize` (whose statics, apparent gravity and memory it shares: constants FOLLOWER_*
then REORGANIZE_*, memory FOLLOWER_* then REORGANIZE_ACCELERATION and REORGANIZE_SHIFT).
World frame z up, SI units; positions relative to the leader [m]."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (REORGANIZE_MAX_RATE, REORGANIZE_PAYLOAD_MASS,
                                           REORGANIZE_RADIUS, REORGANIZE_RIGID,
                                           REORGANIZE_UAV_LARGEST, REORGANIZE_UAV_MASS,
                                           REORGANIZE_UAV_SIZE, REORGANIZE_UAVS)
from multilift_control.laws.reorganize import LEAST_TENSION_SHARE, _begin, _kept
from multilift_control.laws.rigid_allocation import body_allocated_places

SHARE_MARGIN = 0.02  # every share at most 1/2 less this [-]
REORGANIZE_COUNT = 3  # allocates three cables in closed form


@jit
def load_shares(constants, effective):
    """Each cable's share s_i (n,) of the payload's apparent weight that gives every UAV the
    same thrust utilisation (m_i |g_eff| + s_i m_p |g_eff|) / u_T,max,i (the least effort under
    the thrust limits: the largest utilisation least), the cable's vertical pull counted as
    its tension, clipped to [LEAST_TENSION_SHARE / n, 1/2 - SHARE_MARGIN] (a triangle of forces
    exists only with every share below 1/2) and renormalised."""
    n = REORGANIZE_COUNT
    weight = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    load = constants[REORGANIZE_PAYLOAD_MASS] * weight
    largest = np.empty(n)
    own = np.empty(n)
    for j in range(n):
        row = REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j
        largest[j] = constants[row + REORGANIZE_UAV_LARGEST]
        own[j] = constants[row + REORGANIZE_UAV_MASS] * weight
    utilisation = (load + own.sum()) / largest.sum()
    shares = (utilisation * largest - own) / load
    low, high = LEAST_TENSION_SHARE / n, 0.5 - SHARE_MARGIN
    for _ in range(4):
        for j in range(n):
            shares[j] = min(max(shares[j], low), high)
        shares /= shares.sum()
    return shares


@jit
def allocated_places(constants, effective):
    """The three UAVs' places relative to the leader (3, 3) [m] where their cables carry
    `load_shares`: level UAVs on equal cables at REORGANIZE_RADIUS from the point below which
    the payload hangs, in directions u_i with sum s_i u_i = 0 (the horizontal balance), the
    leader ahead (+x) and UAV 2 on its left (+y) as in the V: the triangle of forces of sides
    s_1, s_2, s_3, the angle between u_1 and u_2 by the law of cosines."""
    s = load_shares(constants, effective)
    cosine = (s[2] ** 2 - s[0] ** 2 - s[1] ** 2) / (2.0 * s[0] * s[1])
    cosine = min(max(cosine, -1.0), 1.0)
    sine = math.sqrt(1.0 - cosine * cosine)
    units = np.zeros((3, 3))
    units[0, 0] = 1.0
    units[1, 0], units[1, 1] = cosine, sine
    for d in range(2):
        units[2, d] = -(s[0] * units[0, d] + s[1] * units[1, d]) / s[2]
    places = np.zeros((3, 3))
    radius = constants[REORGANIZE_RADIUS]
    for j in range(3):
        for d in range(2):
            places[j, d] = radius * (units[j, d] - units[0, d])
    return places


@jit
def allocate(constants, memory, t, masses, rows, targets, vectors):
    """`reorganize`'s tick for `formation.reorganize: cable_forces` (three UAVs, a point
    payload): the followers' places move towards `allocated_places` at the apparent gravity,
    each at most REORGANIZE_MAX_RATE, within the limits; returns targets + shift (m,) [m]."""
    n = vectors.shape[0]
    dt, effective, shift, places = _begin(constants, memory, t, masses, rows, targets, vectors)
    wanted = (body_allocated_places(constants, effective) if constants[REORGANIZE_RIGID]
              else allocated_places(constants, effective))  # a rigid body: rigid_allocation
    moved = places.copy()
    for j in range(1, n):
        gap = math.sqrt((wanted[j, 0] - places[j, 0]) ** 2 + (wanted[j, 1] - places[j, 1]) ** 2)
        step = constants[REORGANIZE_MAX_RATE] * dt
        scale = 1.0 if gap <= step else step / gap
        for d in range(2):
            moved[j, d] += scale * (wanted[j, d] - places[j, d])
    return _kept(rows, targets, shift, constants, effective, places, moved)
