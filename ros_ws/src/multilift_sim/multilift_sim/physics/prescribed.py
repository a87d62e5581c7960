"""Prescribed UAV motion (`uavs[i].trajectory`, issue 34 item 3): a UAV whose position,
velocity, acceleration and attitude are given functions of time (its drive), a kinematic
driver of the formation DAE: no equation of motion and no controller for it, while its cable
and the payload are simulated. World frame (z up), SI units; the drive table's slots are
`physics.layout`'s (DRIVE_*, after the formation's scalars).

What the DAE does with a driven UAV i (`prescribed_solve`, the multiplier form of seed Eq.
2.59-2.60 with UAV i's row replaced): its acceleration is the drive's a_i(t), whatever its
cable pulls (an infinite mass: its 1/m_i is 0 in G M^-1 G^T, delta_i = 0, so the Woodbury
form of `formation_dae.cable_multipliers`, which divides by delta_i, gives way to a dense
n x n solve); its cable's multiplier still acts on the payload. Its attitude turns at the
body rates of the tick's state over the period (omega_dot = 0). The time t of a stage is
FORMATION_TIME of the period's copy of the scalars (`physics.tick.advance` writes the tick's
time, `formation_dae.rk4_step` each stage's), and at every tick `prescribe_state` resets the
driven UAVs' state to the drive's (position, velocity, attitude, body rates), so nothing
drifts: the payload integrates against the driver, the driver is the file.
"""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import quaternion_rate
from multilift_sim.physics.free_motion import payload_motion, payload_pulled, uav_free_motion
from multilift_sim.physics.layout import (
    BODY_QUATERNION, BODY_RATES, CABLE_OFFSET, CABLE_THRUST, DRIVE_AXES, DRIVE_EULER,
    DRIVE_KNOTS, DRIVE_ORDER, DRIVE_PIECES, DRIVE_POSITION, FORMATION_BETA_SQ,
    FORMATION_GRAVITY, FORMATION_INV_PAYLOAD_MASS, FORMATION_PRESCRIBED, FORMATION_SCALARS,
    FORMATION_TIME, FORMATION_TWO_ALPHA, POSITION, UAV_LENGTH_SQ, UAV_MASS)
from multilift_sim.physics.measurement import euler_quaternion
from multilift_sim.physics.nullspace import dense_solve
from multilift_sim.physics.state_slots import (payload_slot, rates_slot, uav_attitude_slot,
                                               uav_slot)


@jit
def drive_of(formation, i):
    """Where UAV i's drive starts in `formation` (the scalars and the drive table), 0 when its
    motion is not prescribed."""
    if formation[FORMATION_PRESCRIBED] == 0.0:
        return 0
    return int(formation[FORMATION_SCALARS + i])


@jit
def drive_axis(formation, drive, axis, t):
    """The drive's axis `axis` (DRIVE_*: x, y, z [m], roll, pitch, yaw [rad]) at t [s]: its
    value, first and second derivative (per s, per s^2). The piece holding t (the first or the
    last one outside the knots: validation makes the file cover the run)."""
    pieces = int(formation[drive + DRIVE_PIECES])
    knots = drive + DRIVE_KNOTS
    low, high = 0, pieces - 1  # the last piece k with t_k <= t (bisection)
    while low < high:
        middle = (low + high + 1) // 2
        if formation[knots + middle] <= t:
            low = middle
        else:
            high = middle - 1
    s = t - formation[knots + low]
    first = knots + pieces + 1 + (low * DRIVE_AXES + axis) * DRIVE_ORDER
    value = rate = acceleration = 0.0
    for j in range(DRIVE_ORDER - 1, -1, -1):  # Horner on the polynomial and its derivatives
        c = formation[first + j]
        acceleration = acceleration * s + 2.0 * rate
        rate = rate * s + value
        value = value * s + c
    return value, rate, acceleration


@jit
def body_rates(phi, theta, phi_rate, theta_rate, psi_rate):
    """omega [rad/s], body FLU, of ZYX Euler angles' rates [rad/s] at roll phi, pitch theta
    [rad] (seed Eq. 2.7 inverted: omega = W(eta) eta_dot)."""
    s_phi, c_phi = math.sin(phi), math.cos(phi)
    s_th, c_th = math.sin(theta), math.cos(theta)
    return (phi_rate - s_th * psi_rate,
            c_phi * theta_rate + s_phi * c_th * psi_rate,
            -s_phi * theta_rate + c_phi * c_th * psi_rate)


@jit
def prescribe_state(x, n, formation, t):
    """Every driven UAV's block of state x (n UAVs) set to its drive at t [s]: position [m],
    velocity [m/s], attitude quaternion and body rates [rad/s]; the others untouched."""
    nq = rates_slot(n)
    for i in range(n):
        drive = drive_of(formation, i)
        if drive == 0:
            continue
        r = uav_slot(i) + POSITION
        for axis in range(3):
            value, rate, _ = drive_axis(formation, drive, DRIVE_POSITION + axis, t)
            x[r + axis] = value
            x[nq + r + axis] = rate
        phi, phi_rate, _ = drive_axis(formation, drive, DRIVE_EULER, t)
        theta, theta_rate, _ = drive_axis(formation, drive, DRIVE_EULER + 1, t)
        psi, psi_rate, _ = drive_axis(formation, drive, DRIVE_EULER + 2, t)
        base = uav_attitude_slot(n, i)
        qx, qy, qz, qw = euler_quaternion(phi, theta, psi)
        x[base + BODY_QUATERNION] = qw
        x[base + BODY_QUATERNION + 1] = qx
        x[base + BODY_QUATERNION + 2] = qy
        x[base + BODY_QUATERNION + 3] = qz
        (x[base + BODY_RATES], x[base + BODY_RATES + 1],
         x[base + BODY_RATES + 2]) = body_rates(phi, theta, phi_rate, theta_rate, psi_rate)


