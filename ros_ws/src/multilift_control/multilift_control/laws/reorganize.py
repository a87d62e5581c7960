"""A formation that reorganises to share its payload by thrust margin (issue 35 item 2,
`formation.reorganize: thrust_margin`; the seed's §5.2 third suggestion): each tick the
followers' horizontal offsets from the leader (the targets of the linear rows of g_vc, Eq. 3.6)
move along the gradient of a cost of the UAVs' thrust margins, rate limited and kept within the
spacing and spread limits. The margins are the statics' (Eq. 2.73, as
`multilift_sim.analysis.loads`): the formation at its target places under the apparent gravity
g e_z + a, a point payload hanging where every cable reaches (`hang_point`), the tensions the
least-norm that carry m_p (g e_z + a) (`cable_tensions`), UAV i's thrust
|m_i (g e_z + a) + T_i e_i| (e_i the unit vector from the payload up its cable to UAV i) and its
margin 1 - u_T,i / u_T,max,i.

Every follower computes the same step from the same inputs (the formation's states and lifts,
its own copy of the shift in memory), so the followers agree without talking. constants:
FOLLOWER_* then REORGANIZE_* slots (layout); memory: FOLLOWER_* then REORGANIZE_ACCELERATION
and REORGANIZE_SHIFT. World frame z up, SI units; positions relative to the leader [m]."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (FOLLOWER_GRAVITY, FOLLOWER_LAST_T, ROW_AXIS,
                                           ROW_FIRST, ROW_SECOND, REORGANIZE_ACCELERATION,
                                           REORGANIZE_FILTER_TIME, REORGANIZE_FLOOR,
                                           REORGANIZE_GAIN, REORGANIZE_MAX_RATE,
                                           REORGANIZE_MAX_SPREAD, REORGANIZE_MIN_SPACING,
                                           REORGANIZE_PAYLOAD_MASS, REORGANIZE_RIGID,
                                           REORGANIZE_SHIFT,
                                           REORGANIZE_UAV_LARGEST, REORGANIZE_UAV_LENGTH,
                                           REORGANIZE_UAV_MASS, REORGANIZE_UAV_SIZE,
                                           REORGANIZE_UAVS)
from multilift_control.laws.linalg import minimum_norm_solve
from multilift_control.laws.rigid_statics import body_tensions

TAUT = 1e-6          # a cable within this share of its length of taut carries load [-]
REACH = 1e-9         # a candidate this share past a cable's length still counts as reached [-]
FLOOR_WEIGHT = 10.0  # the floor's penalty against the margins' spread in the cost [-]
STEP = 1e-3          # the cost's gradient by central differences of this step [m]
# the least tension a cable keeps, as a share of m_p |g e_z + a| / n [-]: an unloaded cable
# is one gust from slack (which the rigid-cable formulations cannot fly); in v3_mixed's flight
# UAV 3's cable dips up to 0.7 N below its static tension (the climb's start, the corners), so
# at a quarter (0.65 N) it pushed, at a third (0.87 N) it keeps 0.23 N (docs/loads.md)
LEAST_TENSION_SHARE = 1.0 / 3.0


@jit
def _lowest(best, best_depth, point, down, uavs, lengths):
    """`point` if every cable reaches it and it lies lower along `down` than `best`."""
    for j in range(uavs.shape[0]):
        gap = 0.0
        for d in range(3):
            gap += (point[d] - uavs[j, d]) ** 2
        if math.sqrt(gap) > lengths[j] * (1.0 + REACH):
            return best, best_depth
    depth = point[0] * down[0] + point[1] * down[1] + point[2] * down[2]
    if depth > best_depth:
        return point.copy(), depth
    return best, best_depth


@jit
def hang_point(uavs, lengths, down):
    """(p (3,) [m], found) where a point payload hangs from cables of `lengths` (n,) [m] tied
    to `uavs` (n, 3) [m] when its apparent weight pulls along the unit vector `down`: the
    lowest point along `down` every cable reaches, on the boundary of the balls' intersection:
    one cable straight, the lowest point of two spheres' circle, or a corner of three."""
    n = uavs.shape[0]
    best = np.zeros(3)
    best_depth = -math.inf
    for i in range(n):
        best, best_depth = _lowest(best, best_depth, uavs[i] + lengths[i] * down, down, uavs,
                                   lengths)
    for i in range(n):
        for j in range(i + 1, n):
            span = uavs[j] - uavs[i]
            distance = math.sqrt(span[0] ** 2 + span[1] ** 2 + span[2] ** 2)
            if distance == 0.0 or distance > lengths[i] + lengths[j] \
                    or distance < abs(lengths[i] - lengths[j]):
                continue
            axis = span / distance
            along = (distance ** 2 + lengths[i] ** 2 - lengths[j] ** 2) / (2.0 * distance)
            centre = uavs[i] + along * axis
            radius = math.sqrt(max(lengths[i] ** 2 - along ** 2, 0.0))
            across = down - (down[0] * axis[0] + down[1] * axis[1] + down[2] * axis[2]) * axis
            size = math.sqrt(across[0] ** 2 + across[1] ** 2 + across[2] ** 2)
            if size > 1e-12:
                best, best_depth = _lowest(best, best_depth, centre + radius * across / size,
                                           down, uavs, lengths)
            for k in range(j + 1, n):  # the circle's points at l_k from UAV k
                offset = uavs[k] - centre
                height = offset[0] * axis[0] + offset[1] * axis[1] + offset[2] * axis[2]
                flat = offset - height * axis
                reach = math.sqrt(flat[0] ** 2 + flat[1] ** 2 + flat[2] ** 2)
                if reach == 0.0 or radius <= 0.0:
                    continue
                cosine = (radius ** 2 + reach ** 2 + height ** 2 - lengths[k] ** 2) / (
                    2.0 * radius * reach)
                if abs(cosine) > 1.0:
                    continue
                e1 = flat / reach
                e2 = np.cross(axis, e1)
                sine = math.sqrt(1.0 - cosine * cosine)
                for sign in (1.0, -1.0):
                    best, best_depth = _lowest(best, best_depth,
                                               centre + radius * (cosine * e1 + sign * sine * e2),
                                               down, uavs, lengths)
    return best, best_depth > -math.inf


