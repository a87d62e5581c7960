"""The formation DAE (seed Eq. 2.41-2.70) on one formation's arrays: the payload's drag and
gusts, the solve for q_ddot and the cable multipliers, RK4 over a control period, the
constraint residuals. World frame (z up), SI units; the array slots are `physics.layout`'s.

Arguments shared by the functions: ``x`` the state (docs/conventions.md: the translations'
(q, q_dot), 2 (3n + 3), then the bodies' attitude blocks); ``wrenches`` (n,
WRENCH_COLUMNS) the body wrenches (u_T [N], tau [N m], FLU), held; ``uavs`` (n, UAV_COLUMNS),
``gusts`` (k, GUST_COLUMNS) and ``formation`` (FORMATION_SCALARS,) the constants;
``taut`` (n,) bool: which cables are constraints (a slack cable has multiplier 0 and leaves
UAV i and the payload free of each other); ``cables`` (n, CABLE_COLUMNS) and ``work``
(WORK_ROWS, len(x)) scratch.

The equations (dynamics.py's docstring): with f the unconstrained forces,
``Lambda = (G M^-1 G^T)^-1 (G M^-1 f + G_dot q_dot + 2 alpha_f g_dot + beta_f^2 g)`` and
``q_ddot = M^-1 (f - G^T Lambda)`` (Eq. 2.60/2.70 with the signs gathered), never forming
the mass matrix: each UAV's attitude on its own (its quaternion and body rates), and the n x n
cable system by the
Woodbury identity (`cable_multipliers`).
"""
import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.free_motion import (add_cable_torque, air_velocity,  # noqa: F401
                                              attached_off_centre, cable_moment_arm,
                                              payload_force_per_mass, payload_motion,
                                              payload_pulled,
                                              rotational_compliance,
                                              uav_attach_motion, uav_free_motion)
from multilift_sim.physics.chain_cables import chain_residuals, chain_solve
from multilift_sim.physics.elastic_cables import elastic_solve
from multilift_sim.physics.nullspace import nullspace_solve, project, translational_masses
from multilift_sim.physics.attitude import normalize_quaternion
from multilift_sim.physics.prescribed import prescribed_solve
from multilift_sim.physics.rigid_payload import rigid_residuals, rigid_solve
from multilift_sim.physics.winch import reeled_cable
from multilift_sim.physics.layout import (
    BODY_ATTITUDE, BODY_RATES, CABLE_COLUMNS, CABLE_INV_DELTA, CABLE_MOMENT, CABLE_OFFSET,
    CABLE_RHS, CABLE_THRUST, FORMATION_BETA_SQ, FORMATION_CHAIN_LINKS, FORMATION_ELASTIC,
    FORMATION_GRAVITY, FORMATION_NULL_SPACE, FORMATION_PAYLOAD_MASS,
    FORMATION_PRESCRIBED, FORMATION_PROJECTION_STEPS, FORMATION_PROJECTION_TOLERANCE,
    FORMATION_TIME, FORMATION_TWO_ALPHA, FORMATION_WINCH, NODE_STATE, POSITION, UAV_LENGTH_SQ,
    UAV_MASS,
    WORK_ACC, WORK_K1, WORK_K2, WORK_K3, WORK_K4, WORK_MULTIPLIERS, WORK_ROWS, WORK_STAGE)
from multilift_sim.physics.symmetric_solve import symmetric_solve3
from multilift_sim.physics.state_slots import (chain_inner_nodes, payload_slot, rates_slot,
                                               rigid_payload_state, uav_attitude_slot,
                                               uav_slot)