@jit
def prescribed_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers, cables):
    """`formation_dae.solve` for a formation with driven UAVs (a point payload on rigid cables
    from the UAVs' centres): q_ddot into acc[:3n + 3] [m/s^2], the attitude blocks' rates
    after it, the multipliers Lambda [N/m] into multipliers (n,), at state x and the time
    FORMATION_TIME. A driven UAV's acceleration is its drive's; a free one's its thrust's and
    its cable's (seed Eq. 2.60, 2.70), the `taut` cables constrained:
    ``(Delta + 4 D D^T / m_p) Lambda = b`` with delta_i = 4 |d_i|^2 / m_i (0 for a driven UAV)
    and b_i = 2 d_i . (a_p,free - a_i,free) + 2 |d_i_dot|^2 + 2 alpha_f g_dot_i + beta_f^2 g_i,
    gravity cancelling in the difference."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    t = formation[FORMATION_TIME]
    gravity = formation[FORMATION_GRAVITY]
    two_alpha, beta_sq = formation[FORMATION_TWO_ALPHA], formation[FORMATION_BETA_SQ]
    px, py, pz, pvx, pvy, pvz, drag_ax, drag_ay, drag_az = payload_motion(x, n, gusts,
                                                                          formation)
    system = np.zeros((n, n))
    rhs = np.zeros(n)
    inverse_mass = np.zeros(n)  # 1 / m_i, 0 for a driven UAV
    for i in range(n):
        r = uav_slot(i) + POSITION
        drive = drive_of(formation, i)
        if drive == 0:
            free_x, free_y, free_z = uav_free_motion(x, i, wrenches, uavs, formation, acc)
            inverse_mass[i] = 1.0 / uavs[i, UAV_MASS]
        else:  # its acceleration is the drive's, gravity excluded as a free UAV's thrust is
            _, _, free_x = drive_axis(formation, drive, DRIVE_POSITION, t)
            _, _, free_y = drive_axis(formation, drive, DRIVE_POSITION + 1, t)
            _, _, free_z = drive_axis(formation, drive, DRIVE_POSITION + 2, t)
            free_z += gravity
            base = uav_attitude_slot(n, i)
            rate = base - nq  # its attitude turns at the state's body rates, held
            (acc[rate + BODY_QUATERNION], acc[rate + BODY_QUATERNION + 1],
             acc[rate + BODY_QUATERNION + 2], acc[rate + BODY_QUATERNION + 3]) = \
                quaternion_rate(x, base, x[base + BODY_RATES], x[base + BODY_RATES + 1],
                                x[base + BODY_RATES + 2])
            acc[rate + BODY_RATES] = acc[rate + BODY_RATES + 1] = 0.0
            acc[rate + BODY_RATES + 2] = 0.0
        dx, dy, dz = px - x[r], py - x[r + 1], pz - x[r + 2]
        dvx, dvy, dvz = pvx - x[nq + r], pvy - x[nq + r + 1], pvz - x[nq + r + 2]
        offset_sq = dx * dx + dy * dy + dz * dz
        cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], cables[i, CABLE_OFFSET + 2] = \
            dx, dy, dz
        cables[i, CABLE_THRUST], cables[i, CABLE_THRUST + 1], cables[i, CABLE_THRUST + 2] = \
            free_x, free_y, free_z
        if not taut[i]:
            system[i, i] = 1.0
            continue
        rhs[i] = (2.0 * (dx * (drag_ax - free_x) + dy * (drag_ay - free_y)
                         + dz * (drag_az - free_z))
                  + 2.0 * (dvx * dvx + dvy * dvy + dvz * dvz)
                  + two_alpha * 2.0 * (dx * dvx + dy * dvy + dz * dvz)
                  + beta_sq * (offset_sq - uavs[i, UAV_LENGTH_SQ]))
        system[i, i] = 4.0 * offset_sq * inverse_mass[i]
    coupling = 4.0 * formation[FORMATION_INV_PAYLOAD_MASS]
    for i in range(n):
        if not taut[i]:
            continue
        for j in range(n):
            if taut[j]:
                system[i, j] += coupling * (
                    cables[i, CABLE_OFFSET] * cables[j, CABLE_OFFSET]
                    + cables[i, CABLE_OFFSET + 1] * cables[j, CABLE_OFFSET + 1]
                    + cables[i, CABLE_OFFSET + 2] * cables[j, CABLE_OFFSET + 2])
    multipliers[:] = dense_solve(system, rhs)
    for i in range(n):  # a driven UAV's 1/m_i is 0: its drive's acceleration
        pull = 2.0 * multipliers[i] * inverse_mass[i]
        r = uav_slot(i) + POSITION
        for axis in range(3):
            acc[r + axis] = cables[i, CABLE_THRUST + axis] + pull * cables[i, CABLE_OFFSET + axis]
        acc[r + 2] -= gravity
    payload_pulled(cables, multipliers, formation, drag_ax, drag_ay, drag_az, acc, p)
