"""Each body's motion without the cables, on one formation's arrays: the air at a point (the
seed's 1-cosine gusts, Eq. 2.55), the payload's drag in it (Eq. 2.53) and each UAV's attitude
and thrust (Eq. 2.6-2.8, 2.20, 2.28). Both formulations of the DAE build on these
(`formation_dae.solve`, `nullspace.nullspace_solve`). World frame (z up), SI units; the slots
are `physics.layout`'s.
"""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import (
    EULER, FORMATION_DRAG, FORMATION_INV_PAYLOAD_MASS, FORMATION_WIND, GUST_CENTER,
    GUST_DIRECTION, GUST_GRADIENT_DISTANCE, GUST_REFERENCE_SPEED, PAYLOAD_COORDINATES, POSITION,
    UAV_COORDINATES, UAV_DRAG, UAV_GYRO, UAV_INV_INERTIA, UAV_MASS, WRENCH_THRUST, WRENCH_TORQUE)


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
    [m/s]. (The numpy form is disturbances.payload_drag and gust_velocity; tests hold them
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
def uav_free_motion(x, i, wrenches, uavs, formation, acc):
    """UAV i's motion without its cable at state x: its attitude's eta_ddot [rad/s^2] into acc's
    EULER slots of UAV i (Euler's equation pulled back to eta, Eq. 2.7-2.8, 2.28), and returns
    its translational acceleration [m/s^2], world, from its thrust along R e_z (Eq. 2.6, 2.20)
    and its own drag in the steady wind, gravity excluded. Both formulations call it
    (`solve`, `physics.nullspace`)."""
    nq = UAV_COORDINATES * uavs.shape[0] + PAYLOAD_COORDINATES
    mass = uavs[i, UAV_MASS]
    inv_ixx, inv_iyy = uavs[i, UAV_INV_INERTIA], uavs[i, UAV_INV_INERTIA + 1]
    inv_izz = uavs[i, UAV_INV_INERTIA + 2]
    gyro_x, gyro_y, gyro_z = uavs[i, UAV_GYRO], uavs[i, UAV_GYRO + 1], uavs[i, UAV_GYRO + 2]
    r = UAV_COORDINATES * i + POSITION
    e = UAV_COORDINATES * i + EULER
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
    omega_x = phi_dot - s_theta * psi_dot
    omega_y = c_phi * theta_dot + s_phi * c_theta_psi_dot
    omega_z = c_phi * c_theta_psi_dot - s_phi * theta_dot
    s_theta_theta_psi_dot = s_theta * theta_dot * psi_dot
    w_eta_ddot_x = (torque_x * inv_ixx - gyro_x * omega_y * omega_z
                    + c_theta_psi_dot * theta_dot)
    w_eta_ddot_y = (torque_y * inv_iyy - gyro_y * omega_z * omega_x
                    - phi_dot * omega_z + s_phi * s_theta_theta_psi_dot)
    w_eta_ddot_z = (torque_z * inv_izz - gyro_z * omega_x * omega_y
                    + phi_dot * omega_y + c_phi * s_theta_theta_psi_dot)
    yaw_part = s_phi * w_eta_ddot_y + c_phi * w_eta_ddot_z         # W^-1 of Eq. 2.8
    acc[e] = w_eta_ddot_x + s_theta / c_theta * yaw_part
    acc[e + 1] = c_phi * w_eta_ddot_y - s_phi * w_eta_ddot_z
    acc[e + 2] = yaw_part / c_theta

    # Unconstrained translational acceleration: thrust along R e_z (Eq. 2.6, 2.20).
    # Gravity is common to every body (in `solve` it cancels in a_p - a_i; added at the end).
    thrust_per_mass = thrust / mass
    s_theta_c_phi = s_theta * c_phi
    thrust_ax = (c_psi * s_theta_c_phi + s_psi * s_phi) * thrust_per_mass
    thrust_ay = (s_psi * s_theta_c_phi - c_psi * s_phi) * thrust_per_mass
    thrust_az = c_theta * c_phi * thrust_per_mass
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
