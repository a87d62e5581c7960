"""Cable-force allocation (`formation.reorganize: cable_forces`, issue 35 item 3) for n >= 2
cables of a point payload: each tick the share of the payload's apparent weight each cable
should carry so that the largest thrust utilisation of the UAVs is least (`load_shares`,
closed form), the places where the cables pull those shares by the statics of seed Eq. 2.73
(`allocated_places`: the horizontal balance sum_i T_i,horizontal = 0, the directions nearest
the current ones for n >= 3, the heights for n = 2; in the frame where the apparent gravity
g e_z + a is vertical, the formation tilted as one body), the tensions nearest those shares
that the followers feed forward (`allocated_statics`), and the followers' step towards them
(`allocate`), rate limited and within the spacing and spread limits of `laws.reorganize`
(whose statics, apparent gravity and memory it shares: constants FOLLOWER_* then REORGANIZE_*,
memory FOLLOWER_* then REORGANIZE_ACCELERATION and REORGANIZE_SHIFT). A rigid body's places are
searched with its rigid statics instead (`laws.rigid_allocation`, which `allocate` calls).

The statics of a place: UAV i at r_i from the point above the payload, h_i above it, on its
cable of length l_i (h_i = sqrt(l_i^2 - r_i^2)), pulling along u_i horizontally. Its cable's
vertical pull T_i h_i / l_i is its share s_i of the apparent weight W = m_p |g e_z + a|, so
T_i = s_i W l_i / h_i and its horizontal pull s_i W r_i / h_i u_i; the payload is balanced
when sum_i s_i (r_i / h_i) u_i = 0. World frame z up, SI units; places relative to the
leader [m]."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (FOLLOWER_GRAVITY, REORGANIZE_DEPTH, REORGANIZE_MAX_RATE,
                                           REORGANIZE_PAYLOAD_MASS, REORGANIZE_RIGID,
                                           REORGANIZE_UAV_LARGEST, REORGANIZE_UAV_LENGTH,
                                           REORGANIZE_UAV_MASS, REORGANIZE_UAV_SIZE,
                                           REORGANIZE_UAVS)
from multilift_control.laws.reorganize import (TAUT, _begin, _kept,
                                              cable_tensions, hang_point, hover_statics,
                                              statics_hold)
from multilift_control.laws.rigid_allocation import body_allocation_step

SHARE_MARGIN = 0.02  # n >= 3: every share at most 1/2 less this [-] (a polygon of forces)
BISECTIONS = 60      # halvings of a bracket: the utilisation's, n = 2's radius [-]
NEWTON_STEPS = 50    # the directions' Gauss-Newton iterations at most [-]
NEWTON_TURN = 0.5    # the largest turn of a direction in one iteration [rad]
CLOSED = 1e-12       # the balance met within this share of sum_i s_i r_i / H [-]
# the least share this much above the least tension's (relative): at its bound a cable's
# tension, solved again by the statics, would otherwise fall below it by a rounding and the
# allocation's own places be refused [-]
ROUNDING_GUARD = 1e-6
# the least tension a cable keeps in the allocation, as a share of m_p |g e_z + a| / n [-]:
# below `laws.reorganize`'s LEAST_TENSION_SHARE (a third), which the gradient's formation also
# leaves between v3_mixed's corners (UAV 3's cable 0.53 N median over 80-95 s against the third's
# 0.87 N; docs/loads.md). At a third UAV 3's least margin was 4.55 % (the second gust); at 0.27
# it keeps 5.06 % and its cable 0.16 N at least, flown (the climb's start, t = 10.0 s: the
# leader's step takes 0.55 N from it at once)
ALLOCATED_TENSION_SHARE = 0.27


@jit
def _uav(constants, j, slot):
    """UAV j's REORGANIZE_UAV_* `slot` from the constants."""
    return constants[REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j + slot]


