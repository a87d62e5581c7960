"""Formation control by virtual constraints (seed §3.2, Eq. 3.8-3.13): the force a follower's
thrust should produce to keep its rows of g_vc (`constraints`) and the leader's altitude, and
a follower's tick through the cascade (`cascade.command`): what every follower of a tick
shares, once (`formation_terms`), then each follower's own step (`follower_update`), O(n)
each. The law and its departures from the print are told in
`multilift_control.formation.FormationFollower`'s docstring.

constants: FOLLOWER_* slots, memory: FOLLOWER_INTEGRAL, _LAST_T, _LIFT, _YAW (layout);
masses: the m_i of M_f,r (n,) [kg]; rows, targets: the constraint rows; states (n,
UAV_STATE_SIZE) of every UAV, the leader (index 0) first; thrust_vectors (n, 3): each UAV's
lift R_i e_z u_T,i, world [N]. World frame z up."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.cascade import clipped, command, elapsed
from multilift_control.laws.constraints import (free_follower_motions, jacobian,
                                                jacobian_rate_product, residual, row_rate,
                                                rows_by_uav)
from multilift_control.laws.layout import (CASCADE_THRUST_COEFFICIENT,
                                           FOLLOWER_ALTITUDE_OFFSET, FOLLOWER_BETA_SQ,
                                           FOLLOWER_COMMANDED, FOLLOWER_FREE_MODE_GAIN,
                                           FOLLOWER_GRAVITY, FOLLOWER_HOVER_MASS,
                                           FOLLOWER_INTEGRAL, FOLLOWER_INTEGRAL_LIMIT,
                                           FOLLOWER_KD_Z, FOLLOWER_KI_Z, FOLLOWER_KP_Z,
                                           FOLLOWER_LAST_T, FOLLOWER_LEADER_CLIMB,
                                           FOLLOWER_LIFT, FOLLOWER_LINEAR,
                                           FOLLOWER_TWO_ALPHA, FOLLOWER_YAW, UAV_EULER,
                                           UAV_POSITION, UAV_VELOCITY)
from multilift_control.laws.linalg import minimum_norm_solve
from multilift_sim.physics.free_motion import thrust_axis
from multilift_control.laws.mixer import collective_thrust

_FREE_TOL = 1e-9  # singular values of the followers' columns that count as zero (relative)


@jit
def virtual_forces(rows, targets, masses, gravity, two_alpha, beta_sq, positions, velocities,
                   thrust_vectors):
    """Virtual constraint forces u_vf = -J_vc^T Lambda_c (seed Eq. 3.8-3.12), world frame:
    (u_vf (n, 3) [N], Lambda (m,) [N/m or N/m^2]). gravity g [m/s^2], two_alpha = 2 alpha_vc
    [1/s], beta_sq = beta_vc^2 [1/s^2]; positions, velocities (n, 3).

    With M = diag(m_i I_3), f_i = m_i g e_z (the weight moved to the left of Eq. 3.9, in the
    z-up frame) and the formation dynamics M r_ddot + f + J^T Lambda = u (Eq. 3.9), Lambda makes
    g_ddot + 2 alpha g_dot + beta^2 g = 0 (Eq. 3.8):

        Lambda = (J M^-1 J^T)^-1 (J M^-1 (u - f) + J_dot r_dot + 2 alpha J r_dot + beta^2 g_vc)

    Read from the print (Eq. 3.11-3.12): its M_c and J_c are M_f,r and J_vc; its "- c_c" is
    + v_c, so the stabilised residual is g_vc itself (J r + v_c, Eq. 3.6); the J_dot r_dot term
    is not printed (the V's rows are linear) and is added for the nonlinear rows.
    J M^-1 J^T is singular when J_vc loses row rank: a distance row whose two UAVs coincide,
    or circle rows whose UAVs are collinear; Lambda is then the least-squares, minimum-norm
    solution (`linalg.minimum_norm_solve`)."""
    n = positions.shape[0]
    m = rows.shape[0]
    jac = jacobian(rows, positions)
    driven = np.empty(3 * n)  # M^-1 (u - f)
    for j in range(n):
        for axis in range(3):
            weight = masses[j] * gravity if axis == 2 else 0.0  # f_j = m_j g e_z
            driven[3 * j + axis] = (1.0 / masses[j]) * (thrust_vectors[j, axis] - weight)
    g = residual(rows, targets, positions)
    curvature = jacobian_rate_product(rows, velocities)
    rhs = np.empty(m)  # Eq. 3.12
    a = np.empty((m, m))  # J M^-1 J^T
    for k in range(m):
        pushed = 0.0
        moving = 0.0
        for c in range(3 * n):
            pushed += jac[k, c] * driven[c]
            moving += jac[k, c] * velocities[c // 3, c % 3]
        rhs[k] = pushed + curvature[k] + two_alpha * moving + beta_sq * g[k]
        for other in range(m):
            total = 0.0
            for c in range(3 * n):
                total += jac[k, c] * (1.0 / masses[c // 3]) * jac[other, c]
            a[k, other] = total
    lam = minimum_norm_solve(a, rhs)
    u_vf = np.zeros((n, 3))
    for c in range(3 * n):
        total = 0.0
        for k in range(m):
            total += jac[k, c] * lam[k]
        u_vf[c // 3, c % 3] = -total
    return u_vf, lam


@jit
def free_mode_correction(masses, gain, index, positions, velocities, thrust_vectors, rows):
    """Horizontal force [N] (2,) for follower `index` that replaces, in the free follower
    motions (`constraints.free_follower_motions`), the followers' forces u_j by
    m_j (a_1 + k_f (v_1 - v_j)), a_1 = (u_1)_xy / m_1 the leader's horizontal thrust
    acceleration (the weight is vertical), gain k_f [1/s]; zero without free motions. Not in
    the seed: see FormationFollower."""
    basis = free_follower_motions(rows, positions, _FREE_TOL)
    correction = np.zeros(2)
    if basis.shape[1] == 0:
        return correction
    n = positions.shape[0]
    wanted = np.empty(2 * (n - 1))  # target - u over the followers' x, y
    for j in range(1, n):
        for axis in range(2):
            leader_accel = thrust_vectors[0, axis] / masses[0]
            target = masses[j] * (leader_accel + gain * (velocities[0, axis]
                                                         - velocities[j, axis]))
            wanted[2 * (j - 1) + axis] = target - thrust_vectors[j, axis]
    for k in range(basis.shape[1]):
        along = 0.0
        for c in range(2 * (n - 1)):
            along += basis[c, k] * wanted[c]
        for axis in range(2):
            correction[axis] += basis[2 * (index - 1) + axis, k] * along
    return correction


@jit
def driven_entry(masses, gravity, two_alpha, j, axis, force, velocity):
    """Entry 3 j + axis of M^-1 (u - f) + 2 alpha v, the vector the linear law's Q maps
    (`linear_virtual_force`): force u_j,axis [N], velocity v_j,axis [m/s], f_j = m_j g e_z."""
    weight = masses[j] * gravity if axis == 2 else 0.0
    return (1.0 / masses[j]) * (force - weight) + two_alpha * velocity


@jit
def formation_terms(constants, masses, rows, targets, states, thrust_vectors):
    """What the laws of every follower of one tick share, computed once in O(n + m) from the
    formation's states and thrust_vectors (the thrust book's, the same for every follower):
    `loaded_terms` with no static pulls (the seed's law: the cables' pulls are disturbances)."""
    return loaded_terms(constants, masses, rows, targets, states, thrust_vectors,
                        np.zeros((states.shape[0], 3)))


@jit
def loaded_terms(constants, masses, rows, targets, states, thrust_vectors, pulls):
    """`formation_terms` with each UAV's static load beyond its hover mass's weight in f of Eq.
    3.9: (positions (n, 3) [m], velocities (n, 3) [m/s], g_vc (m,), driven (3n,), row_start
    (n + 1,), row_index, pulls (n, 3) [N]), driven = M^-1 (u - pulls - f) + 2 alpha v
    (`driven_entry`) with u = thrust_vectors (a follower that feeds back its own lift replaces
    its 3 entries: `follower_force`), the rows of UAV j row_index[row_start[j]:row_start[j + 1]]
    (`constraints.rows_by_uav`). pulls (world [N]): the force each UAV's thrust spends on its
    cable at rest beyond the weight of its hover mass, T_j e_j - (M_j - m_j) g e_z (zeros: the
    seed's law; a formation that knows its statics, `laws.reorganize.static_pulls`), so a UAV
    tilted to hold its cable at rest is not accelerating in the law's eyes. constants: a
    follower's of the formation (its followers share FOLLOWER_GRAVITY and FOLLOWER_TWO_ALPHA).
    A follower's own step (`follower_force`, `follower_update`) then touches its own rows and
    columns only."""
    n = states.shape[0]
    positions = np.empty((n, 3))
    velocities = np.empty((n, 3))
    for j in range(n):
        for axis in range(3):
            positions[j, axis] = states[j, UAV_POSITION + axis]
            velocities[j, axis] = states[j, UAV_VELOCITY + axis]
    driven = np.empty(3 * n)
    for j in range(n):
        for axis in range(3):
            driven[3 * j + axis] = driven_entry(
                masses, constants[FOLLOWER_GRAVITY], constants[FOLLOWER_TWO_ALPHA], j, axis,
                thrust_vectors[j, axis] - pulls[j, axis], velocities[j, axis])
    row_start, row_index = rows_by_uav(rows, n)
    return (positions, velocities, residual(rows, targets, positions), driven, row_start,
            row_index, pulls)


@jit
def linear_virtual_force(constants, law_p, law_q, index, driven, own_driven, g):
    """This follower's u_vf,i (3,) [N] for linear (and V) rows, where J_vc and M are constant:
    u_vf,i = Q (M^-1 (u - f) + 2 alpha v) + beta^2 P g_vc (J_dot = 0), law_p = P (3, m),
    law_q = Q (3, 3n) (FormationFollower._linear_law_matrices): O(n) per tick instead of the
    O(n^3) solve of `virtual_forces`. driven: M^-1 (u - f) + 2 alpha v (3n,) of the tick
    (`formation_terms`) but for this follower's own 3 entries, own_driven (3,); g: g_vc (m,).
    The three axes' sums run side by side, each in the order of c and k."""
    first = 3 * index
    pushed_x = pushed_y = pushed_z = 0.0
    for c in range(driven.shape[0]):
        d = own_driven[c - first] if first <= c < first + 3 else driven[c]
        pushed_x += law_q[0, c] * d
        pushed_y += law_q[1, c] * d
        pushed_z += law_q[2, c] * d
    held_x = held_y = held_z = 0.0
    for k in range(g.shape[0]):
        held_x += law_p[0, k] * g[k]
        held_y += law_p[1, k] * g[k]
        held_z += law_p[2, k] * g[k]
    beta_sq = constants[FOLLOWER_BETA_SQ]
    out = np.empty(3)
    out[0] = pushed_x + beta_sq * held_x
    out[1] = pushed_y + beta_sq * held_y
    out[2] = pushed_z + beta_sq * held_z
    return out


@jit
def follower_force(constants, masses, rows, targets, law_p, law_q, index, memory, t,
                   thrust_vectors, terms):
    """(F world [N] (3,), this follower's rows of g_vc [m or m^2], their rates [m/s or
    m^2/s]) at t [s]: the force the thrust should produce before Eq. 3.13, and the altitude
    integral advanced in memory. terms: the tick's `formation_terms` of these thrust_vectors.

    horizontal: F_xy = (u_i + u_vf,i)_xy (+ `free_mode_correction` with FOLLOWER_FREE_MODE_GAIN
    on and nonlinear rows: linear rows have no free motions), u_i the lift asked at the last
    tick when FOLLOWER_COMMANDED (memory), else thrust_vectors[i]; vertical: the altitude loop
    to z_1 + FOLLOWER_ALTITUDE_OFFSET."""
    positions, velocities, g, driven, row_start, row_index, pulls = terms
    own = thrust_vectors[index].copy()  # u_i
    if constants[FOLLOWER_COMMANDED] != 0.0 and not math.isnan(memory[FOLLOWER_LIFT]):
        for axis in range(3):
            own[axis] = memory[FOLLOWER_LIFT + axis]
    force = np.empty(3)
    if constants[FOLLOWER_LINEAR] != 0.0:
        own_driven = np.empty(3)
        for axis in range(3):
            own_driven[axis] = driven_entry(
                masses, constants[FOLLOWER_GRAVITY], constants[FOLLOWER_TWO_ALPHA], index, axis,
                own[axis] - pulls[index, axis], velocities[index, axis])
        u_vf = linear_virtual_force(constants, law_p, law_q, index, driven, own_driven, g)
        for axis in range(2):
            force[axis] = own[axis] + u_vf[axis]
    else:
        u = thrust_vectors.copy()
        for axis in range(3):
            u[index, axis] = own[axis]
        for j in range(u.shape[0]):  # the law's u - pulls (terms: `loaded_terms`)
            for axis in range(3):
                u[j, axis] -= pulls[j, axis]
        u_vf_all, _ = virtual_forces(rows, targets, masses, constants[FOLLOWER_GRAVITY],
                                     constants[FOLLOWER_TWO_ALPHA], constants[FOLLOWER_BETA_SQ],
                                     positions, velocities, u)
        for axis in range(2):
            force[axis] = own[axis] + u_vf_all[index, axis]
        gain = constants[FOLLOWER_FREE_MODE_GAIN]
        if not math.isnan(gain):  # not in the seed: see FormationFollower
            correction = free_mode_correction(masses, gain, index, positions, velocities, u,
                                              rows)
            for axis in range(2):
                force[axis] += correction[axis]
    dt = elapsed(memory, FOLLOWER_LAST_T, t)
    # z_d,i = z_1 (seed §3.2, after Eq. 3.13), a reference the outer loop updates each tick:
    # the damping acts on the follower's own climb rate, not on z_1_dot - z_i_dot, hence
    # the follower's lag in the climb (§4.3, Fig. 4.7) and the leader's larger thrust
    # (Fig. 4.8); with FOLLOWER_LEADER_CLIMB on z_1_dot - z_i_dot (not in the seed)
    error = positions[0, 2] + constants[FOLLOWER_ALTITUDE_OFFSET] - positions[index, 2]
    error_rate = -velocities[index, 2]
    if constants[FOLLOWER_LEADER_CLIMB] != 0.0:
        error_rate += velocities[0, 2]
    memory[FOLLOWER_INTEGRAL] = clipped(
        memory[FOLLOWER_INTEGRAL] + constants[FOLLOWER_KI_Z] * error * dt,
        constants[FOLLOWER_INTEGRAL_LIMIT])
    force[2] = constants[FOLLOWER_HOVER_MASS] * (
        constants[FOLLOWER_GRAVITY] + constants[FOLLOWER_KP_Z] * error
        + constants[FOLLOWER_KD_Z] * error_rate + memory[FOLLOWER_INTEGRAL])
    first, last = row_start[index], row_start[index + 1]
    errors = np.empty(last - first)
    rates = np.empty(last - first)
    for k in range(first, last):
        errors[k - first] = g[row_index[k]]
        rates[k - first] = row_rate(rows, positions, velocities, row_index[k])
    return force, errors, rates


@jit
def follower_update(constants, masses, rows, targets, law_p, law_q, index, memory, t, states,
                    thrust_vectors, terms, cascade_constants, mixer):
    """One follower's tick at t [s]: `follower_force` (terms: the tick's `formation_terms`),
    Eq. 3.13 and the cascade's attitude loop and mixer at the held heading (memory FOLLOWER_YAW:
    the one measured at the first tick when NaN), and the lift the rotors give after saturation
    along the thrust axis asked for, kept in memory (FOLLOWER_LIFT). cascade_constants:
    CASCADE_* slots, mixer: MIXER_* rows. Returns (speeds [rad/s], saturated, setpoint [rad],
    thrust [N], rows of g_vc, their rates)."""
    if math.isnan(memory[FOLLOWER_YAW]):
        memory[FOLLOWER_YAW] = states[index, UAV_EULER + 2]  # hold the initial heading
    force, errors, rates = follower_force(constants, masses, rows, targets, law_p, law_q,
                                          index, memory, t, thrust_vectors, terms)
    speeds, saturated, setpoint, thrust = command(cascade_constants, mixer, states[index],
                                                  force, memory[FOLLOWER_YAW])
    lifted = collective_thrust(cascade_constants[CASCADE_THRUST_COEFFICIENT], speeds)
    axis = thrust_axis(setpoint[0], setpoint[1], setpoint[2])
    for k in range(3):
        memory[FOLLOWER_LIFT + k] = axis[k] * lifted
    return speeds, saturated, setpoint, thrust, errors, rates


@jit
def follower_tick(constants, masses, rows, targets, law_p, law_q, index, memory, t, states,
                  thrust_vectors, cascade_constants, mixer):
    """One follower's tick at t [s] where it is the only one to answer the formation's states
    and thrust_vectors (a follower node, `FormationFollower.update`), in one call: the tick's
    `formation_terms`, then its `follower_update` (the engine computes the terms once for every
    follower, `engine.tick.answer_formation`). Returns `follower_update`'s result."""
    terms = formation_terms(constants, masses, rows, targets, states, thrust_vectors)
    return follower_update(constants, masses, rows, targets, law_p, law_q, index, memory, t,
                           states, thrust_vectors, terms, cascade_constants, mixer)


@jit
def lift_vectors(states, thrusts):
    """Every UAV's lift R_j e_z u_T,j, world [N] (n, 3), of the states' attitudes and the
    collective thrusts u_T,j [N] (n,): the thrust vectors u_f,r of Eq. 3.9-3.12."""
    n = states.shape[0]
    out = np.empty((n, 3))
    for j in range(n):
        axis = thrust_axis(states[j, UAV_EULER], states[j, UAV_EULER + 1],
                           states[j, UAV_EULER + 2])
        for k in range(3):
            out[j, k] = axis[k] * thrusts[j]
    return out
