"""A rigid-body payload on the formation's cables (issue 20): the DAE's solve and residuals when
x carries the payload's attitude (`layout.PAYLOAD_ATTITUDE` after the UAVs' blocks). World frame (z
up),
SI units; the slots are `physics.layout`'s; docs/rigid_payload.md writes the equations out.

Cable i holds the payload at b_i (`UAV_PAYLOAD_ATTACH`, payload frame) and UAV i at its centre
of mass: with R_p the payload's attitude and e_i = R_p b_i,

    d_i = r_p + e_i - r_i,    g_i = |d_i|^2 - l_i^2,
    d_i_dot = v_p + w x e_i - v_i              (w = R_p omega_p, world),
    d_i_ddot = a_p + R_p (alpha_p x b_i) + w x (w x e_i) - a_i.

The cable's pull 2 lambda_i d_i acts on UAV i and -2 lambda_i d_i on the payload at b_i, whose
moment is b_i x (-2 lambda_i f_i), f_i = R_p^T d_i. With c_i = b_i x f_i the Baumgarte rows
(seed Eq. 2.59) become A Lambda = b with

    A_ij = 4 d_i.d_j / m_p + 4 c_i.J_p^-1 c_j + delta_ij 4 |d_i|^2 / m_i,
    b_i = 2 |d_i_dot|^2 + 2 d_i.(a_p0 - a_i0) + 2 c_i.alpha_0 + 2 d_i.(w x (w x e_i))
          + 2 alpha_f g_i_dot + beta_f^2 g_i,

a_p0, a_i0 the accelerations without the cables (gravity cancels), alpha_0 = J_p^-1 (-omega_p
x J_p omega_p). A = Delta + U W U^T with U_i = 2 (d_i, c_i) and W = diag(I / m_p, J_p^-1), so
the Woodbury identity leaves a 6 x 6 system, S = W^-1 + sum_i U_i U_i^T / delta_i: the point
payload's 3 x 3 (`formation_dae.cable_multipliers`) with the rotation's three rows added.
With every b_i = 0 it is the point payload's DAE (c_i = 0) and the attitude spins free.
"""
import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.free_motion import (add_cable_torque, attached_off_centre,
                                              cable_moment_arm, cross, payload_force_per_mass,
                                              rotational_compliance, uav_attach_motion,
                                              uav_free_motion)
from multilift_sim.physics.attitude import quaternion_rate
from multilift_sim.physics.attitude import quaternion_rotation as payload_rotation
from multilift_sim.physics.layout import (
    BODY_RATES, CABLE_INV_DELTA, CABLE_MOMENT, CABLE_OFFSET, CABLE_PAYLOAD_MOMENT, CABLE_RHS,
    CABLE_THRUST, FORMATION_BETA_SQ, FORMATION_GRAVITY, FORMATION_PAYLOAD_INERTIA,
    FORMATION_PAYLOAD_MASS, FORMATION_TWO_ALPHA, PAYLOAD_BODY_RATES,
    PAYLOAD_QUATERNION, POSITION, UAV_LENGTH_SQ, UAV_MASS, UAV_PAYLOAD_ATTACH)
from multilift_sim.physics.state_slots import (attitude_slot, payload_slot, rates_slot,
                                               uav_attitude_slot, uav_slot)
from multilift_sim.physics.nullspace import dense_solve
from multilift_sim.physics.winch import reeled_cable


@jit
def cable_geometry(x, uavs, i, rotation, omega_world, base, attach):
    """Cable i's (d_i, d_i_dot, e_i = R_p b_i) at x, world [m, m/s, m], as 3 + 3 + 3 floats;
    `attach` (3, 3): UAV i's attach point's offset, rate and acceleration
    (`free_motion.uav_attach_motion`; zeros for its centre of mass)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    r = uav_slot(i) + POSITION
    b0, b1, b2 = (uavs[i, UAV_PAYLOAD_ATTACH], uavs[i, UAV_PAYLOAD_ATTACH + 1],
                  uavs[i, UAV_PAYLOAD_ATTACH + 2])
    e0 = rotation[0, 0] * b0 + rotation[0, 1] * b1 + rotation[0, 2] * b2
    e1 = rotation[1, 0] * b0 + rotation[1, 1] * b1 + rotation[1, 2] * b2
    e2 = rotation[2, 0] * b0 + rotation[2, 1] * b1 + rotation[2, 2] * b2
    spin0, spin1, spin2 = cross(omega_world, (e0, e1, e2))
    d0 = x[p] + e0 - x[r] - attach[0, 0]
    d1 = x[p + 1] + e1 - x[r + 1] - attach[0, 1]
    d2 = x[p + 2] + e2 - x[r + 2] - attach[0, 2]
    v0 = x[nq + p] + spin0 - x[nq + r] - attach[1, 0]
    v1 = x[nq + p + 1] + spin1 - x[nq + r + 1] - attach[1, 1]
    v2 = x[nq + p + 2] + spin2 - x[nq + r + 2] - attach[1, 2]
    return d0, d1, d2, v0, v1, v2, e0, e1, e2


@jit
def world_rates(x, base, rotation):
    """The payload's angular velocity in the world frame, R_p omega_p (3,) [rad/s]."""
    w = np.empty(3)
    for k in range(3):
        w[k] = (rotation[k, 0] * x[base + PAYLOAD_BODY_RATES]
                + rotation[k, 1] * x[base + PAYLOAD_BODY_RATES + 1]
                + rotation[k, 2] * x[base + PAYLOAD_BODY_RATES + 2])
    return w