@jit
def cable_tensions(uavs, lengths, payload, load):
    """(T (n,) [N], e (n, 3)): the least-norm tensions of the taut cables whose pulls
    sum_i T_i e_i give the payload `load` [N] (its apparent weight m_p (g e_z + a)), e_i the
    unit vector from the payload at `payload` up cable i (Eq. 2.73's payload rows); a slack
    cable carries 0."""
    n = uavs.shape[0]
    units = np.zeros((n, 3))
    taut = np.zeros(n, dtype=np.bool_)
    for j in range(n):
        gap = uavs[j] - payload
        size = math.sqrt(gap[0] ** 2 + gap[1] ** 2 + gap[2] ** 2)
        if size > 0.0:
            units[j] = gap / size
        taut[j] = size >= lengths[j] * (1.0 - TAUT)
    product = np.zeros((3, 3))  # A A^T over the taut cables
    for j in range(n):
        if taut[j]:
            for a in range(3):
                for b in range(3):
                    product[a, b] += units[j, a] * units[j, b]
    y = minimum_norm_solve(product, load)
    tensions = np.zeros(n)
    for j in range(n):
        if taut[j]:
            tensions[j] = units[j, 0] * y[0] + units[j, 1] * y[1] + units[j, 2] * y[2]
    return tensions, units


@jit
def static_margins(constants, places, effective):
    """Each UAV's thrust margin 1 - u_T,i / u_T,max,i (n,) [-] with the UAVs at `places`
    (n, 3) [m] under the apparent gravity `effective` = g e_z + a [m/s^2] (module docstring);
    NaN where the payload cannot hang or a cable would carry less than LEAST_TENSION_SHARE of
    its even share."""
    n = places.shape[0]
    size = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    margins = np.full(n, np.nan)
    tensions, units, found = cable_statics(constants, places, effective)
    if not found:
        return margins
    least = LEAST_TENSION_SHARE * constants[REORGANIZE_PAYLOAD_MASS] * size / n
    for j in range(n):
        if tensions[j] < least:
            return margins
    for j in range(n):
        row = REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j
        thrust = 0.0
        for d in range(3):
            thrust += (constants[row + REORGANIZE_UAV_MASS] * effective[d]
                       + tensions[j] * units[j, d]) ** 2
        margins[j] = 1.0 - math.sqrt(thrust) / constants[row + REORGANIZE_UAV_LARGEST]
    return margins


@jit
def hover_statics(constants, places):
    """(T (n,) [N], e (n, 3), found) of the UAVs at `places` (n, 3) [m] at hover: the payload's
    `cable_statics` under g e_z (Eq. 2.73's payload rows); found False where the payload cannot
    hang (T zero)."""
    return cable_statics(constants, places, np.array((0.0, 0.0, constants[FOLLOWER_GRAVITY])))