@jit
def share_bounds(constants, n):
    """(low (n,), high (n,)) [-]: the shares s_i each of n cables may carry. Low: its
    tension at least ALLOCATED_TENSION_SHARE of the even share W / n (the slack bound, on the
    tension T_i = s_i W l_i / h_i, so s_i >= ALLOCATED_TENSION_SHARE h_i / (n l_i), h_i the
    depth REORGANIZE_DEPTH of the level start; ROUNDING_GUARD above). High:
    n >= 3 below 1/2 less SHARE_MARGIN (no side of a polygon of forces longer than the others
    together); n = 2 one less the other's low."""
    low = np.empty(n)
    high = np.empty(n)
    for j in range(n):
        low[j] = (ALLOCATED_TENSION_SHARE * (1.0 + ROUNDING_GUARD) * constants[REORGANIZE_DEPTH]
                  / (n * _uav(constants, j, REORGANIZE_UAV_LENGTH)))
    for j in range(n):
        high[j] = 0.5 - SHARE_MARGIN if n > 2 else 1.0 - low[1 - j]
    return low, high


@jit
def load_shares(constants, effective, n):
    """Each of the n cables' share s_i (n,) of the payload's apparent weight W = m_p |g_eff|
    [-] that makes the largest thrust utilisation (m_i |g_eff| + s_i W) / u_T,max,i of the
    UAVs least within `share_bounds` (the least effort under the thrust limits, a cable's
    vertical pull counted as the thrust it costs): every UAV whose share is not at a bound at one
    utilisation u, s_i = clip((u u_T,max,i - m_i |g_eff|) / W, low_i, high_i), u such that
    sum_i s_i = 1 (sum s_i nondecreasing in u: bisected). Independent of |g_eff|."""
    low, high = share_bounds(constants, n)
    weight = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    load = constants[REORGANIZE_PAYLOAD_MASS] * weight
    largest = np.empty(n)
    own = np.empty(n)
    for j in range(n):
        largest[j] = _uav(constants, j, REORGANIZE_UAV_LARGEST)
        own[j] = _uav(constants, j, REORGANIZE_UAV_MASS) * weight
    below, above = 0.0, 0.0  # a bracket of u: every share at its low, at its high bound
    for j in range(n):
        above = max(above, (own[j] + high[j] * load) / largest[j])
    below = above
    for j in range(n):
        below = min(below, (own[j] + low[j] * load) / largest[j])
    shares = np.empty(n)
    for _ in range(BISECTIONS):
        middle = 0.5 * (below + above)
        total = 0.0
        for j in range(n):
            shares[j] = min(max((middle * largest[j] - own[j]) / load, low[j]), high[j])
            total += shares[j]
        if total > 1.0:
            above = middle
        else:
            below = middle
    for j in range(n):
        shares[j] = min(max((above * largest[j] - own[j]) / load, low[j]), high[j])
    return shares / shares.sum()


@jit
def balanced_directions(weights, angles):
    """(angles (n,) [rad], found): the cables' horizontal directions u_i = (cos, sin) of the
    angles with sum_i weights_i u_i = 0 (n >= 3; weights_i = s_i r_i / H, the horizontal
    balance), near the given ones: Gauss-Newton's minimum-norm corrections of the angles (each
    iteration the least sum of squared turns that meets the linearised balance, no direction
    turning more than NEWTON_TURN), until the balance holds within CLOSED of sum_i weights_i;
    found False where it did not (no polygon of forces: a weight above the others' sum)."""
    n = weights.shape[0]
    phi = angles.copy()
    scale = weights.sum()
    for _ in range(NEWTON_STEPS):
        fx, fy = 0.0, 0.0
        for j in range(n):
            fx += weights[j] * math.cos(phi[j])
            fy += weights[j] * math.sin(phi[j])
        if math.sqrt(fx * fx + fy * fy) <= CLOSED * scale:
            return phi, True
        a, b, c = 0.0, 0.0, 0.0  # J J^T = [[a, b], [b, c]], J = [-w sin; w cos]
        for j in range(n):
            sine, cosine = math.sin(phi[j]), math.cos(phi[j])
            a += (weights[j] * sine) ** 2
            b -= weights[j] ** 2 * sine * cosine
            c += (weights[j] * cosine) ** 2
        determinant = a * c - b * b
        if determinant <= 1e-12 * (a + c) ** 2:
            return phi, False
        yx = (c * fx - b * fy) / determinant
        yy = (a * fy - b * fx) / determinant
        turns = np.empty(n)
        largest = 0.0
        for j in range(n):
            turns[j] = weights[j] * (math.sin(phi[j]) * yx - math.cos(phi[j]) * yy)
            largest = max(largest, abs(turns[j]))
        phi += turns * (1.0 if largest <= NEWTON_TURN else NEWTON_TURN / largest)
    return phi, False


