"""Heavy cables (`cable_model: chain`, issue 32 item 2): each cable a chain of N rigid links
between its UAV (node 0) and the payload (node N: a point payload's centre, or a rigid one's
attach point, physics.chain_payload), with N - 1 point masses between them (node k of cable
i, its state at `chain_node_slot(len(x), n, N - 1, i, k)`). World frame (z up), SI units;
slots: `physics.layout` (NODE_*, CHAIN_*, UAV_NODE_MASS, UAV_NODE_DRAG,
FORMATION_CHAIN_LINKS). docs/cables.md, "Heavy cables".

Node 0 is UAV i's attach point r_i + R_i a_i where its cable holds it off its centre (issue
20): the top link's pull then turns the UAV too (its moment a_i x R_i^T 2 lambda_i1 d_i1,
Eq. 2.28), and adds 2 k . J^-1 k to the top link's diagonal (k = a_i x R_i^T d_i1).

The seed's cable constraint (Eq. 2.42) per link: g_ik = |d_ik|^2 - s_i^2 = 0, d_ik = r_ik -
r_i(k-1), s_i = l_i / N, held by Lagrange multipliers with Baumgarte's stabilisation as the
formation's (Eq. 2.59-2.60: g_ddot = -2 alpha_f g_dot - beta_f^2 g). A link's multiplier
lambda_ik pulls node k by -2 lambda_ik d_ik and node k - 1 by +2 lambda_ik d_ik (Eq. 2.70's
signs: its tension is 2 s_i lambda_ik). With the payload's acceleration a_p given, each cable's
multipliers solve a tridiagonal system (row k: link k, which couples only with links k - 1
and k + 1 through their shared node)

    A_i lambda_i = u_rhs_i + e_N (d_iN . a_p),   A_i = tridiag(-2 d_k.d_k-1 / m_k-1,
                                                 2 |d_k|^2 (1/m_k-1 + 1/m_k), ...)

(1/m_N = 0: the payload's acceleration is the unknown), so lambda_i = u_i + (d_iN . a_p) w_i
(u_i = A_i^-1 u_rhs_i, w_i = A_i^-1 e_N: one Thomas sweep with two right-hand sides), and the
payload's m_p a_p = m_p a_p_free - 2 sum_i lambda_iN d_iN is the 3 x 3 system
(m_p I + 2 sum_i w_iN d_iN d_iN^T) a_p = m_p a_p_free - 2 sum_i u_iN d_iN (the Schur
complement on the payload's acceleration): O(n N) a solve. Gravity is common to every body
and cancels in the links' equations; it is added at the end.

Elastic links (the cable's UAV_CABLE_STIFFNESS k > 0, cables.chain): each link a rope
segment N k l_i(0) / l_i(t) stiff and N c l_i(0) / l_i(t) damped (`elastic_cables.rope_tension`:
it pulls only when longer than s_i, never pushes), so each multiplier is known,
lambda_ik = T_ik / (2 |d_ik|), with w_i = 0: no solve; the payload's 3 x 3 (or 6 x 6) system
then carries the pulls alone.

Rigid links are rods: a link's multiplier may go negative (it pushes: a chain folding fast, or
whipped), which a real rope cannot; the chain keeps it (rods, not a rope) and the run's
`compressed_time` figure reports it for the top link (the tension the tick reports).
"""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.free_motion import (add_cable_torque, air_velocity,
                                              attached_off_centre, cable_moment_arm,
                                              payload_motion, rotational_compliance,
                                              uav_attach_motion, uav_free_motion)