@jit
def cable_statics(constants, places, effective):
    """(T (n,) [N], e (n, 3), found) of the payload hanging at rest from the UAVs at `places`
    (n, 3) [m] under the apparent gravity `effective` = g e_z + a [m/s^2]: a point payload at
    `hang_point` with the least-norm `cable_tensions` that carry m_p (g e_z + a), or with
    REORGANIZE_RIGID a rigid body (`laws.rigid_statics.body_tensions`); T zero, found False
    where it cannot hang."""
    if constants[REORGANIZE_RIGID] != 0.0:
        return body_tensions(constants, places, effective)
    n = places.shape[0]
    lengths = np.empty(n)
    for j in range(n):
        lengths[j] = constants[REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j + REORGANIZE_UAV_LENGTH]
    size = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    payload, found = hang_point(places, lengths, -effective / size)
    if not found:
        return np.zeros(n), np.zeros((n, 3)), False
    tensions, units = cable_tensions(places, lengths, payload,
                                     constants[REORGANIZE_PAYLOAD_MASS] * effective)
    return tensions, units, True


@jit
def hover_mass(constants, tensions, units, found, index):
    """The mass [kg] whose weight UAV `index`'s thrust carries at hover with the statics of
    the places flown (tensions T (n,) [N], units e (n, 3), found: as `hover_statics` returns
    them, solved once a tick for this and `static_pulls`): m_i + T_i e_i,z / g, its own and
    its cable's vertical pull by Eq. 2.73. The feedforward of the geometry flown: the seed's
    m_i + m_p / n is its even share, which a reorganised formation does not carry (v3_mixed:
    UAV 3 0.09 kg of the payload at its start places, where the even share is 0.27 kg). The
    even share where the payload cannot hang (found False)."""
    n = tensions.shape[0]
    own = constants[REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * index + REORGANIZE_UAV_MASS]
    if not found:
        return own + constants[REORGANIZE_PAYLOAD_MASS] / n
    return own + tensions[index] * units[index, 2] / constants[FOLLOWER_GRAVITY]


@jit
def static_pulls(constants, tensions, units, found, masses):
    """Each UAV's static load beyond its hover mass's weight (n, 3) [N], world: T_j e_j -
    (M_j - m_j) g e_z with the statics of the places flown (tensions, units, found as
    `hover_statics` returns them; M_j = masses[j], the law's hover mass m_j + m_p / n), what
    its thrust spends at rest on its cable beyond the even share the seed's law feeds forward
    (`follower.loaded_terms`): zero for an even V, the horizontal pull of a tilted UAV's cable
    in any other. Zeros where the payload cannot hang (found False: the seed's law)."""
    n = tensions.shape[0]
    pulls = np.zeros((n, 3))
    if not found:
        return pulls
    gravity = constants[FOLLOWER_GRAVITY]
    for j in range(n):
        own = constants[REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j + REORGANIZE_UAV_MASS]
        for d in range(3):
            pulls[j, d] = tensions[j] * units[j, d]
        pulls[j, 2] -= (masses[j] - own) * gravity
    return pulls


@jit
def margin_cost(margins, floor):
    """The cost the formation descends [-]: the margins' spread sum (mu_i - mean)^2 plus
    FLOOR_WEIGHT sum max(0, floor - mu_i)^2; infinite where a margin is NaN."""
    n = margins.shape[0]
    mean = 0.0
    for j in range(n):
        if math.isnan(margins[j]):
            return math.inf
        mean += margins[j] / n
    cost = 0.0
    for j in range(n):
        cost += (margins[j] - mean) ** 2 + FLOOR_WEIGHT * max(0.0, floor - margins[j]) ** 2
    return cost


@jit
def target_places(rows, targets, shift, n):
    """The UAVs' places relative to the leader (n, 3) [m] the linear rows (0, j, axis) of
    targets + shift ask for: r_j - r_1 = -(target + shift)."""
    places = np.zeros((n, 3))
    for k in range(rows.shape[0]):
        if rows[k, ROW_FIRST] == 0 and rows[k, ROW_AXIS] >= 0:
            places[rows[k, ROW_SECOND], rows[k, ROW_AXIS]] = -(targets[k] + shift[k])
    return places


@jit
def within_limits(places, min_spacing, max_spread):
    """Whether every two UAVs stand at least min_spacing and at most max_spread apart,
    horizontally [m]."""
    n = places.shape[0]
    for i in range(n):
        for j in range(i + 1, n):
            gap = math.sqrt((places[i, 0] - places[j, 0]) ** 2
                            + (places[i, 1] - places[j, 1]) ** 2)
            if gap < min_spacing or gap > max_spread:
                return False
    return True


