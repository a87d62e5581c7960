"""A rigid-body payload on heavy cables (`cable_model: chain` with `payload.type: rigid_body`;
physics.chain_cables): cable i's last link ends at the payload's attach point r_p + e_i,
e_i = R_p b_i (b_i `UAV_PAYLOAD_ATTACH`, payload frame), moving at v_p + w x e_i (w = R_p
omega_p) and accelerating at a_p + R_p (alpha_p x b_i) + w x (w x e_i) (as
physics.rigid_payload's massless cables). With c_i = b_i x R_p^T d_iN the last link's row
reads d_iN . a_p + c_i . alpha_p, so each cable's multipliers are lambda_i = u_i + (d_iN . a_p
+ c_i . alpha_p) w_i, and Newton's and Euler's equations of the payload, m_p a_p = m_p a_free
- 2 sum_i lambda_iN d_iN and J_p alpha_p = -omega_p x J_p omega_p - 2 sum_i lambda_iN c_i,
are the 6 x 6 system (the Schur complement on (a_p, alpha_p))

    [m_p I + 2 sum w d d^T,  2 sum w d c^T ] [a_p    ]   [m_p a_free - 2 sum u d        ]
    [2 sum w c d^T,       J_p + 2 sum w c c^T] [alpha_p] = [-omega_p x J_p omega_p - 2 sum u c]

(w, u the last links' entries of w_i, u_i; gravity excluded, added by the caller). World frame
(z up), SI units; slots: `physics.layout`.
"""
import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import quaternion_rate
from multilift_sim.physics.free_motion import cross
from multilift_sim.physics.layout import (FORMATION_PAYLOAD_INERTIA, FORMATION_PAYLOAD_MASS,
                                          PAYLOAD_BODY_RATES, PAYLOAD_QUATERNION,
                                          UAV_PAYLOAD_ATTACH)
from multilift_sim.physics.nullspace import dense_solve
from multilift_sim.physics.state_slots import attitude_slot, rates_slot


@jit
def payload_ends(x, uavs, rotation, ends):
    """Each cable's end on the payload at state x into ends (n, 3, 3): e_i = R_p b_i [m], its
    velocity w x e_i [m/s] and its centripetal acceleration w x (w x e_i) [m/s^2], world, all
    relative to the payload's centre (`rotation` R_p (3, 3))."""
    n = uavs.shape[0]
    base = attitude_slot(n)
    omega = (x[base + PAYLOAD_BODY_RATES], x[base + PAYLOAD_BODY_RATES + 1],
             x[base + PAYLOAD_BODY_RATES + 2])
    w = (rotation[0, 0] * omega[0] + rotation[0, 1] * omega[1] + rotation[0, 2] * omega[2],
         rotation[1, 0] * omega[0] + rotation[1, 1] * omega[1] + rotation[1, 2] * omega[2],
         rotation[2, 0] * omega[0] + rotation[2, 1] * omega[1] + rotation[2, 2] * omega[2])
    for i in range(n):
        for row in range(3):
            ends[i, 0, row] = (rotation[row, 0] * uavs[i, UAV_PAYLOAD_ATTACH]
                               + rotation[row, 1] * uavs[i, UAV_PAYLOAD_ATTACH + 1]
                               + rotation[row, 2] * uavs[i, UAV_PAYLOAD_ATTACH + 2])
        spin = cross(w, (ends[i, 0, 0], ends[i, 0, 1], ends[i, 0, 2]))
        turn = cross(w, spin)
        for row in range(3):
            ends[i, 1, row] = spin[row]
            ends[i, 2, row] = turn[row]


@jit
def payload_moment(uavs, i, rotation, d0, d1, d2):
    """c_i = b_i x R_p^T d [m^2], payload frame: the moment arm of a pull along d at cable i's
    attach point."""
    f = (rotation[0, 0] * d0 + rotation[1, 0] * d1 + rotation[2, 0] * d2,
         rotation[0, 1] * d0 + rotation[1, 1] * d1 + rotation[2, 1] * d2,
         rotation[0, 2] * d0 + rotation[1, 2] * d1 + rotation[2, 2] * d2)
    return cross((uavs[i, UAV_PAYLOAD_ATTACH], uavs[i, UAV_PAYLOAD_ATTACH + 1],
                  uavs[i, UAV_PAYLOAD_ATTACH + 2]), f)


@jit
def rigid_payload_acceleration(x, formation, drag, last, moments, acc, out):
    """(a_p [m/s^2], world, gravity excluded; alpha_p [rad/s^2], payload frame) into out (6,)
    from the 6 x 6 system above; `drag` (3,) the payload's drag over m_p [m/s^2], `last`
    (n, 5): each cable's last link d_iN (3), u_iN, w_iN; `moments` (n, 3) the c_i. Writes the
    payload's attitude block's rate into acc (q_dot = q (x) (0, omega) / 2, then alpha_p)."""
    n = last.shape[0]
    base = attitude_slot(n)
    mass = formation[FORMATION_PAYLOAD_MASS]
    inertia = formation[FORMATION_PAYLOAD_INERTIA:FORMATION_PAYLOAD_INERTIA + 3]
    omega = (x[base + PAYLOAD_BODY_RATES], x[base + PAYLOAD_BODY_RATES + 1],
             x[base + PAYLOAD_BODY_RATES + 2])
    gyro = cross(omega, (inertia[0] * omega[0], inertia[1] * omega[1], inertia[2] * omega[2]))
    system = np.zeros((6, 6))
    rhs = np.empty(6)
    for k in range(3):
        system[k, k] = mass
        system[3 + k, 3 + k] = inertia[k]
        rhs[k] = mass * drag[k]
        rhs[3 + k] = -gyro[k]
    along = np.empty(6)
    for i in range(n):
        for k in range(3):
            along[k] = last[i, k]
            along[3 + k] = moments[i, k]
        weight, value = 2.0 * last[i, 4], 2.0 * last[i, 3]
        for row in range(6):
            rhs[row] -= value * along[row]
            for col in range(6):
                system[row, col] += weight * along[row] * along[col]
    solution = dense_solve(system, rhs)
    for k in range(6):
        out[k] = solution[k]
    rate = base - rates_slot(n)  # the block's derivative in acc
    (acc[rate + PAYLOAD_QUATERNION], acc[rate + PAYLOAD_QUATERNION + 1],
     acc[rate + PAYLOAD_QUATERNION + 2], acc[rate + PAYLOAD_QUATERNION + 3]) = quaternion_rate(
        x, base, omega[0], omega[1], omega[2])
    for k in range(3):
        acc[rate + PAYLOAD_BODY_RATES + k] = out[3 + k]