@jit
def rigid_cable_row(x, uavs, i, wrenches, rotation, w, base, attach, cables):
    """Cable i's row of G M^-1 G^T at x into cables[i]: d_i [m] (CABLE_OFFSET, world), c_i =
    b_i x R_p^T d_i [m^2] (CABLE_PAYLOAD_MOMENT, payload frame), k_i = a_i x R_i^T d_i [m^2]
    (CABLE_MOMENT, UAV i's body; 0 at its centre) and 1 / delta_i, delta_i = 4 |d_i|^2 / m_i
    + 4 k_i . J_i^-1 k_i (CABLE_INV_DELTA). `attach` (3, 3) gets UAV i's attach point's motion
    (`free_motion.uav_attach_motion` under `wrenches`; zeros at its centre). Returns d_i_dot
    [m/s], e_i = R_p b_i [m] (world) and |d_i|^2 [m^2] as 7 floats."""
    attach[:, :] = 0.0
    k0 = k1 = k2 = 0.0
    held_off_centre = attached_off_centre(uavs, i)
    if held_off_centre:
        uav_rotation_i = uav_attach_motion(x, i, wrenches, uavs, attach)
    d0, d1, d2, v0, v1, v2, e0, e1, e2 = cable_geometry(x, uavs, i, rotation, w, base, attach)
    if held_off_centre:
        k0, k1, k2 = cable_moment_arm(uavs, i, uav_rotation_i, d0, d1, d2)
    # f_i = R_p^T d_i, c_i = b_i x f_i (payload frame)
    f0 = rotation[0, 0] * d0 + rotation[1, 0] * d1 + rotation[2, 0] * d2
    f1 = rotation[0, 1] * d0 + rotation[1, 1] * d1 + rotation[2, 1] * d2
    f2 = rotation[0, 2] * d0 + rotation[1, 2] * d1 + rotation[2, 2] * d2
    c0, c1, c2 = cross((uavs[i, UAV_PAYLOAD_ATTACH], uavs[i, UAV_PAYLOAD_ATTACH + 1],
                        uavs[i, UAV_PAYLOAD_ATTACH + 2]), (f0, f1, f2))
    offset_sq = d0 * d0 + d1 * d1 + d2 * d2
    cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], cables[i, CABLE_OFFSET + 2] = \
        d0, d1, d2
    cables[i, CABLE_PAYLOAD_MOMENT], cables[i, CABLE_PAYLOAD_MOMENT + 1] = c0, c1
    cables[i, CABLE_PAYLOAD_MOMENT + 2] = c2
    cables[i, CABLE_MOMENT], cables[i, CABLE_MOMENT + 1], cables[i, CABLE_MOMENT + 2] = \
        k0, k1, k2
    cables[i, CABLE_INV_DELTA] = 1.0 / (4.0 * offset_sq / uavs[i, UAV_MASS]
                                        + 4.0 * rotational_compliance(uavs, i, k0, k1, k2))
    return v0, v1, v2, e0, e1, e2, offset_sq


