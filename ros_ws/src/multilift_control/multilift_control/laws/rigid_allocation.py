"""Cable-force allocation for a rigid-body payload (`formation.reorganize: cable_forces`, issue
35 item 3; `laws.cable_forces.allocate` calls `body_allocated_places` when REORGANIZE_RIGID is
set): the cable forces f_i at the attach points b_i that give the body, held level, the wrench
its apparent weight asks (the force m_p (g e_z + a), no torque about its centre of mass: the
rigid body's rows of Eq. 2.73 with R = I),

    A f = w,   A = [I ... I; [b_1]x ... [b_n]x] (6, 3n),   w = (m_p (g e_z + a), 0),

with the least effort under the thrust limits: the weighted least norm, min sum |f_i|^2 / c_i
with c_i = u_T,max,i - m_i |g e_z + a| (the thrust UAV i has left for its cable), f_0 = C A^T
(A C A^T)^+ w; plus the internal force N z (A N = 0: it moves no part of the wrench) that
spreads the cables as the formation's places did at the start: UAV i out along its attach
point's horizontal direction u_i at REORGANIZE_RADIUS from the body's centre (the horizontal
part of f_i as close as least squares can bring it to t_i f_0,i,z u_i, t_i the slope of a cable
reaching that far; the minimum-norm z leaves f_0's vertical parts as they are). Each UAV then
flies where its cable pulls its force, b_i + l_i f_i / |f_i|.
World frame z up, SI units; places relative to the leader [m]."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (REORGANIZE_PAYLOAD_MASS, REORGANIZE_RADIUS,
                                           REORGANIZE_UAV_ATTACH, REORGANIZE_UAV_LARGEST,
                                           REORGANIZE_UAV_LENGTH, REORGANIZE_UAV_MASS,
                                           REORGANIZE_UAV_SIZE, REORGANIZE_UAVS)
from multilift_control.laws.linalg import minimum_norm_solve, right_singular

LEAST_SPARE = 1e-3  # a UAV's spare thrust counts as at least this share of its largest [-]


@jit
def wrench_rows(attach):
    """A (6, 3n): the wrench (force [N], torque about the centre of mass [N m]) on the level
    body of cable forces f (3n,) at the attach points `attach` (n, 3) [m]."""
    n = attach.shape[0]
    rows = np.zeros((6, 3 * n))
    for j in range(n):
        b = attach[j]
        for d in range(3):
            rows[d, 3 * j + d] = 1.0
        rows[3, 3 * j + 1], rows[3, 3 * j + 2] = -b[2], b[1]
        rows[4, 3 * j + 0], rows[4, 3 * j + 2] = b[2], -b[0]
        rows[5, 3 * j + 0], rows[5, 3 * j + 1] = -b[1], b[0]
    return rows


@jit
def least_effort_forces(rows, wrench, spare):
    """f (3n,) [N]: the least sum |f_i|^2 / spare_i with rows f = wrench (the weighted least
    norm spare-scaled C A^T (A C A^T)^+ w, `minimum_norm_solve` where A C A^T is singular: a
    beam's spin about its line)."""
    size = rows.shape[1]
    weighted = np.zeros((6, size))
    for k in range(size):
        for a in range(6):
            weighted[a, k] = rows[a, k] * spare[k // 3]
    product = np.zeros((6, 6))
    for a in range(6):
        for b in range(6):
            for k in range(size):
                product[a, b] += weighted[a, k] * rows[b, k]
    y = minimum_norm_solve(product, wrench)
    forces = np.zeros(size)
    for k in range(size):
        for a in range(6):
            forces[k] += weighted[a, k] * y[a]
    return forces


@jit
def internal_forces(rows):
    """N (3n, k): an orthonormal basis of the internal forces, A N = 0 (the right singular
    vectors of A whose values are below 1e-12 of the largest)."""
    size = rows.shape[1]
    square = np.zeros((size, size))  # A padded to square: its q - 6 extra zero rows
    for a in range(6):
        for k in range(size):
            square[a, k] = rows[a, k]
    values, basis, _ = right_singular(square)
    largest = values.max()
    count = 0
    for k in range(size):
        if values[k] <= 1e-12 * largest:
            count += 1
    null = np.zeros((size, count))
    column = 0
    for k in range(size):
        if values[k] <= 1e-12 * largest:
            for j in range(size):
                null[j, column] = basis[j, k]
            column += 1
    return null


@jit
def body_cable_forces(constants, effective):
    """f (n, 3) [N], world: the least-effort cable forces on the level body (module docstring)
    under the apparent gravity `effective` = g e_z + a [m/s^2], spread by internal forces as the
    formation was at the start (REORGANIZE_RADIUS)."""
    n = (constants.shape[0] - REORGANIZE_UAVS) // REORGANIZE_UAV_SIZE
    weight = math.sqrt(effective[0] ** 2 + effective[1] ** 2 + effective[2] ** 2)
    attach = np.empty((n, 3))
    spare = np.empty(n)
    slope = np.zeros(n)
    for j in range(n):
        row = REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j
        for d in range(3):
            attach[j, d] = constants[row + REORGANIZE_UAV_ATTACH + d]
        largest = constants[row + REORGANIZE_UAV_LARGEST]
        spare[j] = max(largest - constants[row + REORGANIZE_UAV_MASS] * weight,
                       LEAST_SPARE * largest)
        out = constants[REORGANIZE_RADIUS] - math.sqrt(attach[j, 0] ** 2 + attach[j, 1] ** 2)
        length = constants[row + REORGANIZE_UAV_LENGTH]
        if 0.0 < out < length:
            slope[j] = out / math.sqrt(length ** 2 - out ** 2)
    rows = wrench_rows(attach)
    wrench = np.zeros(6)
    for d in range(3):
        wrench[d] = constants[REORGANIZE_PAYLOAD_MASS] * effective[d]
    forces = least_effort_forces(rows, wrench, spare)
    null = internal_forces(rows)
    # the spread's misfit r = (f_0 + N z)_h - t_j f_0,j,z u_j: each force's horizontal part
    # against the start's slope times its least-effort vertical part (which the internal
    # forces fitting r then leave alone: a vertical internal force moves no horizontal part)
    k = null.shape[1]
    if k > 0:
        moved = np.zeros((2 * n, k))  # the horizontal rows of N
        misfit = np.zeros(2 * n)
        for j in range(n):
            radial = math.sqrt(attach[j, 0] ** 2 + attach[j, 1] ** 2)
            for d in range(2):
                misfit[2 * j + d] = forces[3 * j + d]
                if radial > 0.0:
                    misfit[2 * j + d] -= slope[j] * forces[3 * j + 2] * attach[j, d] / radial
                for a in range(k):
                    moved[2 * j + d, a] = null[3 * j + d, a]
        normal = np.zeros((k, k))
        right = np.zeros(k)
        for a in range(k):
            for r in range(2 * n):
                right[a] -= moved[r, a] * misfit[r]
                for b in range(k):
                    normal[a, b] += moved[r, a] * moved[r, b]
        z = minimum_norm_solve(normal, right)
        for q in range(3 * n):
            for a in range(k):
                forces[q] += null[q, a] * z[a]
    return forces.reshape((n, 3))


@jit
def body_allocated_places(constants, effective):
    """The UAVs' places relative to the leader (n, 3) [m] where level cables pull the
    body's `body_cable_forces`: b_i + l_i f_i / |f_i| (the body's centre at the origin), less
    the leader's."""
    forces = body_cable_forces(constants, effective)
    n = forces.shape[0]
    places = np.zeros((n, 3))
    for j in range(n):
        row = REORGANIZE_UAVS + REORGANIZE_UAV_SIZE * j
        size = math.sqrt(forces[j, 0] ** 2 + forces[j, 1] ** 2 + forces[j, 2] ** 2)
        for d in range(3):
            places[j, d] = (constants[row + REORGANIZE_UAV_ATTACH + d]
                            + constants[row + REORGANIZE_UAV_LENGTH] * forces[j, d] / size)
    leader = places[0].copy()
    for j in range(n):
        for d in range(3):
            places[j, d] -= leader[d]
    return places