@jit
def line_heights(constants, shares, spacing):
    """(r (2,), h (2,)) [m] of two cables whose UAVs stand `spacing` apart horizontally with
    the payload between them on their line: the horizontal balance s_1 r_1 / h_1 =
    s_2 r_2 / h_2 with r_1 + r_2 = spacing and h_i = sqrt(l_i^2 - r_i^2) (the more loaded
    cable the steeper; both level only where l_1 = l_2 and s_1 = s_2, or the lengths make it
    so), r_1 bisected. NaN where both cables cannot reach (spacing >= l_1 + l_2)."""
    l1 = _uav(constants, 0, REORGANIZE_UAV_LENGTH)
    l2 = _uav(constants, 1, REORGANIZE_UAV_LENGTH)
    radii = np.full(2, np.nan)
    heights = np.full(2, np.nan)
    if spacing >= l1 + l2:
        return radii, heights
    below, above = max(0.0, spacing - l2), min(spacing, l1)
    for _ in range(BISECTIONS):
        r1 = 0.5 * (below + above)
        r2 = spacing - r1
        balance = (shares[0] * r1 / math.sqrt(max(l1 * l1 - r1 * r1, 0.0))
                   - shares[1] * r2 / math.sqrt(max(l2 * l2 - r2 * r2, 0.0)))
        if balance > 0.0:
            above = r1
        else:
            below = r1
    radii[0] = 0.5 * (below + above)
    radii[1] = spacing - radii[0]
    heights[0] = math.sqrt(l1 * l1 - radii[0] ** 2)
    heights[1] = math.sqrt(l2 * l2 - radii[1] ** 2)
    return radii, heights


@jit
def upright(effective):
    """The rotation Q (3, 3) that turns the world's e_z onto the apparent gravity's direction
    g_eff / |g_eff| (`effective` = g e_z + a [m/s^2], the support a body needs per unit mass)
    about their common normal (Rodrigues): Q^T maps world vectors into the frame where the
    apparent gravity is vertical."""
    size = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    up = effective / size
    axis = np.array((-up[1], up[0], 0.0))  # e_z x up
    sine = math.sqrt(axis[0] ** 2 + axis[1] ** 2)
    cosine = up[2]
    rotation = np.eye(3)
    if sine == 0.0:
        return rotation  # upright already (an apparent gravity never points down)
    cross = np.array(((0.0, -axis[2], axis[1]), (axis[2], 0.0, -axis[0]),
                      (-axis[1], axis[0], 0.0)))
    return rotation + cross + cross @ cross * ((1.0 - cosine) / (sine * sine))


@jit
def allocated_places(constants, effective, places):
    """(places (n, 3) [m] relative to the leader, found): `level_places` in the frame where
    the apparent gravity `effective` [m/s^2] is vertical (`upright`): under an acceleration a
    the cables carry the shares of m_p |g e_z + a| along it, the UAVs in the plane normal to
    it (the formation tilted as one body; the reference's wrench, not only its weight)."""
    rotation = upright(effective)
    size = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    wanted, found = level_places(constants, size, places @ rotation)
    return wanted @ rotation.T, found