from multilift_sim.physics.layout import (BODY_RATES, CHAIN_LINK_COLUMNS, CHAIN_LINK_DIAGONAL,
                                          CHAIN_LINK_OFFSET, CHAIN_LINK_U, CHAIN_LINK_UPPER,
                                          CHAIN_LINK_W, CHAIN_NODE_COLUMNS, CHAIN_NODE_FREE,
                                          CHAIN_NODE_INV_MASS, FORMATION_BETA_SQ,
                                          FORMATION_CHAIN_LINKS,
                                          FORMATION_GRAVITY, FORMATION_PAYLOAD_MASS,
                                          FORMATION_TWO_ALPHA, FORMATION_WIND, NODE_POSITION,
                                          NODE_VELOCITY, POSITION, REEL_LENGTH, REEL_RATE,
                                          UAV_CABLE_DAMPING, UAV_CABLE_STIFFNESS,
                                          UAV_LENGTH_SQ, UAV_MASS, UAV_NODE_DRAG,
                                          UAV_NODE_MASS)
from multilift_sim.physics.attitude import quaternion_rotation
from multilift_sim.physics.elastic_cables import rope_tension
from multilift_sim.physics.chain_payload import (payload_ends, payload_moment,
                                                 rigid_payload_acceleration)
from multilift_sim.physics.symmetric_solve import symmetric_solve3
from multilift_sim.physics.winch import reeled_cable
from multilift_sim.physics.state_slots import (attitude_slot, chain_node_slot, payload_slot,
                                               rates_slot, rigid_payload_state,
                                               uav_attitude_slot, uav_slot)


@jit
def put3(row, at, a, b, c):
    """row[at:at + 3] = (a, b, c)."""
    row[at], row[at + 1], row[at + 2] = a, b, c


@jit
def get3(row, at):
    """row[at:at + 3] as three floats."""
    return row[at], row[at + 1], row[at + 2]


@jit
def off_centre_any(moments, i):
    """Whether cable i's top link pulls UAV i off its centre (a moment arm not 0)."""
    return moments[i, 0] != 0.0 or moments[i, 1] != 0.0 or moments[i, 2] != 0.0


@jit
def node_point(x, n, inner, i, k, p, nq):
    """The offset in x of node k's position of cable i (0: UAV i's r_i, N: the payload's r_p,
    else an inner node's) and of its velocity."""
    if k == 0:
        r = uav_slot(i) + POSITION
        return r, nq + r
    if k == inner + 1:
        return p, nq + p
    base = chain_node_slot(x.shape[0], n, inner, i, k)
    return base + NODE_POSITION, base + NODE_VELOCITY