@jit
def rigid_multipliers(cables, formation, taut, out):
    """Solve ``A_TT z = b_T`` over the taut cables T, z = 0 on the others, into out (n,): A =
    G M^-1 G^T of a rigid payload (the module docstring) from each cable's row of `cables`
    (CABLE_OFFSET d_i, CABLE_PAYLOAD_MOMENT c_i, CABLE_INV_DELTA, CABLE_RHS b_i;
    `rigid_cable_row`). Woodbury: A = Delta + U W U^T, U_i = 2 (d_i, c_i), W = diag(I / m_p,
    J_p^-1), A^-1 b = Delta^-1 (b - U y) with S y = U^T Delta^-1 b, S = W^-1 + sum_i U_i U_i^T
    / delta_i (6 x 6: the point payload's `formation_dae.cable_multipliers` with the
    rotation's three rows added)."""
    n = cables.shape[0]
    s = np.zeros((6, 6))
    for k in range(3):
        s[k, k] = formation[FORMATION_PAYLOAD_MASS]
        s[3 + k, 3 + k] = formation[FORMATION_PAYLOAD_INERTIA + k]
    sb = np.zeros(6)
    u = np.empty(6)
    for i in range(n):
        if not taut[i]:
            continue
        inv_delta = cables[i, CABLE_INV_DELTA]
        for k in range(3):
            u[k] = 2.0 * cables[i, CABLE_OFFSET + k]
            u[3 + k] = 2.0 * cables[i, CABLE_PAYLOAD_MOMENT + k]
        for a in range(6):
            sb[a] += u[a] * inv_delta * cables[i, CABLE_RHS]
            for b in range(6):
                s[a, b] += u[a] * u[b] * inv_delta
    y = dense_solve(s, sb)
    for i in range(n):
        if not taut[i]:
            out[i] = 0.0
            continue
        projection = 0.0
        for k in range(3):
            projection += (2.0 * cables[i, CABLE_OFFSET + k] * y[k]
                           + 2.0 * cables[i, CABLE_PAYLOAD_MOMENT + k] * y[3 + k])
        out[i] = (cables[i, CABLE_RHS] - projection) * cables[i, CABLE_INV_DELTA]


