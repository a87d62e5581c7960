"""The statics of a rigid-body payload hanging from its UAVs' cables (seed Eq. 2.73 with a rigid
body's rows, docs/rigid_payload.md; issue 35), for the reorganising formation's law
(`laws.reorganize.cable_statics` calls it when REORGANIZE_RIGID is set).

Cable i joins the body at b_i (payload frame) to UAV i at s_i, d_i = s_i - p - R b_i (the body's
end to the UAV's, world), and pulls the body with lambda_i d_i (the seed's 2 lambda_i d_i,
Eq. 2.58, the factor taken into lambda here). The body hangs at rest under the apparent gravity
g e_z + a where

    |d_i|^2 = l_i^2                         (every cable at its length, Eq. 2.42)
    sum_i lambda_i d_i = m_p (g e_z + a)    (the body's force rows of Eq. 2.73)
    sum_i (R b_i) x lambda_i d_i = 0        (its moment rows, about its centre of mass)

n + 6 equations in n + 6 unknowns: the body's place p, its attitude R and the multipliers.
Unlike a point payload's, the tensions are not set by the cables' directions alone: attach
points above the centre of mass let the body tilt, which moves its weight between the cables
(docs/loads.md). World frame z up, SI units; places relative to any origin [m]."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (REORGANIZE_PAYLOAD_MASS, REORGANIZE_UAV_ATTACH,
                                           REORGANIZE_UAV_LENGTH, REORGANIZE_UAV_SIZE,
                                           REORGANIZE_UAVS)
from multilift_control.laws.linalg import minimum_norm_solve

NEWTON_STEPS = 30  # Newton steps at most (from the level start: 3 to 9 in the shipped cases)
SETTLED = 1e-11    # a residual this share of its scale (l_i, |load|, |load| max |b_i|) is zero
PIVOT = 1e-12      # a pivot this share of the Jacobian's largest entry is singular: the SVD


@jit
def _cross(a, b):
    """a x b (3,)."""
    return np.array((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]))


@jit
def _product(a, b):
    """a b (3, 3) of two (3, 3) matrices, in plain loops (the same bits compiled or not)."""
    out = np.zeros((3, 3))
    for i in range(3):
        for k in range(3):
            for j in range(3):
                out[i, j] += a[i, k] * b[k, j]
    return out


@jit
def _applied(a, v):
    """a v (3,) of a (3, 3) matrix and a (3,) vector, in plain loops."""
    out = np.zeros(3)
    for i in range(3):
        out[i] = a[i, 0] * v[0] + a[i, 1] * v[1] + a[i, 2] * v[2]
    return out


@jit
def _turned(rotation, angle):
    """exp([angle]x) R (3, 3): `rotation` turned by the rotation vector `angle` [rad], world
    (Rodrigues' formula)."""
    size = math.sqrt(angle[0] ** 2 + angle[1] ** 2 + angle[2] ** 2)
    if size == 0.0:
        return rotation.copy()
    k = angle / size
    skew = np.array(((0.0, -k[2], k[1]), (k[2], 0.0, -k[0]), (-k[1], k[0], 0.0)))
    turn = np.eye(3) + math.sin(size) * skew + (1.0 - math.cos(size)) * _product(skew, skew)
    return _product(turn, rotation)


@jit
def _solved(matrix, rhs):
    """x of the square system A x = rhs (m,): Gaussian elimination with partial pivoting, in
    plain loops; where a pivot falls to PIVOT of A's largest entry (a beam's spin about its
    own line moves nothing: a null direction), the least-squares, minimum-norm solution of
    `minimum_norm_solve` (the SVD, a dozen times the work)."""
    m = matrix.shape[0]
    a = matrix.copy()
    x = rhs.copy()
    largest = 0.0
    for i in range(m):
        for j in range(m):
            largest = max(largest, abs(a[i, j]))
    for k in range(m):
        pivot = k
        for i in range(k + 1, m):
            if abs(a[i, k]) > abs(a[pivot, k]):
                pivot = i
        if abs(a[pivot, k]) <= PIVOT * largest:
            return minimum_norm_solve(matrix, rhs)
        if pivot != k:
            for j in range(m):
                a[k, j], a[pivot, j] = a[pivot, j], a[k, j]
            x[k], x[pivot] = x[pivot], x[k]
        for i in range(k + 1, m):
            factor = a[i, k] / a[k, k]
            if factor != 0.0:
                for j in range(k, m):
                    a[i, j] -= factor * a[k, j]
                x[i] -= factor * x[k]
    for k in range(m - 1, -1, -1):
        total = x[k]
        for j in range(k + 1, m):
            total -= a[k, j] * x[j]
        x[k] = total / a[k, k]
    return x


@jit
def _level_start(uavs, lengths, attach):
    """(p (3,) [m], found): the body level under the centroid of s_i - b_i, at the mean depth
    its cables reach there (formation_geometry.hanging_payload's start); found False when a
    UAV stands farther from its attach point horizontally than its cable."""
    n = uavs.shape[0]
    centre = np.zeros(3)
    for j in range(n):
        for d in range(2):
            centre[d] += (uavs[j, d] - attach[j, d]) / n
    for j in range(n):
        span = math.sqrt((uavs[j, 0] - attach[j, 0] - centre[0]) ** 2
                         + (uavs[j, 1] - attach[j, 1] - centre[1]) ** 2)
        if span >= lengths[j]:
            return centre, False
        centre[2] += (uavs[j, 2] - math.sqrt(lengths[j] ** 2 - span ** 2) - attach[j, 2]) / n
    return centre, True


@jit
def hang_body(uavs, lengths, attach, load):
    """(p (3,) [m], R (3, 3) payload frame -> world, lambda (n,) [N/m], found): where a rigid
    body hangs at rest (module docstring) from UAVs at `uavs` (n, 3) [m] on cables of
    `lengths` (n,) [m] holding it at `attach` (n, 3) [m], payload frame, under `load` [N]
    (world: the support its apparent weight asks, m_p (g e_z + a)). Newton's method on the
    n + 6 equations in (p, a small turn theta of R, lambda), from the body level
    (`_level_start`); each step by `_solved` (elimination; a beam's spin about its own line
    moves nothing: a null direction, which the SVD's minimum norm leaves out). found False
    when a cable cannot reach the start or the residual does not settle to SETTLED of its
    scale; lambda may come out negative (a cable that would push: the caller's to refuse)."""
    n = uavs.shape[0]
    position, found = _level_start(uavs, lengths, attach)
    rotation = np.eye(3)
    weight = math.sqrt(load[0] ** 2 + load[1] ** 2 + load[2] ** 2)
    arm = 1e-3
    mean_length = 0.0
    for j in range(n):
        arm = max(arm, math.sqrt(attach[j, 0] ** 2 + attach[j, 1] ** 2 + attach[j, 2] ** 2))
        mean_length += lengths[j] / n
    multipliers = np.full(n, weight / (n * mean_length))
    if not found:
        return position, rotation, multipliers, False
    size = n + 6
    for _ in range(NEWTON_STEPS):
        residual = np.zeros(size)
        jacobian = np.zeros((size, size))
        settled = True
        for d in range(3):
            residual[n + d] = -load[d]
        for j in range(n):
            arm_j = _applied(rotation, attach[j])        # w_j = R b_j, world
            gap = uavs[j] - position - arm_j              # d_j
            lever = uavs[j] - position                    # s_j - p
            residual[j] = (gap[0] ** 2 + gap[1] ** 2 + gap[2] ** 2 - lengths[j] ** 2) / (
                2.0 * lengths[j])
            settled = settled and abs(residual[j]) <= SETTLED * lengths[j]
            twist = _cross(gap, arm_j)
            moment = _cross(arm_j, gap)
            for d in range(3):
                jacobian[j, d] = -gap[d] / lengths[j]     # dg_j / dp
                jacobian[j, 3 + d] = twist[d] / lengths[j]  # dg_j / dtheta
                residual[n + d] += multipliers[j] * gap[d]
                residual[n + 3 + d] += multipliers[j] * moment[d]
                jacobian[n + d, 6 + j] = gap[d]           # dF / dlambda_j
                jacobian[n + 3 + d, 6 + j] = moment[d]    # dM / dlambda_j
                jacobian[n + d, d] -= multipliers[j]      # dF / dp
            # dF / dtheta += lambda_j [w_j]x; dM / dp -= lambda_j [w_j]x;
            # dM / dtheta += lambda_j [s_j - p]x [w_j]x = lambda_j (w_j (s_j - p)^T - (.) I)
            skew = np.array(((0.0, -arm_j[2], arm_j[1]), (arm_j[2], 0.0, -arm_j[0]),
                             (-arm_j[1], arm_j[0], 0.0)))
            inner = lever[0] * arm_j[0] + lever[1] * arm_j[1] + lever[2] * arm_j[2]
            for a in range(3):
                for b in range(3):
                    jacobian[n + a, 3 + b] += multipliers[j] * skew[a, b]
                    jacobian[n + 3 + a, b] -= multipliers[j] * skew[a, b]
                    jacobian[n + 3 + a, 3 + b] += multipliers[j] * (
                        arm_j[a] * lever[b] - (inner if a == b else 0.0))
        force = math.sqrt(residual[n] ** 2 + residual[n + 1] ** 2 + residual[n + 2] ** 2)
        torque = math.sqrt(residual[n + 3] ** 2 + residual[n + 4] ** 2 + residual[n + 5] ** 2)
        if settled and force <= SETTLED * weight and torque <= SETTLED * weight * arm:
            return position, rotation, multipliers, True
        step = _solved(jacobian, -residual)
        for d in range(3):
            position[d] += step[d]
        rotation = _turned(rotation, step[3:6])
        for j in range(n):
            multipliers[j] += step[6 + j]
        if not np.all(np.isfinite(step)):
            return position, rotation, multipliers, False
    return position, rotation, multipliers, False


@jit
def body_tensions(constants, places, effective):
    """(T (n,) [N], e (n, 3), found) of a rigid-body payload (mass REORGANIZE_PAYLOAD_MASS,
    attach points REORGANIZE_UAV_ATTACH) hanging at rest (`hang_body`) from the UAVs at
    `places` (n, 3) [m] under the apparent gravity `effective` = g e_z + a [m/s^2]: each
    cable's tension T_i = lambda_i |d_i| and its unit vector e_i from the body up to UAV i;
    zeros where the body cannot hang."""
    n = places.shape[0]
    lengths = np.empty(n)
    attach = np.empty((n, 3))
    for j in range(n):
        row = REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j
        lengths[j] = constants[row + REORGANIZE_UAV_LENGTH]
        for d in range(3):
            attach[j, d] = constants[row + REORGANIZE_UAV_ATTACH + d]
    load = constants[REORGANIZE_PAYLOAD_MASS] * effective
    position, rotation, multipliers, found = hang_body(places, lengths, attach, load)
    tensions = np.zeros(n)
    units = np.zeros((n, 3))
    if not found:
        return tensions, units, False
    for j in range(n):
        gap = places[j] - position - _applied(rotation, attach[j])
        size = math.sqrt(gap[0] ** 2 + gap[1] ** 2 + gap[2] ** 2)
        tensions[j] = multipliers[j] * size
        units[j] = gap / size
    return tensions, units, True