@jit
def chain_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers):
    """The state's rates into acc at state x (q_ddot, the attitude blocks' rates, then each
    inner node's velocity and acceleration at its block's place less 3n + 3), the cables
    chains of FORMATION_CHAIN_LINKS rigid links; each cable's top link tension T_i = 2 s_i
    lambda_i1 [N] into multipliers (n,) as T_i / (2 l_i) [N/m] (what the tick reads as a rigid
    cable's). `taut` is not read: a chain is always held."""
    n = uavs.shape[0]
    links = int(formation[FORMATION_CHAIN_LINKS])
    inner = links - 1
    p = payload_slot(n)
    nq = rates_slot(n)
    px, py, pz, pvx, pvy, pvz, drag_ax, drag_ay, drag_az = payload_motion(x, n, gusts,
                                                                          formation)
    two_alpha, beta_sq = formation[FORMATION_TWO_ALPHA], formation[FORMATION_BETA_SQ]
    gravity = formation[FORMATION_GRAVITY]
    wind_x, wind_y, wind_z = (formation[FORMATION_WIND], formation[FORMATION_WIND + 1],
                              formation[FORMATION_WIND + 2])
    link_rows = np.empty((n, links, CHAIN_LINK_COLUMNS))
    node_rows = np.empty((n, links, CHAIN_NODE_COLUMNS))
    # where a cable holds its UAV off its centre (issue 20): the attach point's offset R_i a_i,
    # its rate and its acceleration without the cable (rows 0-2; all 0 at the centre), the
    # pull's moment arm k_i = a_i x R_i^T d_i1 [m^2], body FLU, and the UAV's thrust [m/s^2]
    attach = np.zeros((n, 3, 3))
    moments = np.zeros((n, 3))
    # a rigid payload (physics.chain_payload): each cable's end on it (e_i, its rate, its
    # centripetal acceleration), the last links' (d_iN, u_iN, w_iN) and their moment arms c_i
    rigid = rigid_payload_state(x.shape[0], n)
    ends = np.zeros((n, 3, 3))
    last_links = np.empty((n, 5))
    payload_moments = np.zeros((n, 3))
    payload_rotation = np.eye(3)
    if rigid:
        payload_rotation = quaternion_rotation(x, attitude_slot(n))
        payload_ends(x, uavs, payload_rotation, ends)
    thrusts = np.empty((n, 3))
    top = np.zeros(n)   # an elastic top link's T_i / l_i [N/m]
    rotation = np.empty((3, 3))
    payload_mass = formation[FORMATION_PAYLOAD_MASS]
    # the Schur complement S a_p = rhs on the payload's acceleration (gravity excluded)
    s00 = s11 = s22 = payload_mass
    s01 = s02 = s12 = 0.0
    b0, b1, b2 = payload_mass * drag_ax, payload_mass * drag_ay, payload_mass * drag_az
    for i in range(n):
        lk = link_rows[i]
        nd = node_rows[i]
        thrust_ax, thrust_ay, thrust_az = uav_free_motion(x, i, wrenches, uavs, formation, acc)
        put3(thrusts[i], 0, thrust_ax, thrust_ay, thrust_az)
        off_centre = attached_off_centre(uavs, i)
        if off_centre:  # node 0 is the attach point r_i + R_i a_i
            rotation[:, :] = uav_attach_motion(x, i, wrenches, uavs, attach[i])
        put3(nd[0], CHAIN_NODE_FREE, thrust_ax + attach[i, 2, 0], thrust_ay + attach[i, 2, 1],
             thrust_az + attach[i, 2, 2])
        nd[0, CHAIN_NODE_INV_MASS] = 1.0 / uavs[i, UAV_MASS]
        node_mass, node_drag_c = uavs[i, UAV_NODE_MASS], uavs[i, UAV_NODE_DRAG]
        for k in range(1, links):  # the inner nodes: their drag in the air
            r, v = node_point(x, n, inner, i, k, p, nq)
            nd[k, CHAIN_NODE_INV_MASS] = 1.0 / node_mass
            fx = fy = fz = 0.0
            if node_drag_c > 0.0:  # -c |v_rel| v_rel / m, v_rel against the wind and gusts
                air_x, air_y, air_z = air_velocity(x[r], x[r + 1], gusts)
                rel_x = x[v] - air_x - wind_x
                rel_y = x[v + 1] - air_y - wind_y
                rel_z = x[v + 2] - air_z - wind_z
                scale = -node_drag_c / node_mass * math.sqrt(rel_x * rel_x + rel_y * rel_y
                                                             + rel_z * rel_z)
                fx, fy, fz = scale * rel_x, scale * rel_y, scale * rel_z
            put3(nd[k], CHAIN_NODE_FREE, fx, fy, fz)
        # s_i^2 and a reeled length's terms of g_dot and g_ddot (s_i s_i_dot, s_i_dot^2 +
        # s_i s_i_ddot; 0 without a winch): each link is l_i(t) / N (physics.winch)
        length_sq, reel_rate, reel_acc = reeled_cable(uavs, formation, i)
        per_link = links * links
        link_sq, link_rate, link_acc = (length_sq / per_link, reel_rate / per_link,
                                        reel_acc / per_link)
        # elastic links (the cable's k, c at its length l_0 = l_i(0)): each N k l_0 / l_i(t)
        # stiff and N c l_0 / l_i(t) damped about its rest length s_i, stretching at
        # d_hat . dv - s_i_dot (0: rigid links, held by their multipliers)
        stretchy = uavs[i, UAV_CABLE_STIFFNESS] > 0.0
        rest = link_stiffness = link_damping = rest_rate = top_tension = 0.0
        if stretchy:
            rest = math.sqrt(link_sq)
            scale = math.sqrt(uavs[i, UAV_LENGTH_SQ] / length_sq) * links
            link_stiffness = uavs[i, UAV_CABLE_STIFFNESS] * scale
            link_damping = uavs[i, UAV_CABLE_DAMPING] * scale
            rest_rate = link_rate / rest
        for k in range(1, links + 1):  # link k's row: d_k, A's entries, its right-hand side
            r0, v0 = node_point(x, n, inner, i, k - 1, p, nq)
            r1, v1 = node_point(x, n, inner, i, k, p, nq)
            dx, dy, dz = x[r1] - x[r0], x[r1 + 1] - x[r0 + 1], x[r1 + 2] - x[r0 + 2]
            dvx, dvy, dvz = x[v1] - x[v0], x[v1 + 1] - x[v0 + 1], x[v1 + 2] - x[v0 + 2]
            if k == 1 and off_centre:  # from the attach point
                dx, dy, dz = dx - attach[i, 0, 0], dy - attach[i, 0, 1], dz - attach[i, 0, 2]
                dvx, dvy, dvz = (dvx - attach[i, 1, 0], dvy - attach[i, 1, 1],
                                 dvz - attach[i, 1, 2])
            if k == links and rigid:  # to the payload's attach point
                dx, dy, dz = dx + ends[i, 0, 0], dy + ends[i, 0, 1], dz + ends[i, 0, 2]
                dvx, dvy, dvz = dvx + ends[i, 1, 0], dvy + ends[i, 1, 1], dvz + ends[i, 1, 2]
            row = lk[k - 1]
            put3(row, CHAIN_LINK_OFFSET, dx, dy, dz)
            offset_sq = dx * dx + dy * dy + dz * dz
            if stretchy:  # its pull 2 lambda d = T d_hat, lambda = T / (2 |d|), known
                tension, span = rope_tension(link_stiffness, link_damping, rest, dx, dy, dz,
                                             dvx, dvy, dvz, rest_rate)
                row[CHAIN_LINK_U] = 0.5 * tension / span if tension > 0.0 else 0.0
                row[CHAIN_LINK_W] = 0.0
                if k == 1:
                    top_tension = tension
                if k == 1 and off_centre:  # the pull's moment arm on the UAV
                    k0, k1, k2 = cable_moment_arm(uavs, i, rotation, dx, dy, dz)
                    put3(moments[i], 0, k0, k1, k2)
                continue
            upper_inv = nd[k - 1, CHAIN_NODE_INV_MASS]
            lower_inv = nd[k, CHAIN_NODE_INV_MASS] if k < links else 0.0
            row[CHAIN_LINK_DIAGONAL] = 2.0 * offset_sq * (upper_inv + lower_inv)
            if k == 1 and off_centre:  # the UAV's turn adds 2 k . J^-1 k (Eq. 2.28)
                k0, k1, k2 = cable_moment_arm(uavs, i, rotation, dx, dy, dz)
                put3(moments[i], 0, k0, k1, k2)
                row[CHAIN_LINK_DIAGONAL] += 2.0 * rotational_compliance(uavs, i, k0, k1, k2)
            # d_k . (a_k - a_(k-1)) = -|dv_k|^2 + s_dot^2 + s s_ddot - alpha_f g_dot_k
            # - beta_f^2 g_k / 2 (Eq. 2.59; g_dot_k / 2 = d_k . dv_k - s s_dot)
            target = (-(dvx * dvx + dvy * dvy + dvz * dvz - link_acc)
                      - two_alpha * (dx * dvx + dy * dvy + dz * dvz - link_rate)
                      - 0.5 * beta_sq * (offset_sq - link_sq))
            free_x, free_y, free_z = (-nd[k - 1, CHAIN_NODE_FREE], -nd[k - 1, CHAIN_NODE_FREE + 1],
                                      -nd[k - 1, CHAIN_NODE_FREE + 2])
            if k < links:
                free_x += nd[k, CHAIN_NODE_FREE]
                free_y += nd[k, CHAIN_NODE_FREE + 1]
                free_z += nd[k, CHAIN_NODE_FREE + 2]
            elif rigid:  # the payload's end's centripetal part, w x (w x e_i)
                free_x += ends[i, 2, 0]
                free_y += ends[i, 2, 1]
                free_z += ends[i, 2, 2]
            row[CHAIN_LINK_U] = dx * free_x + dy * free_y + dz * free_z - target
            row[CHAIN_LINK_W] = 1.0 if k == links else 0.0
            if k > 1:  # A[k - 1, k] = -2 d_(k-1) . d_k / m_(k-1), their shared node's
                above = lk[k - 2]
                above[CHAIN_LINK_UPPER] = -2.0 * upper_inv * (
                    above[CHAIN_LINK_OFFSET] * dx + above[CHAIN_LINK_OFFSET + 1] * dy
                    + above[CHAIN_LINK_OFFSET + 2] * dz)
        lk[links - 1, CHAIN_LINK_UPPER] = 0.0
        last = links - 1
        if stretchy:  # every link's multiplier known: no solve
            top[i] = top_tension / math.sqrt(length_sq)
        else:  # Thomas' algorithm on A (symmetric positive definite), two right-hand sides
            for k in range(1, links):
                factor = lk[k - 1, CHAIN_LINK_UPPER] / lk[k - 1, CHAIN_LINK_DIAGONAL]
                lk[k, CHAIN_LINK_DIAGONAL] -= factor * lk[k - 1, CHAIN_LINK_UPPER]
                lk[k, CHAIN_LINK_U] -= factor * lk[k - 1, CHAIN_LINK_U]
                lk[k, CHAIN_LINK_W] -= factor * lk[k - 1, CHAIN_LINK_W]
            lk[last, CHAIN_LINK_U] /= lk[last, CHAIN_LINK_DIAGONAL]
            lk[last, CHAIN_LINK_W] /= lk[last, CHAIN_LINK_DIAGONAL]
            for k in range(links - 2, -1, -1):
                row, below = lk[k], lk[k + 1]
                row[CHAIN_LINK_U] = (row[CHAIN_LINK_U]
                                     - row[CHAIN_LINK_UPPER] * below[CHAIN_LINK_U]) \
                    / row[CHAIN_LINK_DIAGONAL]
                row[CHAIN_LINK_W] = (row[CHAIN_LINK_W]
                                     - row[CHAIN_LINK_UPPER] * below[CHAIN_LINK_W]) \
                    / row[CHAIN_LINK_DIAGONAL]
        dx, dy, dz = get3(lk[last], CHAIN_LINK_OFFSET)
        if rigid:  # the 6 x 6 system's terms (physics.chain_payload)
            put3(last_links[i], 0, dx, dy, dz)
            last_links[i, 3], last_links[i, 4] = lk[last, CHAIN_LINK_U], lk[last, CHAIN_LINK_W]
            c0, c1, c2 = payload_moment(uavs, i, payload_rotation, dx, dy, dz)
            put3(payload_moments[i], 0, c0, c1, c2)
            continue
        w2, u2 = 2.0 * lk[last, CHAIN_LINK_W], 2.0 * lk[last, CHAIN_LINK_U]
        s00 += w2 * dx * dx
        s01 += w2 * dx * dy
        s02 += w2 * dx * dz
        s11 += w2 * dy * dy
        s12 += w2 * dy * dz
        s22 += w2 * dz * dz
        b0 -= u2 * dx
        b1 -= u2 * dy
        b2 -= u2 * dz
    turn = np.zeros(6)   # a rigid payload's (a_p, alpha_p)
    if rigid:
        rigid_payload_acceleration(x, formation, np.array([drag_ax, drag_ay, drag_az]),
                                   last_links, payload_moments, acc, turn)
        ap_x, ap_y, ap_z = turn[0], turn[1], turn[2]
    else:  # a_p = S^-1 b (gravity excluded)
        ap_x, ap_y, ap_z = symmetric_solve3(s00, s01, s02, s11, s12, s22, b0, b1, b2)
    acc[p], acc[p + 1], acc[p + 2] = ap_x, ap_y, ap_z - gravity
    for i in range(n):
        lk = link_rows[i]
        nd = node_rows[i]
        last = links - 1
        along = (lk[last, CHAIN_LINK_OFFSET] * ap_x + lk[last, CHAIN_LINK_OFFSET + 1] * ap_y
                 + lk[last, CHAIN_LINK_OFFSET + 2] * ap_z + payload_moments[i, 0] * turn[3]
                 + payload_moments[i, 1] * turn[4] + payload_moments[i, 2] * turn[5])
        for k in range(links):  # lambda_k = u_k + (d_N . a_p) w_k, into CHAIN_LINK_U
            lk[k, CHAIN_LINK_U] += along * lk[k, CHAIN_LINK_W]
        # T_i / (2 l_i) = 2 s_i lambda_1 / (2 l_i); an elastic top link's T_i / (2 l_i)
        multipliers[i] = (0.5 * top[i] if uavs[i, UAV_CABLE_STIFFNESS] > 0.0
                          else lk[0, CHAIN_LINK_U] / links)
        for j in range(links):  # node j: its free acceleration + 2 / m_j (lambda_(j+1) d_(j+1)
            # - lambda_j d_j) - g e_z (node 0 the UAV, whose block is q's)
            pull = 2.0 * nd[j, CHAIN_NODE_INV_MASS]
            below_x, below_y, below_z = get3(lk[j], CHAIN_LINK_OFFSET)
            ax, ay, az = get3(nd[j], CHAIN_NODE_FREE)
            lam = pull * lk[j, CHAIN_LINK_U]
            ax, ay, az = ax + lam * below_x, ay + lam * below_y, az + lam * below_z
            if j > 0:
                above_x, above_y, above_z = get3(lk[j - 1], CHAIN_LINK_OFFSET)
                lam = pull * lk[j - 1, CHAIN_LINK_U]
                ax, ay, az = ax - lam * above_x, ay - lam * above_y, az - lam * above_z
            r, v = node_point(x, n, inner, i, j, p, nq)
            if j == 0:  # the UAV's centre: its thrust and the top link's pull (and its moment)
                lam = pull * lk[0, CHAIN_LINK_U]
                acc[r] = thrusts[i, 0] + lam * below_x
                acc[r + 1] = thrusts[i, 1] + lam * below_y
                acc[r + 2] = thrusts[i, 2] + lam * below_z - gravity
                if off_centre_any(moments, i):
                    add_cable_torque(uavs, i, acc, uav_attitude_slot(n, i) - nq + BODY_RATES,
                                     2.0 * lk[0, CHAIN_LINK_U], moments[i, 0], moments[i, 1],
                                     moments[i, 2])
                continue
            at = r - nq   # the node's block in acc: its position's rate, then its velocity's
            acc[at], acc[at + 1], acc[at + 2] = x[v], x[v + 1], x[v + 2]
            acc[at + 3], acc[at + 4], acc[at + 5] = ax, ay, az - gravity


