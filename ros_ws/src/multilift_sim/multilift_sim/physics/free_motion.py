"""Each body's motion without the cables, on one formation's arrays: the air at a point (the
seed's 1-cosine gusts, Eq. 2.55), the payload's drag in it (Eq. 2.53) and each UAV's attitude
and thrust (Eq. 2.6-2.8, 2.20, 2.28). Both formulations of the DAE build on these
(`formation_dae.solve`, `nullspace.nullspace_solve`). World frame (z up), SI units; the slots
are `physics.layout`'s.
"""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import (
    EULER, FORMATION_DRAG, FORMATION_INV_PAYLOAD_MASS, FORMATION_WIND, GUST_CENTER,
    GUST_DIRECTION, GUST_GRADIENT_DISTANCE, GUST_REFERENCE_SPEED, POSITION,
    UAV_ATTACH, UAV_DRAG, UAV_GYRO, UAV_INV_INERTIA, UAV_MASS, WRENCH_THRUST,
    WRENCH_TORQUE)
from multilift_sim.physics.state_slots import rates_slot, uav_slot


@jit
def air_velocity(px, py, gusts):
    """The air velocity w [m/s], world, at a point (px, py) [m] of the horizontal plane (the
    height does not matter): the sum of the 1-cosine gusts (Eq. 2.55), each of its speed along
    its direction, r the horizontal distance from its centre (a square root, not math.hypot:
    Python's and the C library's hypot round differently, and the uncompiled run must give
    the compiled one's bits)."""
    air_x = air_y = air_z = 0.0
    for k in range(gusts.shape[0]):
        east, north = px - gusts[k, GUST_CENTER], py - gusts[k, GUST_CENTER + 1]
        radius = math.sqrt(east * east + north * north)
        h = gusts[k, GUST_GRADIENT_DISTANCE]
        if radius > h:
            speed = 0.0
        else:
            speed = 0.5 * gusts[k, GUST_REFERENCE_SPEED] * (1.0 + math.cos(math.pi * radius / h))
        if speed != 0.0:
            air_x += speed * gusts[k, GUST_DIRECTION]
            air_y += speed * gusts[k, GUST_DIRECTION + 1]
            air_z += speed * gusts[k, GUST_DIRECTION + 2]
    return air_x, air_y, air_z


@jit
def payload_force_per_mass(px, py, pz, pvx, pvy, pvz, gusts, formation):
    """Drag (gusts and the steady wind included) on the payload over m_p [m/s^2], world,
    gravity excluded: at payload position (px, py, pz) [m] and velocity (pvx, pvy, pvz)
    [m/s]. (The numpy form is wind.gusts.payload_drag and gust_velocity; tests hold them
    equal.)"""
    drag = formation[FORMATION_DRAG]
    if drag <= 0.0:
        return 0.0, 0.0, 0.0
    air_x, air_y, air_z = air_velocity(px, py, gusts)
    air_x += formation[FORMATION_WIND]
    air_y += formation[FORMATION_WIND + 1]
    air_z += formation[FORMATION_WIND + 2]
    rel_x, rel_y, rel_z = pvx - air_x, pvy - air_y, pvz - air_z
    # Eq. 2.53 on the air-relative velocity: -c_pd v_rel |v_rel| / m_p
    scale = (-drag * formation[FORMATION_INV_PAYLOAD_MASS]
             * math.sqrt(rel_x * rel_x + rel_y * rel_y + rel_z * rel_z))
    return scale * rel_x, scale * rel_y, scale * rel_z


@jit
def body_rates(s_phi, c_phi, s_theta, c_theta, phi_dot, theta_dot, psi_dot):
    """omega = W(eta) eta_dot [rad/s], body FLU (Eq. 2.7), from the sines and cosines of roll
    and pitch and the Euler rates."""
    c_theta_psi_dot = c_theta * psi_dot
    return (phi_dot - s_theta * psi_dot, c_phi * theta_dot + s_phi * c_theta_psi_dot,
            c_phi * c_theta_psi_dot - s_phi * theta_dot)


