"""The null-space formulation of the formation EOM (seed Eq. 2.71-2.72 closed by Eq. 2.57) and
its projection back onto the constraint manifold, on one formation's arrays (the `nullspace`
integrator: multilift_sim.nullspace.NullSpaceModel, which sets FORMATION_NULL_SPACE so that
`formation_dae.solve`, and with it RK4 and a control period, take q_ddot from here).

With N_f a basis of ker G_f (G_f N_f = 0, Eq. 2.71), projecting M_f q_ddot + C_f q_dot + f_g +
G_f^T Lambda = B_f u_f + d_f (Eq. 2.46) on N_f removes the constraint forces (Eq. 2.72); the n
equations it loses are the constraints at acceleration level (Eq. 2.57):

    [ N_t^T M_t ]            [ N_t^T f_t         ]
    [    G_t    ]  a_t    =  [ -G_dot_t q_dot_t  ]

on the translations t = (r_1, ..., r_n, r_p) (the attitude columns of G_f are zero, Eq. 2.66,
and M_f is block diagonal, Eq. 2.47, so N_f = blockdiag(N_t, I): each UAV's attitude is its
own Euler equation, `free_motion.uav_free_motion`). N_t: the last 2n + 3 columns of a complete
Householder QR of G_t^T. The multipliers, for the tensions, follow from G_t^T Lambda = f_t -
M_t a_t. Any basis of ker G_t gives the same a_t to rounding; unlike the multipliers' form, no
Baumgarte term: g drifts as the unstabilised DAE's unless `project` puts the state back.

Arguments as formation_dae's. Products in loops: no BLAS call (loading one imports scipy),
so `formation_dae.solve`, which calls `nullspace_solve` under FORMATION_NULL_SPACE, loads as
fast as before."""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.free_motion import payload_force_per_mass, uav_free_motion
from multilift_sim.physics.layout import (FORMATION_GRAVITY, FORMATION_PAYLOAD_MASS,
                                          POSITION,
                                          UAV_LENGTH_SQ, UAV_MASS)
from multilift_sim.physics.state_slots import payload_slot, rates_slot, uav_slot


@jit
def dense_solve(a, b):
    """x of a x = b for a square a (k, k) and b (k,) by Gaussian elimination with partial
    pivoting; a and b are overwritten."""
    k = b.shape[0]
    for col in range(k):
        pivot = col
        for row in range(col + 1, k):
            if abs(a[row, col]) > abs(a[pivot, col]):
                pivot = row
        if pivot != col:
            for c in range(k):
                a[col, c], a[pivot, c] = a[pivot, c], a[col, c]
            b[col], b[pivot] = b[pivot], b[col]
        for row in range(col + 1, k):
            factor = a[row, col] / a[col, col]
            if factor != 0.0:
                for c in range(col, k):
                    a[row, c] -= factor * a[col, c]
                b[row] -= factor * b[col]
    x = np.empty(k)
    for row in range(k - 1, -1, -1):
        total = b[row]
        for c in range(row + 1, k):
            total -= a[row, c] * x[c]
        x[row] = total / a[row, row]
    return x


@jit
def times(a, v):
    """a v for a (r, c), v (c,), in loops (no BLAS: loading it would import scipy); a^T v as
    times(a.T, v)."""
    out = np.zeros(a.shape[0])
    for i in range(a.shape[0]):
        total = 0.0
        for j in range(a.shape[1]):
            total += a[i, j] * v[j]
        out[i] = total
    return out


@jit
def times_transposed(a, b):
    """a b^T for a (r, c), b (s, c)."""
    out = np.empty((a.shape[0], b.shape[0]))
    for i in range(a.shape[0]):
        for k in range(b.shape[0]):
            total = 0.0
            for j in range(a.shape[1]):
                total += a[i, j] * b[k, j]
            out[i, k] = total
    return out


@jit
def complete_q(a):
    """Q (m, m) of a complete QR of a (m, k), m >= k, by Householder reflections
    (Q = H_1 ... H_k); its last m - k columns span the null space of a^T."""
    m, k = a.shape
    r = a.copy()
    vectors = np.zeros((k, m))
    for j in range(k):
        norm = 0.0
        for i in range(j, m):
            norm += r[i, j] * r[i, j]
        norm = math.sqrt(norm)
        alpha = -norm if r[j, j] >= 0.0 else norm
        v = vectors[j]
        for i in range(j, m):
            v[i] = r[i, j]
        v[j] -= alpha
        reflect(v, j, r, j, k)  # r <- H_j r
    q = np.eye(m)
    for j in range(k - 1, -1, -1):  # q <- H_j q, the last reflection first
        reflect(vectors[j], j, q, 0, m)
    return q


@jit
def reflect(v, j, a, first, last):
    """a[j:, first:last] <- (I - 2 v v^T / |v|^2) a[j:, first:last], the Householder
    reflection by v (its entries from j on); nothing for v = 0."""
    length = 0.0
    for i in range(j, v.shape[0]):
        length += v[i] * v[i]
    if length == 0.0:
        return
    for c in range(first, last):
        dot = 0.0
        for i in range(j, v.shape[0]):
            dot += v[i] * a[i, c]
        scale = 2.0 * dot / length
        for i in range(j, v.shape[0]):
            a[i, c] -= scale * v[i]


@jit
def translational_jacobian(x, n, jacobian):
    """G_t (n, 3n + 3) of g_i = |r_p - r_i|^2 - l_i^2 (Eq. 2.65) at state x: row i is
    -2 d_i on r_i and +2 d_i on r_p, d_i = r_p - r_i."""
    p = payload_slot(n)
    jacobian[:, :] = 0.0
    for i in range(n):
        r = uav_slot(i) + POSITION
        for axis in range(3):
            d = x[p + axis] - x[r + axis]
            jacobian[i, 3 * i + axis] = -2.0 * d
            jacobian[i, 3 * n + axis] = 2.0 * d