@jit
def chain_residuals(x, uavs, inner, length_sq, length_rate, g, g_dot):
    """Each cable's worst link (the largest |g_ik|) at state x: its g_ik = |d_ik|^2 - s_i^2
    [m^2] into g (n,) and the largest |g_dot_ik| = |2 d_ik . (v_ik - v_i(k-1)) - 2 s_i s_i_dot|
    [m^2/s], signed, into g_dot (n,) (`inner` = N - 1 inner nodes per cable; s_i = l_i / N from
    each cable's l_i^2 `length_sq` (n,) [m^2] and l_i l_i_dot `length_rate` (n,) [m^2/s]: a
    reel's, or the constant lengths' and 0)."""
    n = uavs.shape[0]
    links = inner + 1
    p = payload_slot(n)
    nq = rates_slot(n)
    attach = np.zeros((3, 3))
    rigid = rigid_payload_state(x.shape[0], n)
    ends = np.zeros((n, 3, 3))
    if rigid:  # the last links end at the payload's attach points
        payload_ends(x, uavs, quaternion_rotation(x, attitude_slot(n)), ends)
    for i in range(n):
        per_link = links * links
        link_sq, link_rate = length_sq[i] / per_link, length_rate[i] / per_link
        worst = worst_rate = 0.0
        off_centre = attached_off_centre(uavs, i)
        if off_centre:  # node 0 the attach point r_i + R_i a_i
            uav_attach_motion(x, i, np.zeros((n, 4)), uavs, attach)
        for k in range(1, links + 1):
            r0, v0 = node_point(x, n, inner, i, k - 1, p, nq)
            r1, v1 = node_point(x, n, inner, i, k, p, nq)
            dx, dy, dz = x[r1] - x[r0], x[r1 + 1] - x[r0 + 1], x[r1 + 2] - x[r0 + 2]
            dvx, dvy, dvz = x[v1] - x[v0], x[v1 + 1] - x[v0 + 1], x[v1 + 2] - x[v0 + 2]
            if k == 1 and off_centre:
                dx, dy, dz = dx - attach[0, 0], dy - attach[0, 1], dz - attach[0, 2]
                dvx, dvy, dvz = dvx - attach[1, 0], dvy - attach[1, 1], dvz - attach[1, 2]
            if k == links and rigid:
                dx, dy, dz = dx + ends[i, 0, 0], dy + ends[i, 0, 1], dz + ends[i, 0, 2]
                dvx, dvy, dvz = dvx + ends[i, 1, 0], dvy + ends[i, 1, 1], dvz + ends[i, 1, 2]
            value = dx * dx + dy * dy + dz * dz - link_sq
            rate = 2.0 * (dx * dvx + dy * dvy + dz * dvz - link_rate)
            if abs(value) >= abs(worst):
                worst = value
            if abs(rate) >= abs(worst_rate):
                worst_rate = rate
        g[i], g_dot[i] = worst, worst_rate