@jit
def cable_multipliers(cables, payload_mass, taut, out):
    """Solve ``A_TT z = b_T`` over the taut cables T, z = 0 on the others, into out (n,):
    A = G M^-1 G^T (Eq. 2.60) from each cable's row of `cables` (CABLE_OFFSET d_i [m],
    CABLE_INV_DELTA, CABLE_RHS b_i), payload_mass m_p [kg].

    The Woodbury identity on ``A = Delta + 4 D D^T / m_p`` with ``Delta = diag(delta_i)``,
    ``delta_i = 4 |d_i|^2 / m_i``: ``A^-1 b = Delta^-1 (b - D y)`` where
    ``S y = D^T Delta^-1 b`` and ``S = m_p/4 I + sum_i d_i d_i^T / delta_i``
    = ``(m_p I + sum_i m_i e_i e_i^T) / 4`` (e_i the cable directions): a 3 x 3 system, the
    payload's effective mass, always invertible (m_p / 4 I with every cable slack)."""
    n = cables.shape[0]
    # S (symmetric, entries s_jk) and its right-hand side D^T Delta^-1 b (sb_j)
    s00 = s11 = s22 = 0.25 * payload_mass
    s01 = s02 = s12 = sb0 = sb1 = sb2 = 0.0
    for i in range(n):
        if not taut[i]:
            continue
        dx, dy, dz = cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], \
            cables[i, CABLE_OFFSET + 2]
        inv_delta = cables[i, CABLE_INV_DELTA]
        s00 += dx * dx * inv_delta
        s01 += dx * dy * inv_delta
        s02 += dx * dz * inv_delta
        s11 += dy * dy * inv_delta
        s12 += dy * dz * inv_delta
        s22 += dz * dz * inv_delta
        weighted_rhs = cables[i, CABLE_RHS] * inv_delta
        sb0 += dx * weighted_rhs
        sb1 += dy * weighted_rhs
        sb2 += dz * weighted_rhs
    y0, y1, y2 = symmetric_solve3(s00, s01, s02, s11, s12, s22, sb0, sb1, sb2)  # S^-1 sb
    for i in range(n):
        if taut[i]:
            out[i] = (cables[i, CABLE_RHS] - cables[i, CABLE_OFFSET] * y0
                      - cables[i, CABLE_OFFSET + 1] * y1
                      - cables[i, CABLE_OFFSET + 2] * y2) * cables[i, CABLE_INV_DELTA]
        else:
            out[i] = 0.0


@jit
def inverse_delta(uavs, i, offset_sq, k0, k1, k2):
    """1 / delta_i [kg/m^2] of cable i's diagonal of G M^-1 G^T (point payload), |d_i|^2 =
    offset_sq [m^2]: delta_i = 4 |d_i|^2 / m_i, plus 4 k_i . J_i^-1 k_i when the cable holds
    UAV i off its centre (k_i [m^2], `free_motion.cable_moment_arm`; all 0 at its centre)."""
    if k0 == 0.0 and k1 == 0.0 and k2 == 0.0:
        return 0.25 * uavs[i, UAV_MASS] / offset_sq
    return 1.0 / (4.0 * offset_sq / uavs[i, UAV_MASS]
                  + 4.0 * rotational_compliance(uavs, i, k0, k1, k2))