@jit
def level_places(constants, gravity, places):
    """(places (n, 3) [m] relative to the leader, found) under a vertical apparent gravity of
    `gravity` [m/s^2]: where the cables carry `load_shares` by the statics (module
    docstring), near the current `places` (n, 3) [m]. n >= 3: level UAVs, each at
    r_i = sqrt(l_i^2 - H^2) from the point above the payload (H the start's depth,
    REORGANIZE_DEPTH), in directions with sum_i s_i (r_i / H) u_i = 0
    turned little from the current ones (seen from where the payload hangs below them,
    `balanced_directions`): there the tensions T_i = s_i W l_i / H balance the payload
    (`allocated_statics`; n = 3 the only ones, n >= 4 one of many). n = 2: the follower on
    its current horizontal line from the leader at the start's spacing
    sqrt(l_1^2 - H^2) + sqrt(l_2^2 - H^2), at the height the balance asks (`line_heights`;
    level cables of one length carry equal shares only). found False (the places returned
    unchanged) where the payload cannot hang or no balance is reached."""
    n = places.shape[0]
    shares = load_shares(constants, np.array((0.0, 0.0, gravity)), n)
    depth = constants[REORGANIZE_DEPTH]
    radii = np.empty(n)
    for j in range(n):
        reach = _uav(constants, j, REORGANIZE_UAV_LENGTH) ** 2 - depth * depth
        if reach <= 0.0:
            return places, False
        radii[j] = math.sqrt(reach)
    wanted = np.zeros((n, 3))
    if n == 2:
        line = math.sqrt(places[1, 0] ** 2 + places[1, 1] ** 2)
        if line == 0.0:
            return places, False
        radii, heights = line_heights(constants, shares, radii[0] + radii[1])
        if math.isnan(radii[0]):
            return places, False
        for d in range(2):
            wanted[1, d] = (radii[0] + radii[1]) * places[1, d] / line
        wanted[1, 2] = heights[1] - heights[0]
        return wanted, True
    lengths = np.empty(n)
    for j in range(n):
        lengths[j] = _uav(constants, j, REORGANIZE_UAV_LENGTH)
    payload, hangs = hang_point(places, lengths, np.array((0.0, 0.0, -1.0)))
    if not hangs:
        return places, False
    angles = np.empty(n)
    for j in range(n):
        angles[j] = math.atan2(places[j, 1] - payload[1], places[j, 0] - payload[0])
    phi, found = balanced_directions(shares * radii / depth, angles)
    if not found:
        return places, False
    for j in range(n):
        wanted[j, 0] = radii[j] * math.cos(phi[j]) - radii[0] * math.cos(phi[0])
        wanted[j, 1] = radii[j] * math.sin(phi[j]) - radii[0] * math.sin(phi[0])
    return wanted, True


@jit
def allocate(constants, memory, t, masses, rows, targets, vectors):
    """`reorganize`'s tick for `formation.reorganize: cable_forces` (n >= 2 UAVs): a point
    payload's followers move towards `allocated_places` at the apparent gravity, at most
    REORGANIZE_MAX_RATE, kept within the limits and where every cable keeps its least tension
    (`tensions_hold`; `_kept`, the height too: n = 2's follower climbs or sinks to its place);
    a rigid body's take `laws.rigid_allocation.body_allocation_step` (x, y; kept where its
    rigid statics hold, `statics_hold`). Returns targets + shift (m,) [m]."""
    n = vectors.shape[0]
    dt, effective, shift, places = _begin(constants, memory, t, masses, rows, targets, vectors)
    if constants[REORGANIZE_RIGID] != 0.0:  # the rigid statics (laws.rigid_statics)
        moved = body_allocation_step(constants, places, effective, dt)
        return _kept(rows, targets, shift, constants, moved, 2,
                     statics_hold(constants, moved, effective))
    wanted, found = allocated_places(constants, effective, places)
    if not found:  # the places hold
        return _kept(rows, targets, shift, constants, places, 3, False)
    moved = places.copy()
    step = constants[REORGANIZE_MAX_RATE] * dt
    for j in range(1, n):
        gap = 0.0
        for d in range(3):
            gap += (wanted[j, d] - places[j, d]) ** 2
        gap = math.sqrt(gap)
        scale = 1.0 if gap <= step else step / gap
        for d in range(3):
            moved[j, d] += scale * (wanted[j, d] - places[j, d])
    return _kept(rows, targets, shift, constants, moved, 3,
                 tensions_hold(constants, moved, effective))