@jit
def filtered_gravity(constants, memory, dt, masses, vectors):
    """The formation's apparent gravity g e_z + a (3,) [m/s^2], a low-passed in memory
    (REORGANIZE_ACCELERATION, time constant REORGANIZE_FILTER_TIME) from
    a = sum_i lift_i / sum_i m_i - g e_z (vectors (n, 3) the lifts [N], masses the hover masses
    [kg]) over dt [s]."""
    n = vectors.shape[0]
    gravity = constants[FOLLOWER_GRAVITY]
    total = 0.0
    for j in range(n):
        total += masses[j]
    blend = dt / (constants[REORGANIZE_FILTER_TIME] + dt)
    for d in range(3):
        lift = 0.0
        for j in range(n):
            lift += vectors[j, d]
        a = lift / total - (gravity if d == 2 else 0.0)
        memory[REORGANIZE_ACCELERATION + d] += blend * (a - memory[REORGANIZE_ACCELERATION + d])
    effective = memory[REORGANIZE_ACCELERATION:REORGANIZE_ACCELERATION + 3].copy()
    effective[2] += gravity
    return effective


@jit
def _begin(constants, memory, t, masses, rows, targets, vectors):
    """A step's start at t [s]: (dt since the follower's last tick [s], 0 at the first; the
    apparent gravity (`filtered_gravity`) [m/s^2]; the shift, a view of memory's
    REORGANIZE_SHIFT (m,) [m]; the places it asks for (n, 3) [m])."""
    last = memory[FOLLOWER_LAST_T]
    dt = 0.0 if math.isnan(last) else max(t - last, 0.0)
    effective = filtered_gravity(constants, memory, dt, masses, vectors)
    shift = memory[REORGANIZE_SHIFT:REORGANIZE_SHIFT + rows.shape[0]]
    return dt, effective, shift, target_places(rows, targets, shift, vectors.shape[0])


@jit
def statics_hold(constants, places, effective):
    """Whether the payload hangs from the UAVs at `places` (n, 3) [m] under the apparent
    gravity `effective` [m/s^2] with every cable's least-norm tension at least
    LEAST_TENSION_SHARE of its even share (`static_margins` finite)."""
    return math.isfinite(margin_cost(static_margins(constants, places, effective), 0.0))


@jit
def _kept(rows, targets, shift, constants, moved, axes, accepted):
    """Take `moved` (the shift of its rows of the first `axes` axes: 2 x, y; 3 also z) when
    the statics `accepted` it and it keeps the spacing and spread limits; returns
    targets + shift (m,)."""
    m = rows.shape[0]
    if accepted and within_limits(moved, constants[REORGANIZE_MIN_SPACING],
                                  constants[REORGANIZE_MAX_SPREAD]):
        for k in range(m):
            if rows[k, ROW_FIRST] == 0 and 0 <= rows[k, ROW_AXIS] < axes:
                shift[k] = -moved[rows[k, ROW_SECOND], rows[k, ROW_AXIS]] - targets[k]
    kept = np.empty(m)
    for k in range(m):
        kept[k] = targets[k] + shift[k]
    return kept


@jit
def reorganize(constants, memory, t, masses, rows, targets, vectors):
    """One tick's step at t [s] of the shift of the rows' targets in memory (REORGANIZE_SHIFT),
    returned as the targets the follower keeps (targets + shift, (m,) [m]): the apparent
    gravity (`filtered_gravity`), the cost's gradient over the followers' horizontal places,
    each follower's rate -REORGANIZE_GAIN grad clipped to REORGANIZE_MAX_RATE, the step taken
    when its places keep the limits and the payload hangs there and at every probe of the
    gradient (where it cannot, the cost is infinite: no step this tick, as a NaN rate refused
    it before, without the NaN). Call before `follower_update`, which advances
    FOLLOWER_LAST_T."""
    n = vectors.shape[0]
    dt, effective, shift, places = _begin(constants, memory, t, masses, rows, targets, vectors)
    floor = constants[REORGANIZE_FLOOR]
    moved = places.copy()
    refused = False  # a probe where the payload cannot hang refuses this tick's step
    for j in range(1, n):
        rate = np.zeros(2)
        for d in range(2):
            probe = places.copy()
            probe[j, d] += STEP
            ahead = margin_cost(static_margins(constants, probe, effective), floor)
            probe[j, d] -= 2.0 * STEP
            behind = margin_cost(static_margins(constants, probe, effective), floor)
            rate[d] = -constants[REORGANIZE_GAIN] * (ahead - behind) / (2.0 * STEP)
        speed = math.sqrt(rate[0] ** 2 + rate[1] ** 2)
        if not math.isfinite(speed):
            refused = True
            continue
        limit = constants[REORGANIZE_MAX_RATE]
        scale = limit / speed if speed > limit else 1.0
        for d in range(2):
            moved[j, d] += scale * rate[d] * dt
    if dt == 0.0:
        moved = places
    return _kept(rows, targets, shift, constants, moved, 2,
                 (dt == 0.0 or not refused) and statics_hold(constants, moved, effective))