@jit
def solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers, cables):
    """q_ddot into acc[:3n + 3] [m/s^2], the attitude blocks' rates after it (each UAV's
    quaternion rate and omega_dot [rad/s^2], then a rigid payload's), and the cable
    multipliers Lambda into multipliers (n,) [N/m] at state x (seed Eq. 2.60, 2.70), only the
    `taut` cables constrained. Rotor speeds enter as the held body wrenches."""
    if formation[FORMATION_ELASTIC] != 0.0:  # elastic ropes, no constraint (elastic_cables)
        elastic_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers)
        return
    if formation[FORMATION_CHAIN_LINKS] != 0.0:  # heavy cables of rigid links (chain_cables)
        chain_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers)
        return
    if formation[FORMATION_NULL_SPACE] != 0.0:  # the `nullspace` formulation (every cable taut)
        nullspace_solve(x, wrenches, uavs, gusts, formation, acc, multipliers)
        return
    if formation[FORMATION_PRESCRIBED] != 0.0:  # driven UAVs (uavs[i].trajectory)
        prescribed_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers, cables)
        return
    if rigid_payload_state(x.shape[0], uavs.shape[0]):
        # a rigid-body payload (its attitude block after the UAVs': physics.rigid_payload)
        rigid_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers, cables)
        return
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    px, py, pz, pvx, pvy, pvz, drag_ax, drag_ay, drag_az = payload_motion(x, n, gusts,
                                                                          formation)
    two_alpha, beta_sq = formation[FORMATION_TWO_ALPHA], formation[FORMATION_BETA_SQ]
    gravity = formation[FORMATION_GRAVITY]
    for i in range(n):
        # l_i^2 and a reeled length's terms of g_dot and g_ddot (physics.winch; 0 without)
        length_sq, reel_rate, reel_acc = reeled_cable(uavs, formation, i)
        r = uav_slot(i) + POSITION
        rx, ry, rz = x[r], x[r + 1], x[r + 2]
        vx, vy, vz = x[nq + r], x[nq + r + 1], x[nq + r + 2]
        thrust_ax, thrust_ay, thrust_az = uav_free_motion(x, i, wrenches, uavs, formation, acc)

        # cable i: d = r_p - r_i, its rate, and row i of the multiplier equation (Eq. 2.60)
        free_x, free_y, free_z = thrust_ax, thrust_ay, thrust_az  # the cable end's, uncabled
        k0 = k1 = k2 = 0.0
        if attached_off_centre(uavs, i):  # held at a_i: d from r_i + R_i a_i (issue 20)
            attach = np.empty((3, 3))
            rotation = uav_attach_motion(x, i, wrenches, uavs, attach)
            rx, ry, rz = rx + attach[0, 0], ry + attach[0, 1], rz + attach[0, 2]
            vx, vy, vz = vx + attach[1, 0], vy + attach[1, 1], vz + attach[1, 2]
            free_x, free_y = thrust_ax + attach[2, 0], thrust_ay + attach[2, 1]
            free_z = thrust_az + attach[2, 2]
            k0, k1, k2 = cable_moment_arm(uavs, i, rotation, px - rx, py - ry, pz - rz)
        dx, dy, dz = px - rx, py - ry, pz - rz
        dvx, dvy, dvz = pvx - vx, pvy - vy, pvz - vz
        offset_sq = dx * dx + dy * dy + dz * dz
        cables[i, CABLE_RHS] = (
            2.0 * (dx * (drag_ax - free_x) + dy * (drag_ay - free_y)
                   + dz * (drag_az - free_z))                          # G M^-1 f
            + 2.0 * (dvx * dvx + dvy * dvy + dvz * dvz - reel_acc)     # G_dot q_dot
            + two_alpha * 2.0 * (dx * dvx + dy * dvy + dz * dvz - reel_rate)  # 2 alpha_f g_dot
            + beta_sq * (offset_sq - length_sq))                       # beta_f^2 g
        # G M^-1 G^T = diag(4 |d_i|^2 / m_i) + 4 D D^T / m_p: 1 / delta_i of the diagonal
        # (held off its centre, the UAV's rotation adds 4 k_i . J_i^-1 k_i to delta_i)
        cables[i, CABLE_INV_DELTA] = inverse_delta(uavs, i, offset_sq, k0, k1, k2)
        cables[i, CABLE_MOMENT], cables[i, CABLE_MOMENT + 1], cables[i, CABLE_MOMENT + 2] = \
            k0, k1, k2
        cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], cables[i, CABLE_OFFSET + 2] = \
            dx, dy, dz
        cables[i, CABLE_THRUST], cables[i, CABLE_THRUST + 1], cables[i, CABLE_THRUST + 2] = \
            thrust_ax, thrust_ay, thrust_az
    cable_multipliers(cables, formation[FORMATION_PAYLOAD_MASS], taut, multipliers)
    # q_ddot = M^-1 (f - G^T Lambda): UAV i gets +2 lambda_i d_i / m_i, the payload
    # -2 sum_i lambda_i d_i / m_p.
    for i in range(n):
        dx, dy, dz = cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], \
            cables[i, CABLE_OFFSET + 2]
        multiplier = multipliers[i]
        pull = 2.0 * multiplier / uavs[i, UAV_MASS]
        r = uav_slot(i) + POSITION
        acc[r] = cables[i, CABLE_THRUST] + pull * dx
        acc[r + 1] = cables[i, CABLE_THRUST + 1] + pull * dy
        acc[r + 2] = cables[i, CABLE_THRUST + 2] + pull * dz - gravity
        if cables[i, CABLE_MOMENT] != 0.0 or cables[i, CABLE_MOMENT + 1] != 0.0 or \
                cables[i, CABLE_MOMENT + 2] != 0.0:  # the pull's moment on the UAV's attitude
            add_cable_torque(uavs, i, acc, uav_attitude_slot(n, i) - nq + BODY_RATES,
                             2.0 * multiplier, cables[i, CABLE_MOMENT],
                             cables[i, CABLE_MOMENT + 1], cables[i, CABLE_MOMENT + 2])
    payload_pulled(cables, multipliers, formation, drag_ax, drag_ay, drag_az, acc, p)