@jit
def body_acceleration(uavs, i, torque_x, torque_y, torque_z, omega_x, omega_y, omega_z):
    """UAV i's omega_dot = J^-1 (tau - omega x J omega) [rad/s^2], body FLU, per principal
    axis (omega_dot_x = tau_x / I_xx - (I_zz - I_yy) / I_xx omega_y omega_z, cyclically),
    under body torque tau [N m] at body rates omega [rad/s]."""
    return (torque_x * uavs[i, UAV_INV_INERTIA] - uavs[i, UAV_GYRO] * omega_y * omega_z,
            torque_y * uavs[i, UAV_INV_INERTIA + 1] - uavs[i, UAV_GYRO + 1] * omega_z * omega_x,
            torque_z * uavs[i, UAV_INV_INERTIA + 2] - uavs[i, UAV_GYRO + 2] * omega_x * omega_y)


@jit
def uav_free_motion(x, i, wrenches, uavs, formation, acc):
    """UAV i's motion without its cable at state x: its attitude's eta_ddot [rad/s^2] into acc's
    EULER slots of UAV i (Euler's equation pulled back to eta, Eq. 2.7-2.8, 2.28), and returns
    its translational acceleration [m/s^2], world, from its thrust along R e_z (Eq. 2.6, 2.20)
    and its own drag in the steady wind, gravity excluded. Both formulations call it
    (`solve`, `physics.nullspace`)."""
    nq = rates_slot(uavs.shape[0])
    mass = uavs[i, UAV_MASS]
    r = uav_slot(i) + POSITION
    e = uav_slot(i) + EULER
    phi, theta, psi = x[e], x[e + 1], x[e + 2]
    vx, vy, vz = x[nq + r], x[nq + r + 1], x[nq + r + 2]
    phi_dot, theta_dot, psi_dot = x[nq + e], x[nq + e + 1], x[nq + e + 2]
    thrust = wrenches[i, WRENCH_THRUST]
    torque_x, torque_y = wrenches[i, WRENCH_TORQUE], wrenches[i, WRENCH_TORQUE + 1]
    torque_z = wrenches[i, WRENCH_TORQUE + 2]
    s_phi, c_phi = math.sin(phi), math.cos(phi)
    s_theta, c_theta = math.sin(theta), math.cos(theta)
    s_psi, c_psi = math.sin(psi), math.cos(psi)

    # Attitude: omega = W eta_dot (Eq. 2.7), Euler's equation J omega_dot = tau - omega x
    # J omega per axis (omega_dot_x = tau_x / I_xx - (I_zz - I_yy) / I_xx omega_y omega_z,
    # cyclically), then eta_ddot = W^-1 (omega_dot - W_dot eta_dot) (Eq. 2.8) -- the same
    # as M_eta^-1 (W^T tau - C_eta eta_dot), see multirotor.py; W_dot from
    # kinematics.euler_rate_matrix_dot.
    c_theta_psi_dot = c_theta * psi_dot
    omega_x, omega_y, omega_z = body_rates(s_phi, c_phi, s_theta, c_theta, phi_dot, theta_dot,
                                           psi_dot)
    s_theta_theta_psi_dot = s_theta * theta_dot * psi_dot
    rate_x, rate_y, rate_z = body_acceleration(uavs, i, torque_x, torque_y, torque_z, omega_x,
                                               omega_y, omega_z)
    w_eta_ddot_x = rate_x + c_theta_psi_dot * theta_dot
    w_eta_ddot_y = (rate_y - phi_dot * omega_z + s_phi * s_theta_theta_psi_dot)
    w_eta_ddot_z = (rate_z + phi_dot * omega_y + c_phi * s_theta_theta_psi_dot)
    yaw_part = s_phi * w_eta_ddot_y + c_phi * w_eta_ddot_z         # W^-1 of Eq. 2.8
    acc[e] = w_eta_ddot_x + s_theta / c_theta * yaw_part
    acc[e + 1] = c_phi * w_eta_ddot_y - s_phi * w_eta_ddot_z
    acc[e + 2] = yaw_part / c_theta

    # Unconstrained translational acceleration: thrust along R e_z (Eq. 2.6, 2.20).
    # Gravity is common to every body (in `solve` it cancels in a_p - a_i; added at the end).
    thrust_per_mass = thrust / mass
    axis_x, axis_y, axis_z = thrust_direction(s_phi, c_phi, s_theta, c_theta, s_psi, c_psi)
    thrust_ax = axis_x * thrust_per_mass
    thrust_ay = axis_y * thrust_per_mass
    thrust_az = axis_z * thrust_per_mass
    drag = uavs[i, UAV_DRAG]
    if drag > 0.0:  # the UAV's own drag in the steady wind: -c_d |v_rel| v_rel / m_i
        rel_x = vx - formation[FORMATION_WIND]
        rel_y = vy - formation[FORMATION_WIND + 1]
        rel_z = vz - formation[FORMATION_WIND + 2]
        scale = -drag / mass * math.sqrt(rel_x * rel_x + rel_y * rel_y + rel_z * rel_z)
        thrust_ax += scale * rel_x
        thrust_ay += scale * rel_y
        thrust_az += scale * rel_z
    return thrust_ax, thrust_ay, thrust_az