@jit
def translational_masses(uavs, formation):
    """diag M_t (3n + 3,) [kg]: each UAV's mass three times, then the payload's."""
    n = uavs.shape[0]
    masses = np.empty(3 * n + 3)
    for i in range(n):
        for axis in range(3):
            masses[3 * i + axis] = uavs[i, UAV_MASS]
    for axis in range(3):
        masses[3 * n + axis] = formation[FORMATION_PAYLOAD_MASS]
    return masses


@jit
def nullspace_solve(x, wrenches, uavs, gusts, formation, acc, multipliers):
    """q_ddot into acc[:3n + 3] (the attitude blocks' rates after it) and Lambda into multipliers
    (n,) [N/m] at state x by Eq.
    2.71-2.72 with Eq. 2.57 (every cable a constraint; see the module docstring)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    m = 3 * n + 3
    gravity = formation[FORMATION_GRAVITY]
    masses = translational_masses(uavs, formation)
    forces = np.empty(m)  # f_t [N]: thrust, own drag and weight; the payload's drag and weight
    for i in range(n):
        ax, ay, az = uav_free_motion(x, i, wrenches, uavs, formation, acc)
        mass = uavs[i, UAV_MASS]
        forces[3 * i] = mass * ax
        forces[3 * i + 1] = mass * ay
        forces[3 * i + 2] = mass * az - mass * gravity
    ax, ay, az = payload_force_per_mass(x[p], x[p + 1], x[p + 2], x[nq + p], x[nq + p + 1],
                                        x[nq + p + 2], gusts, formation)
    payload_mass = formation[FORMATION_PAYLOAD_MASS]
    forces[3 * n] = payload_mass * ax
    forces[3 * n + 1] = payload_mass * ay
    forces[3 * n + 2] = payload_mass * az - payload_mass * gravity
    jacobian = np.empty((n, m))
    translational_jacobian(x, n, jacobian)
    q = complete_q(np.ascontiguousarray(jacobian.T))
    system = np.empty((m, m))
    rhs = np.empty(m)
    for row in range(m - n):  # N_t^T M_t a = N_t^T f_t, N_t = q[:, n:]
        total = 0.0
        for c in range(m):
            system[row, c] = q[c, n + row] * masses[c]
            total += q[c, n + row] * forces[c]
        rhs[row] = total
    for i in range(n):  # G_t a = -G_dot_t q_dot_t = -2 |d_i_dot|^2 (Eq. 2.57)
        for c in range(m):
            system[m - n + i, c] = jacobian[i, c]
        r = uav_slot(i) + POSITION
        rate_sq = 0.0
        for axis in range(3):
            rate = x[nq + p + axis] - x[nq + r + axis]
            rate_sq += rate * rate
        rhs[m - n + i] = -2.0 * rate_sq
    accelerations = dense_solve(system, rhs)
    for i in range(n):
        r = uav_slot(i) + POSITION
        for axis in range(3):
            acc[r + axis] = accelerations[3 * i + axis]
    for axis in range(3):
        acc[p + axis] = accelerations[3 * n + axis]
    # the eliminated constraint forces: G_t^T Lambda = f_t - M_t a, by G_t G_t^T Lambda = G_t (.)
    residual_force = forces - masses * accelerations
    multipliers[:] = dense_solve(times_transposed(jacobian, jacobian),
                                 times(jacobian, residual_force))


@jit
def project(x, uavs, masses, tolerance, max_steps):
    """x (docs/conventions.md) moved onto the constraint manifold in place: positions by Newton
    steps dq = -M^-1 G^T (G M^-1 G^T)^-1 g until |g_i| <= tolerance l_i^2 (at most max_steps), then
    velocities dv = -M^-1 G^T (G M^-1 G^T)^-1 G v (exact: g_dot = G v is linear in v), with
    M_t = diag(`masses`) (3n + 3,) [kg] (`translational_masses`). Only the translations move
    (the attitude columns of G are zero)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    m = 3 * n + 3
    jacobian = np.empty((n, m))
    for _ in range(max_steps):
        residual = np.empty(n)
        inside = True
        for i in range(n):
            r = uav_slot(i) + POSITION
            total = 0.0
            for axis in range(3):
                d = x[p + axis] - x[r + axis]
                total += d * d
            residual[i] = total - uavs[i, UAV_LENGTH_SQ]
            if abs(residual[i]) > tolerance * uavs[i, UAV_LENGTH_SQ]:
                inside = False
        if inside:
            break
        translational_jacobian(x, n, jacobian)
        weighted = jacobian / masses  # G M^-1
        step = times(weighted.T, dense_solve(times_transposed(weighted, jacobian), residual))
        _move_translations(x, n, 0, step)
    translational_jacobian(x, n, jacobian)
    weighted = jacobian / masses
    velocities = np.empty(m)
    for i in range(n):
        r = uav_slot(i) + POSITION
        for axis in range(3):
            velocities[3 * i + axis] = x[nq + r + axis]
    for axis in range(3):
        velocities[3 * n + axis] = x[nq + p + axis]
    step = times(weighted.T, dense_solve(times_transposed(weighted, jacobian),
                                         times(jacobian, velocities)))
    _move_translations(x, n, nq, step)


@jit
def _move_translations(x, n, offset, step):
    """x[offset + translations] -= step (3n + 3,): the UAVs' r_i (or rates), then r_p's."""
    p = payload_slot(n)
    for i in range(n):
        r = offset + uav_slot(i) + POSITION
        for axis in range(3):
            x[r + axis] -= step[3 * i + axis]
    for axis in range(3):
        x[offset + p + axis] -= step[3 * n + axis]