@jit
def reeled_chain_residuals(x, uavs, inner, reel, g, g_dot):
    """`chain_residuals` at state x against reeled cables: each link l_i / N with l_i and
    l_i_dot the reels' (`reel` (n, REEL_COLUMNS), physics.winch)."""
    lengths, rates = reel[:, REEL_LENGTH], reel[:, REEL_RATE]
    chain_residuals(x, uavs, inner, lengths * lengths, lengths * rates, g, g_dot)


@jit
def cable_paths(x, uavs, inner):
    """Each cable's N + 1 points [m], world, at state x (n, N + 1, 3): where it holds its UAV
    (r_i + R_i a_i), its `inner` nodes, where it holds the payload (r_p, or a rigid one's
    r_p + R_p b_i)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    paths = np.empty((n, inner + 2, 3))
    ends = np.zeros((n, 3, 3))
    if rigid_payload_state(x.shape[0], n):
        payload_ends(x, uavs, quaternion_rotation(x, attitude_slot(n)), ends)
    attach = np.zeros((3, 3))
    for i in range(n):
        for k in range(inner + 2):
            r, _ = node_point(x, n, inner, i, k, p, nq)
            put3(paths[i, k], 0, x[r], x[r + 1], x[r + 2])
        if attached_off_centre(uavs, i):
            uav_attach_motion(x, i, np.zeros((n, 4)), uavs, attach)
            paths[i, 0] += attach[0]
        paths[i, inner + 1] += ends[i, 0]
    return paths