@jit
def thrust_direction(s_phi, c_phi, s_theta, c_theta, s_psi, c_psi):
    """R e_z (x, y, z) [unit, world]: the body z axis along which the rotors push, the third
    column of R = Rz(psi) Ry(theta) Rx(phi) (Eq. 2.6), from the angles' sines and cosines."""
    s_theta_c_phi = s_theta * c_phi
    return (c_psi * s_theta_c_phi + s_psi * s_phi, s_psi * s_theta_c_phi - c_psi * s_phi,
            c_theta * c_phi)


@jit
def thrust_axis(roll, pitch, yaw):
    """`thrust_direction` of the Euler angles (roll, pitch, yaw) [rad]."""
    return thrust_direction(math.sin(roll), math.cos(roll), math.sin(pitch), math.cos(pitch),
                            math.sin(yaw), math.cos(yaw))


@jit
def uav_rotation(phi, theta, psi):
    """R_i = Rz(psi) Ry(theta) Rx(phi) (3, 3), body FLU -> world (Eq. 2.6); its third column
    `thrust_direction`. (kinematics.rotation_matrix: the numpy form over stacks, the tests'
    oracle.)"""
    s_phi, c_phi = math.sin(phi), math.cos(phi)
    s_theta, c_theta = math.sin(theta), math.cos(theta)
    s_psi, c_psi = math.sin(psi), math.cos(psi)
    r = np.empty((3, 3))
    r[0, 0] = c_psi * c_theta
    r[0, 1] = c_psi * s_theta * s_phi - s_psi * c_phi
    r[1, 0] = s_psi * c_theta
    r[1, 1] = s_psi * s_theta * s_phi + c_psi * c_phi
    r[2, 0] = -s_theta
    r[2, 1] = c_theta * s_phi
    r[0, 2], r[1, 2], r[2, 2] = thrust_direction(s_phi, c_phi, s_theta, c_theta, s_psi, c_psi)
    return r


@jit
def attached_off_centre(uavs, i):
    """Whether UAV i's cable holds it off its centre of mass (UAV_ATTACH not zero)."""
    return (uavs[i, UAV_ATTACH] != 0.0 or uavs[i, UAV_ATTACH + 1] != 0.0
            or uavs[i, UAV_ATTACH + 2] != 0.0)