@jit
def nearest_tensions(constants, places, effective):
    """(T (n,) [N], e (n, 3), found) of the UAVs at `places` (n, 3) [m] under the apparent
    gravity `effective` [m/s^2]: the payload at `hang_point` along it, e_i up its cables, and
    the tensions the balance of Eq. 2.73's payload rows allows nearest the allocation's,
    T*_i = s_i W l_i / H (`load_shares`, W = m_p |g_eff|; 0 on a slack cable):
    T = T* + A^T y, (A A^T) y = m_p g_eff - A T*, A = [e_1 .. e_n]. With n <= 3 cables
    (statically determinate) the least-norm ones of `laws.reorganize.cable_tensions`; with
    n >= 4 (indeterminate: the UAVs' thrusts decide) the allocation's where they stand at its
    places. found False (T zero) where the payload cannot hang."""
    n = places.shape[0]
    lengths = np.empty(n)
    for j in range(n):
        lengths[j] = _uav(constants, j, REORGANIZE_UAV_LENGTH)
    size = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    payload, found = hang_point(places, lengths, -effective / size)
    if not found:
        return np.zeros(n), np.zeros((n, 3)), False
    weight = constants[REORGANIZE_PAYLOAD_MASS] * size
    shares = load_shares(constants, effective, n)
    _, units = cable_tensions(places, lengths, payload, np.zeros(3))
    preferred = np.empty(n)
    rest = constants[REORGANIZE_PAYLOAD_MASS] * effective
    for j in range(n):
        span = 0.0
        for d in range(3):
            span += (places[j, d] - payload[d]) ** 2
        preferred[j] = shares[j] * weight * lengths[j] / constants[REORGANIZE_DEPTH]
        if math.sqrt(span) < lengths[j] * (1.0 - TAUT):  # a slack cable carries nothing
            preferred[j] = 0.0
        for d in range(3):
            rest[d] -= preferred[j] * units[j, d]
    correction, _ = cable_tensions(places, lengths, payload, rest)
    return preferred + correction, units, True


@jit
def allocated_statics(constants, places):
    """(T (n,) [N], e (n, 3), found) at hover (`nearest_tensions` under g e_z): as
    `laws.reorganize.hover_statics`, the tensions the followers feed forward; a rigid body's
    are its rigid statics' (`hover_statics` itself: its cables do not meet at a point, and the
    point payload's hang put 0.34 s of UAV 2's saturation in beam_lift's start)."""
    if constants[REORGANIZE_RIGID] != 0.0:
        return hover_statics(constants, places)
    return nearest_tensions(constants, places,
                            np.array((0.0, 0.0, constants[FOLLOWER_GRAVITY])))


@jit
def tensions_hold(constants, places, effective):
    """Whether the payload hangs from the UAVs at `places` (n, 3) [m] under `effective`
    [m/s^2] with every `nearest_tensions` at least ALLOCATED_TENSION_SHARE of the even share
    m_p |g_eff| / n (`laws.reorganize.statics_hold` with the allocation's tensions)."""
    n = places.shape[0]
    tensions, _, found = nearest_tensions(constants, places, effective)
    size = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    least = ALLOCATED_TENSION_SHARE * constants[REORGANIZE_PAYLOAD_MASS] * size / n
    if not found:
        return False
    for j in range(n):
        if tensions[j] < least:
            return False
    return True