@jit
def rigid_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers, cables):
    """q_ddot into acc[:3n + 3] [m/s^2], the UAVs' attitude blocks' rates after it, the
    payload's block's rate (quaternion rate, then alpha_p [rad/s^2], payload frame) last, and
    Lambda into
    multipliers (n,) [N/m] at state x (see the module docstring); only `taut` cables pull.
    cables (n, CABLE_COLUMNS) scratch: each cable's row (`rigid_cable_row`; zeros when slack)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    base = attitude_slot(n)
    gravity = formation[FORMATION_GRAVITY]
    payload_mass = formation[FORMATION_PAYLOAD_MASS]
    inertia = formation[FORMATION_PAYLOAD_INERTIA:FORMATION_PAYLOAD_INERTIA + 3]
    rotation = payload_rotation(x, base)
    omega = x[base + PAYLOAD_BODY_RATES:base + PAYLOAD_BODY_RATES + 3]
    w = world_rates(x, base, rotation)
    drag0, drag1, drag2 = payload_force_per_mass(x[p], x[p + 1], x[p + 2], x[nq + p],
                                                 x[nq + p + 1], x[nq + p + 2], gusts, formation)
    # alpha_0 = J^-1 (-omega x J omega), principal axes (Euler's equations without the cables)
    h0, h1, h2 = cross(omega, (inertia[0] * omega[0], inertia[1] * omega[1],
                               inertia[2] * omega[2]))
    alpha0 = np.array([-h0 / inertia[0], -h1 / inertia[1], -h2 / inertia[2]])
    two_alpha, beta_sq = formation[FORMATION_TWO_ALPHA], formation[FORMATION_BETA_SQ]
    attach = np.zeros((3, 3))
    for i in range(n):
        thrust0, thrust1, thrust2 = uav_free_motion(x, i, wrenches, uavs, formation, acc)
        cables[i, CABLE_THRUST], cables[i, CABLE_THRUST + 1] = thrust0, thrust1
        cables[i, CABLE_THRUST + 2] = thrust2
        if not taut[i]:  # a slack cable holds nothing: a zero row
            cables[i, CABLE_RHS] = cables[i, CABLE_INV_DELTA] = 0.0
            for k in range(3):
                cables[i, CABLE_OFFSET + k] = cables[i, CABLE_PAYLOAD_MOMENT + k] = 0.0
                cables[i, CABLE_MOMENT + k] = 0.0
            continue
        v0, v1, v2, e0, e1, e2, offset_sq = rigid_cable_row(x, uavs, i, wrenches, rotation, w,
                                                            base, attach, cables)
        d0, d1, d2 = cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], \
            cables[i, CABLE_OFFSET + 2]
        c0, c1, c2 = cables[i, CABLE_PAYLOAD_MOMENT], cables[i, CABLE_PAYLOAD_MOMENT + 1], \
            cables[i, CABLE_PAYLOAD_MOMENT + 2]
        s0, s1, s2 = cross(w, (e0, e1, e2))
        cp0, cp1, cp2 = cross(w, (s0, s1, s2))  # w x (w x e_i)
        length_sq, reel_rate, reel_acc = reeled_cable(uavs, formation, i)  # physics.winch
        cables[i, CABLE_RHS] = (2.0 * (v0 * v0 + v1 * v1 + v2 * v2 - reel_acc)
                                + 2.0 * (d0 * (drag0 - thrust0 - attach[2, 0])
                                         + d1 * (drag1 - thrust1 - attach[2, 1])
                                         + d2 * (drag2 - thrust2 - attach[2, 2]))
                                + 2.0 * (c0 * alpha0[0] + c1 * alpha0[1] + c2 * alpha0[2])
                                + 2.0 * (d0 * cp0 + d1 * cp1 + d2 * cp2)
                                + two_alpha * 2.0 * (d0 * v0 + d1 * v1 + d2 * v2 - reel_rate)
                                + beta_sq * (offset_sq - length_sq))
    rigid_multipliers(cables, formation, taut, multipliers)
    pull0 = pull1 = pull2 = 0.0     # sum_j lambda_j d_j (world)
    turn0 = turn1 = turn2 = 0.0     # sum_j lambda_j c_j (payload frame)
    for i in range(n):
        lam = multipliers[i]
        d0, d1, d2 = cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], \
            cables[i, CABLE_OFFSET + 2]
        r = uav_slot(i) + POSITION
        pull = 2.0 * lam / uavs[i, UAV_MASS]
        acc[r] = cables[i, CABLE_THRUST] + pull * d0
        acc[r + 1] = cables[i, CABLE_THRUST + 1] + pull * d1
        acc[r + 2] = cables[i, CABLE_THRUST + 2] + pull * d2 - gravity
        if lam != 0.0 and attached_off_centre(uavs, i):  # the pull's moment on the UAV
            add_cable_torque(uavs, i, acc, uav_attitude_slot(n, i) - nq + BODY_RATES, 2.0 * lam,
                             cables[i, CABLE_MOMENT], cables[i, CABLE_MOMENT + 1],
                             cables[i, CABLE_MOMENT + 2])
        pull0 += lam * d0
        pull1 += lam * d1
        pull2 += lam * d2
        turn0 += lam * cables[i, CABLE_PAYLOAD_MOMENT]
        turn1 += lam * cables[i, CABLE_PAYLOAD_MOMENT + 1]
        turn2 += lam * cables[i, CABLE_PAYLOAD_MOMENT + 2]
    scale = 2.0 / payload_mass
    acc[p] = drag0 - scale * pull0
    acc[p + 1] = drag1 - scale * pull1
    acc[p + 2] = drag2 - scale * pull2 - gravity
    # the attitude block: q_dot = q (x) (0, omega) / 2, alpha = alpha_0 - 2 J^-1 sum lambda c
    rate = base - nq  # the block's derivative in acc
    (acc[rate + PAYLOAD_QUATERNION], acc[rate + PAYLOAD_QUATERNION + 1],
     acc[rate + PAYLOAD_QUATERNION + 2], acc[rate + PAYLOAD_QUATERNION + 3]) = quaternion_rate(
        x, base, omega[0], omega[1], omega[2])
    acc[rate + PAYLOAD_BODY_RATES] = alpha0[0] - 2.0 * turn0 / inertia[0]
    acc[rate + PAYLOAD_BODY_RATES + 1] = alpha0[1] - 2.0 * turn1 / inertia[1]
    acc[rate + PAYLOAD_BODY_RATES + 2] = alpha0[2] - 2.0 * turn2 / inertia[2]


@jit
def rigid_residuals(x, uavs, g, g_dot):
    """g_i = |d_i|^2 - l_i^2 [m^2] into g (n,) and g_dot_i = 2 d_i . d_i_dot [m^2/s] into
    g_dot (n,) at a state x with the payload's attitude."""
    n = uavs.shape[0]
    base = attitude_slot(n)
    rotation = payload_rotation(x, base)
    w = world_rates(x, base, rotation)
    attach = np.zeros((3, 3))
    for i in range(n):
        attach[:, :] = 0.0
        if attached_off_centre(uavs, i):
            uav_attach_motion(x, i, np.zeros((n, 4)), uavs, attach)
        d0, d1, d2, v0, v1, v2, _, _, _ = cable_geometry(x, uavs, i, rotation, w, base, attach)
        g[i] = d0 * d0 + d1 * d1 + d2 * d2 - uavs[i, UAV_LENGTH_SQ]
        g_dot[i] = 2.0 * (d0 * v0 + d1 * v1 + d2 * v2)