@jit
def rk4_step(x, wrenches, uavs, gusts, formation, taut, h, out, multipliers, work, cables):
    """One classic RK4 step of h [s] from x with the wrenches held, into out (which may be
    x); the multipliers [N/m] of its first stage (at x) into multipliers (n,). The bodies'
    attitude blocks after q_dot (each UAV's, a rigid payload's) step with the rest (their
    rates from `solve` at acc[3n + 3:]), every quaternion scaled back to unit length at the
    end (`attitude.normalize_quaternion`)."""
    n = uavs.shape[0]
    nq = rates_slot(n)
    bodies = uav_attitude_slot(n, 0)  # the first attitude block: 2 (3n + 3)
    size = x.shape[0]
    extra = size - bodies  # the attitude blocks
    half, sixth = 0.5 * h, h / 6.0
    k1, k2, k3, k4 = work[WORK_K1], work[WORK_K2], work[WORK_K3], work[WORK_K4]
    stage, acc = work[WORK_STAGE], work[WORK_ACC]
    later = work[WORK_MULTIPLIERS, :n]
    # driven UAVs (physics.prescribed) and reeled cables (physics.winch) are functions of
    # time: each stage's time in the period's copy of the scalars, FORMATION_TIME (t0 + h at
    # the end: the next step's start)
    timed = formation[FORMATION_PRESCRIBED] != 0.0 or formation[FORMATION_WINCH] != 0.0
    start = formation[FORMATION_TIME]
    solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers, cables)
    for j in range(nq):  # k = (q_dot, q_ddot, the blocks' rates): the state derivative
        k1[j] = x[nq + j]
        k1[nq + j] = acc[j]
    for j in range(extra):
        k1[bodies + j] = acc[nq + j]
    for k in (WORK_K2, WORK_K3, WORK_K4):  # stage k from x + (h/2 k1, h/2 k2, h k3)
        step, previous = (h if k == WORK_K4 else half), work[k - 1]
        if timed:
            formation[FORMATION_TIME] = start + step
        for j in range(size):
            stage[j] = x[j] + step * previous[j]
        solve(stage, wrenches, uavs, gusts, formation, taut, acc, later, cables)
        derivative = work[k]
        for j in range(nq):
            derivative[j] = stage[nq + j]
            derivative[nq + j] = acc[j]
        for j in range(extra):
            derivative[bodies + j] = acc[nq + j]
    if timed:
        formation[FORMATION_TIME] = start + h
    for j in range(size):
        out[j] = x[j] + sixth * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j])
    # the quaternions: every attitude block's (not a chain's node blocks after them)
    for j in range(bodies, size - NODE_STATE * n * chain_inner_nodes(size, n), BODY_ATTITUDE):
        normalize_quaternion(out, j)


@jit
def residuals(x, uavs, g, g_dot):
    """g_i = |r_p - r_i|^2 - l_i^2 [m^2] (Eq. 2.42) into g (n,) and g_dot_i =
    2 (r_p - r_i) . (v_p - v_i) [m^2/s] (Eq. 2.56) into g_dot (n,), at state x (with a rigid
    payload's attitude: its attach points', `rigid_payload.rigid_residuals`)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    inner = chain_inner_nodes(x.shape[0], n)
    if inner > 0:  # a chain's worst link per cable (chain_cables), a point or rigid payload
        chain_residuals(x, uavs, inner, uavs[:, UAV_LENGTH_SQ].copy(), np.zeros(n), g, g_dot)
        return
    if rigid_payload_state(x.shape[0], n):
        rigid_residuals(x, uavs, g, g_dot)
        return
    for i in range(n):
        b = uav_slot(i) + POSITION
        dx = x[p] - x[b]
        dy = x[p + 1] - x[b + 1]
        dz = x[p + 2] - x[b + 2]
        dvx = x[nq + p] - x[nq + b]
        dvy = x[nq + p + 1] - x[nq + b + 1]
        dvz = x[nq + p + 2] - x[nq + b + 2]
        if attached_off_centre(uavs, i):  # from the attach point r_i + R_i a_i
            attach = np.empty((3, 3))
            uav_attach_motion(x, i, np.zeros((n, 4)), uavs, attach)
            dx, dy, dz = dx - attach[0, 0], dy - attach[0, 1], dz - attach[0, 2]
            dvx, dvy, dvz = dvx - attach[1, 0], dvy - attach[1, 1], dvz - attach[1, 2]
        g[i] = dx * dx + dy * dy + dz * dz - uavs[i, UAV_LENGTH_SQ]
        g_dot[i] = 2.0 * (dx * dvx + dy * dvy + dz * dvz)


@jit
def integrate_period(x, wrenches, uavs, gusts, formation, taut, dt, steps):
    """`steps` RK4 steps of dt [s] from x with the wrenches held (one control period of seed
    Algorithm 1), the `taut` cables constrained, each step projected back onto g = 0,
    g_dot = 0 where the formation asks for it (FORMATION_PROJECTION_STEPS: the null-space
    form's coordinate projection, `physics.nullspace.project`): (the state at the end, the
    multipliers [N/m] at x, g [m^2] and g_dot [m^2/s] at the end). x is not written."""
    n = uavs.shape[0]
    size = x.shape[0]
    work = np.empty((WORK_ROWS, size))
    cables = np.empty((n, CABLE_COLUMNS))
    first = np.empty(n)
    later = np.empty(n)
    state = x.copy()
    projection_steps = int(formation[FORMATION_PROJECTION_STEPS])
    # M_t for the projection (none without it: no allocation in the common case)
    masses = translational_masses(uavs, formation) if projection_steps > 0 else first
    for step in range(steps):
        rk4_step(state, wrenches, uavs, gusts, formation, taut, dt, state,
                 first if step == 0 else later, work, cables)
        if projection_steps > 0:
            project(state, uavs, masses, formation[FORMATION_PROJECTION_TOLERANCE],
                    projection_steps)
    g = np.empty(n)
    g_dot = np.empty(n)
    residuals(state, uavs, g, g_dot)
    return state, first, g, g_dot
