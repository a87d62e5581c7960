"""Each body's motion without the cables, on one formation's arrays: the air at a point (the
seed's 1-cosine gusts, Eq. 2.55), the payload's drag in it (Eq. 2.53) and each UAV's attitude
(its quaternion and body rates, `physics.attitude`; Eq. 2.28) and thrust (Eq. 2.6, 2.20). Both
formulations of the DAE build on these
(`formation_dae.solve`, `nullspace.nullspace_solve`). World frame (z up), SI units; the slots
are `physics.layout`'s.
"""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import (quaternion_axis_z, quaternion_rate,
                                           quaternion_rotation)
from multilift_sim.physics.layout import (
    BODY_QUATERNION, BODY_RATES, CABLE_OFFSET, FORMATION_DRAG, FORMATION_GRAVITY,
    FORMATION_INV_PAYLOAD_MASS, FORMATION_WIND,
    GUST_CENTER,
    GUST_DIRECTION, GUST_GRADIENT_DISTANCE, GUST_REFERENCE_SPEED, POSITION,
    UAV_ATTACH, UAV_DRAG, UAV_GYRO, UAV_INV_INERTIA, UAV_MASS, WRENCH_THRUST,
    WRENCH_TORQUE)
from multilift_sim.physics.state_slots import (payload_slot, rates_slot, uav_attitude_slot,
                                               uav_slot)


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
def payload_motion(x, n, gusts, formation):
    """The payload's position [m], velocity [m/s] and drag over m_p [m/s^2] (world; gusts and
    the steady wind included, gravity excluded) at state x of n UAVs: nine floats, what a
    point payload's solve reads of it first."""
    p = payload_slot(n)
    nq = rates_slot(n)
    px, py, pz = x[p], x[p + 1], x[p + 2]
    pvx, pvy, pvz = x[nq + p], x[nq + p + 1], x[nq + p + 2]
    drag_ax, drag_ay, drag_az = payload_force_per_mass(px, py, pz, pvx, pvy, pvz, gusts,
                                                       formation)
    return px, py, pz, pvx, pvy, pvz, drag_ax, drag_ay, drag_az


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
    """UAV i's motion without its cable at state x: its attitude block's rate (the quaternion's
    q_dot = q (x) (0, omega) / 2 and Euler's equation J omega_dot = tau - omega x J omega,
    Eq. 2.28 in body rates) into acc at its block's place (`uav_attitude_slot` - (3n + 3): acc
    holds q_ddot, then the attitude blocks' rates), and returns its translational acceleration
    [m/s^2], world, from its thrust along R e_z (Eq. 2.6, 2.20) and its own drag in the steady
    wind, gravity excluded. Both formulations call it (`solve`, `physics.nullspace`)."""
    n = uavs.shape[0]
    nq = rates_slot(n)
    mass = uavs[i, UAV_MASS]
    r = uav_slot(i) + POSITION
    base = uav_attitude_slot(n, i)
    vx, vy, vz = x[nq + r], x[nq + r + 1], x[nq + r + 2]
    omega_x = x[base + BODY_RATES]
    omega_y = x[base + BODY_RATES + 1]
    omega_z = x[base + BODY_RATES + 2]
    rate = base - nq  # this block's derivative in acc
    (acc[rate + BODY_QUATERNION], acc[rate + BODY_QUATERNION + 1],
     acc[rate + BODY_QUATERNION + 2], acc[rate + BODY_QUATERNION + 3]) = quaternion_rate(
        x, base, omega_x, omega_y, omega_z)
    (acc[rate + BODY_RATES], acc[rate + BODY_RATES + 1],
     acc[rate + BODY_RATES + 2]) = body_acceleration(
        uavs, i, wrenches[i, WRENCH_TORQUE], wrenches[i, WRENCH_TORQUE + 1],
        wrenches[i, WRENCH_TORQUE + 2], omega_x, omega_y, omega_z)

    # Unconstrained translational acceleration: thrust along R e_z (Eq. 2.6, 2.20).
    # Gravity is common to every body (in `solve` it cancels in a_p - a_i; added at the end).
    thrust_per_mass = wrenches[i, WRENCH_THRUST] / mass
    axis_x, axis_y, axis_z = quaternion_axis_z(x, base)
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
    base = uav_attitude_slot(uavs.shape[0], i)
    rotation = quaternion_rotation(x, base)
    omega = (x[base + BODY_RATES], x[base + BODY_RATES + 1], x[base + BODY_RATES + 2])
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
def cable_turn(uavs, i, pull, k0, k1, k2):
    """J_i^-1 (pull k_i) [rad/s^2 per N m of pull k_i, body FLU]: what the cable's moment pull
    k_i (pull = 2 lambda_i [N/m], k_i [m^2]) adds to UAV i's omega_dot (or, for an impulse,
    to omega; for a Newton step's shift, the body-frame turn), as 3 floats."""
    return (pull * k0 * uavs[i, UAV_INV_INERTIA], pull * k1 * uavs[i, UAV_INV_INERTIA + 1],
            pull * k2 * uavs[i, UAV_INV_INERTIA + 2])


@jit
def add_cable_torque(uavs, i, rates, at, pull, k0, k1, k2):
    """rates[at:at + 3] (UAV i's omega_dot in an acc, or its omega in a state) plus
    `cable_turn`: the torque enters Euler's equation linearly (Eq. 2.28)."""
    t0, t1, t2 = cable_turn(uavs, i, pull, k0, k1, k2)
    rates[at] += t0
    rates[at + 1] += t1
    rates[at + 2] += t2


@jit
def payload_pulled(cables, multipliers, formation, drag_ax, drag_ay, drag_az, acc, p):
    """The point payload's q_ddot into acc[p:p + 3] [m/s^2], world: its drag over m_p (drag_a*)
    less the cables' pull 2 sum_i lambda_i d_i / m_p (seed Eq. 2.70; d_i at CABLE_OFFSET of
    `cables`, Lambda in `multipliers` [N/m]), less gravity. Both solves with multipliers end
    with it (`formation_dae.solve`, `prescribed.prescribed_solve`)."""
    sum_x = sum_y = sum_z = 0.0
    for i in range(multipliers.shape[0]):
        multiplier = multipliers[i]
        sum_x += multiplier * cables[i, CABLE_OFFSET]
        sum_y += multiplier * cables[i, CABLE_OFFSET + 1]
        sum_z += multiplier * cables[i, CABLE_OFFSET + 2]
    pull = 2.0 * formation[FORMATION_INV_PAYLOAD_MASS]
    gravity = formation[FORMATION_GRAVITY]
    acc[p] = drag_ax - pull * sum_x
    acc[p + 1] = drag_ay - pull * sum_y
    acc[p + 2] = drag_az - pull * sum_z - gravity
