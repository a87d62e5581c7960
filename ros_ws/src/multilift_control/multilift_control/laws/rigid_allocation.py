"""Cable-force allocation for a rigid-body payload (`formation.reorganize: cable_forces`, issue
35 item 3; `laws.cable_forces.allocate` calls `body_allocation_step` when REORGANIZE_RIGID is
set): the followers' places that make the UAVs' largest thrust utilisation least, with the
body hanging as its rigid statics put it (`laws.rigid_statics` through
`laws.reorganize.static_margins`: Eq. 2.73's force and moment rows, the body tilting where its
attach points lie above its centre of mass). A body's cables do not meet at a point, so no
closed form gives the places for chosen shares (held level, three attach points at one height
fix the vertical shares whatever the UAVs do); the step searches them instead, as the
reorganising formation does (`laws.reorganize.reorganize`), but for the allocation's own
objective: the utilisations u_i = u_T,i / u_T,max,i (u_T,i = |m_i (g e_z + a) + T_i e_i|, the
statics' thrust) summed smoothly to their largest,

    U = max_j u_j + log(sum_i exp(SHARPNESS (u_i - max_j u_j))) / SHARPNESS,

its gradient over each follower's x, y by differences of reorganize.STEP (one-sided where a
probe leaves the places where every cable keeps its least tension, `static_margins` NaN), each
follower's place moving at -SEARCH_GAIN times it, clipped to REORGANIZE_MAX_RATE.
World frame z up, SI units; places relative to the leader [m]."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import REORGANIZE_MAX_RATE
from multilift_control.laws.reorganize import STEP, static_margins

SHARPNESS = 200.0    # the smooth maximum's sharpness: utilisations 0.005 apart weigh e to 1 [-]
SEARCH_GAIN = 100.0  # a place's rate per unit of the utilisation's gradient [m^2/s]: 0.2 m/s
#                      (v3_box_mixed's max_offset_rate) where 1 m moves 0.2 % of a UAV's thrust


@jit
def largest_utilisation(constants, places, effective):
    """U [-], the UAVs' largest thrust utilisation smoothed (module docstring), with the UAVs
    at `places` (n, 3) [m] under the apparent gravity `effective` [m/s^2]; infinite where the
    body cannot hang or a cable would carry less than its least tension."""
    margins = static_margins(constants, places, effective)
    largest = -math.inf
    for j in range(margins.shape[0]):
        if math.isnan(margins[j]):
            return math.inf
        largest = max(largest, 1.0 - margins[j])
    total = 0.0
    for j in range(margins.shape[0]):
        total += math.exp(SHARPNESS * (1.0 - margins[j] - largest))
    return largest + math.log(total) / SHARPNESS


@jit
def body_allocation_step(constants, places, effective, dt):
    """The followers' places (n, 3) [m] after dt [s] of descent of `largest_utilisation` from
    `places` (x, y only; the leader's row and the heights kept): each follower's rate
    -SEARCH_GAIN grad U [m/s] clipped to REORGANIZE_MAX_RATE, the gradient by central
    differences, one-sided where one probe has no statics; no step where neither has, or the
    places themselves have none."""
    n = places.shape[0]
    moved = places.copy()
    here = largest_utilisation(constants, places, effective)
    if not math.isfinite(here) or dt == 0.0:
        return moved
    limit = constants[REORGANIZE_MAX_RATE]
    for j in range(1, n):
        rate = np.zeros(2)
        for d in range(2):
            probe = places.copy()
            probe[j, d] += STEP
            ahead = largest_utilisation(constants, probe, effective)
            probe[j, d] -= 2.0 * STEP
            behind = largest_utilisation(constants, probe, effective)
            if math.isfinite(ahead) and math.isfinite(behind):
                slope = (ahead - behind) / (2.0 * STEP)
            elif math.isfinite(ahead):
                slope = (ahead - here) / STEP
            elif math.isfinite(behind):
                slope = (here - behind) / STEP
            else:
                slope = 0.0
            rate[d] = -SEARCH_GAIN * slope
        speed = math.sqrt(rate[0] ** 2 + rate[1] ** 2)
        scale = limit / speed if speed > limit else 1.0
        for d in range(2):
            moved[j, d] += scale * rate[d] * dt
    return moved