@jit
def uav_attach_motion(x, i, wrenches, uavs, out):
    """UAV i's attach point a_i (UAV_ATTACH, body FLU) relative to its centre of mass, world,
    into out (3, 3): its offset o = R_i a_i [m], rate o_dot = w x o [m/s] and acceleration
    without the cable R_i (omega_dot_0 x a_i) + w x (w x o) [m/s^2] (w = R_i omega_i; omega_dot_0
    from the rotor torque alone, `body_acceleration`); returns R_i (3, 3)."""
    nq = rates_slot(uavs.shape[0])
    e = uav_slot(i) + EULER
    phi, theta = x[e], x[e + 1]
    rotation = uav_rotation(phi, theta, x[e + 2])
    omega = body_rates(math.sin(phi), math.cos(phi), math.sin(theta), math.cos(theta),
                       x[nq + e], x[nq + e + 1], x[nq + e + 2])
    rate = body_acceleration(uavs, i, wrenches[i, WRENCH_TORQUE], wrenches[i, WRENCH_TORQUE + 1],
                             wrenches[i, WRENCH_TORQUE + 2], omega[0], omega[1], omega[2])
    a = (uavs[i, UAV_ATTACH], uavs[i, UAV_ATTACH + 1], uavs[i, UAV_ATTACH + 2])
    spin = cross(omega, a)                      # omega x a (body)
    turn = cross(omega, spin)                   # omega x (omega x a)
    push = cross(rate, a)                       # omega_dot_0 x a
    for row in range(3):
        out[0, row] = rotation[row, 0] * a[0] + rotation[row, 1] * a[1] + rotation[row, 2] * a[2]
        out[1, row] = (rotation[row, 0] * spin[0] + rotation[row, 1] * spin[1]
                       + rotation[row, 2] * spin[2])
        out[2, row] = (rotation[row, 0] * (push[0] + turn[0])
                       + rotation[row, 1] * (push[1] + turn[1])
                       + rotation[row, 2] * (push[2] + turn[2]))
    return rotation


@jit
def cross(a, b):
    """a x b of two 3-vectors (tuples or arrays), as a tuple."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@jit
def cable_moment_arm(uavs, i, rotation, d0, d1, d2):
    """k_i = a_i x R_i^T d_i [m^2], body FLU: the moment of a pull along d_i at UAV i's attach
    point, per unit of that pull."""
    h = (rotation[0, 0] * d0 + rotation[1, 0] * d1 + rotation[2, 0] * d2,
         rotation[0, 1] * d0 + rotation[1, 1] * d1 + rotation[2, 1] * d2,
         rotation[0, 2] * d0 + rotation[1, 2] * d1 + rotation[2, 2] * d2)
    return cross((uavs[i, UAV_ATTACH], uavs[i, UAV_ATTACH + 1], uavs[i, UAV_ATTACH + 2]), h)


@jit
def rotational_compliance(uavs, i, k0, k1, k2):
    """k_i . J_i^-1 k_i [m^4/(kg m^2)]: what a pull's moment adds to the cable's row of
    G M^-1 G^T, per 4 lambda_i^2."""
    return (k0 * k0 * uavs[i, UAV_INV_INERTIA] + k1 * k1 * uavs[i, UAV_INV_INERTIA + 1]
            + k2 * k2 * uavs[i, UAV_INV_INERTIA + 2])


@jit
def add_cable_torque(x, i, uavs, acc, pull, k0, k1, k2):
    """UAV i's eta_ddot in acc plus what the cable's moment pull k_i [N m] (pull = 2 lambda_i)
    adds: W^-1 J^-1 (pull k_i) (Eq. 2.8; the torque enters omega_dot linearly)."""
    e = uav_slot(i) + EULER
    s_phi, c_phi = math.sin(x[e]), math.cos(x[e])
    s_theta, c_theta = math.sin(x[e + 1]), math.cos(x[e + 1])
    w0 = pull * k0 * uavs[i, UAV_INV_INERTIA]
    w1 = pull * k1 * uavs[i, UAV_INV_INERTIA + 1]
    w2 = pull * k2 * uavs[i, UAV_INV_INERTIA + 2]
    yaw_part = s_phi * w1 + c_phi * w2
    acc[e] += w0 + s_theta / c_theta * yaw_part
    acc[e + 1] += c_phi * w1 - s_phi * w2
    acc[e + 2] += yaw_part / c_theta
