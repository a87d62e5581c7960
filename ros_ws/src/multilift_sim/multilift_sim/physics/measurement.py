"""What the controllers measure of each UAV, from the formation state (its ZYX angles from its
quaternion, `quaternion_euler`; its body rates), and the
rest of what the simulator's messages carry of it (its attitude as R and as a quaternion, its
body-frame velocity): the one place of these equations (`euler_rotation`, `euler_quaternion`;
kinematics.rotation_matrix and .quaternion_from_euler call them over stacks, msgvalues
.quaternion runs the uncompiled form for one attitude; tests/unit/test_kinematics.py holds them
to elementary rotations and scipy)."""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import (BODY_QUATERNION, BODY_RATES, MEASURED_BODY_RATES,
                                          MEASURED_EULER,
                                          MEASURED_POSITION, MEASURED_VELOCITY,
                                          ODOMETRY_BODY_VELOCITY, ODOMETRY_QUATERNION,
                                          ODOMETRY_ROTATION, POSITION)
from multilift_sim.physics.state_slots import (payload_slot, rates_slot, uav_attitude_slot,
                                               uav_slot)

# cos(pitch) below which `quaternion_euler` reads an attitude as gimbal-locked (pitch within
# ~1e-7 rad of +-90 deg): roll and yaw from R's rounding would be good to only ~1e-16 / cos
GIMBAL_LOCK = 1e-7


@jit
def measured_states(x, n, out):
    """Every UAV's measured state into out (n, MEASURED_COLUMNS or more; only the MEASURED_*
    slots are written) from the formation state x (docs/conventions.md): position [m] and
    velocity [m/s] (world), the ZYX Euler angles [rad] of its quaternion (`quaternion_euler`,
    Eq. 2.6) and its body rates omega [rad/s] (body FLU, the state's own)."""
    nq = rates_slot(n)
    for i in range(n):
        r = uav_slot(i) + POSITION
        for axis in range(3):
            out[i, MEASURED_POSITION + axis] = x[r + axis]
            out[i, MEASURED_VELOCITY + axis] = x[nq + r + axis]
        base = uav_attitude_slot(n, i)
        (out[i, MEASURED_EULER], out[i, MEASURED_EULER + 1],
         out[i, MEASURED_EULER + 2]) = quaternion_euler(
            x[base + BODY_QUATERNION], x[base + BODY_QUATERNION + 1],
            x[base + BODY_QUATERNION + 2], x[base + BODY_QUATERNION + 3])
        for axis in range(3):
            out[i, MEASURED_BODY_RATES + axis] = x[base + BODY_RATES + axis]


@jit
def quaternion_euler(w, qx, qy, qz):
    """The ZYX Euler angles (roll phi, pitch theta, yaw psi) [rad] of the unit quaternion
    (w, x, y, z), body -> world, R = Rz(psi) Ry(theta) Rx(phi) (Eq. 2.6): roll and yaw in
    (-pi, pi], pitch in [-pi/2, pi/2] from atan2 of -R_20 and cos(pitch) = |(R_00, R_10)|
    (full precision near +-90 deg; `euler_quaternion` the inverse). Within GIMBAL_LOCK of
    +-90 deg pitch, where only roll -+ yaw is defined (and rounding of the others would
    dominate it), yaw is 0 and roll all of it: atan2(-R_12, R_11)."""
    r20 = 2.0 * (qx * qz - w * qy)
    r00 = 1.0 - 2.0 * (qy * qy + qz * qz)
    r10 = 2.0 * (qx * qy + w * qz)
    cos_pitch = math.sqrt(r00 * r00 + r10 * r10)
    pitch = math.atan2(-r20, cos_pitch)
    if cos_pitch < GIMBAL_LOCK:
        return (math.atan2(-2.0 * (qy * qz - w * qx), 1.0 - 2.0 * (qx * qx + qz * qz)), pitch,
                0.0)
    return (math.atan2(2.0 * (qy * qz + w * qx), 1.0 - 2.0 * (qx * qx + qy * qy)), pitch,
            math.atan2(r10, r00))


@jit
def payload_position(x, n):
    """The payload's position r_p [m] (3,), world, in the formation state x of n UAVs (a view:
    what the snapshot carries and a leader's swing feedback reads, multilift_control.laws.swing)."""
    start = payload_slot(n)
    return x[start:start + 3]


@jit
def payload_velocity(x, n):
    """The payload's velocity v_p [m/s] (3,), world, in the formation state x of n UAVs (a view:
    what the snapshot carries and a leader's swing damping reads, multilift_control.laws.swing)."""
    start = rates_slot(n) + payload_slot(n)
    return x[start:start + 3]


@jit
def odometry_states(states, n, out):
    """Every UAV's odometry row into out (K, n, ODOMETRY_COLUMNS) for K formation states
    (K, len(x)) (FormationSimulator.snapshot: K = 1; the headless bag: a chunk's ticks):
    its measured state (`measured_states`), then the rest (`odometry_rows`)."""
    for k in range(states.shape[0]):
        measured_states(states[k], n, out[k])
    odometry_rows(out)


@jit
def odometry_rows(out):
    """The ODOMETRY_* slots of every row of out (K, n, ODOMETRY_COLUMNS) from its MEASURED_*
    slots (a state's, or the sensors' measurement of it, /uav{i}/measured_odom):
    - R = Rz(psi) Ry(theta) Rx(phi), body -> world (seed Eq. 2.6), row by row;
    - its velocity in the body frame R^T r_i_dot [m/s] (what nav_msgs/Odometry's twist holds),
      each element the sum (R_0j v_x + R_1j v_y) + R_2j v_z;
    - the unit quaternion (x, y, z, w) of R from the half angles."""
    for k in range(out.shape[0]):
        rows = out[k]
        for i in range(rows.shape[0]):
            phi = rows[i, MEASURED_EULER]
            theta = rows[i, MEASURED_EULER + 1]
            psi = rows[i, MEASURED_EULER + 2]
            r = ODOMETRY_ROTATION
            (rows[i, r], rows[i, r + 1], rows[i, r + 2], rows[i, r + 3], rows[i, r + 4],
             rows[i, r + 5], rows[i, r + 6], rows[i, r + 7],
             rows[i, r + 8]) = euler_rotation(phi, theta, psi)
            vx = rows[i, MEASURED_VELOCITY]
            vy = rows[i, MEASURED_VELOCITY + 1]
            vz = rows[i, MEASURED_VELOCITY + 2]
            for axis in range(3):  # column `axis` of R: row `axis` of R^T
                rows[i, ODOMETRY_BODY_VELOCITY + axis] = (
                    rows[i, r + axis] * vx + rows[i, r + 3 + axis] * vy
                    + rows[i, r + 6 + axis] * vz)
            q = ODOMETRY_QUATERNION
            (rows[i, q], rows[i, q + 1], rows[i, q + 2],
             rows[i, q + 3]) = euler_quaternion(phi, theta, psi)


@jit
def euler_rotation(phi, theta, psi):
    """R = Rz(psi) Ry(theta) Rx(phi), body -> world (seed Eq. 2.6), of ZYX Euler angles [rad],
    row by row (9 floats): the one form of it the messages and the analysis use (`odometry_rows`,
    `euler_rotations`: kinematics.rotation_matrix). The physics' own R (free_motion.uav_rotation,
    thrust_direction) groups its third column's products differently (c_psi (s_theta c_phi)):
    the same R to the last bit or so, kept apart so that every run flies to the same bits."""
    s_phi, c_phi = math.sin(phi), math.cos(phi)
    s_th, c_th = math.sin(theta), math.cos(theta)
    s_psi, c_psi = math.sin(psi), math.cos(psi)
    return (c_psi * c_th,
            c_psi * s_th * s_phi - s_psi * c_phi,
            c_psi * s_th * c_phi + s_psi * s_phi,
            s_psi * c_th,
            s_psi * s_th * s_phi + c_psi * c_phi,
            s_psi * s_th * c_phi - c_psi * s_phi,
            -s_th, c_th * s_phi, c_th * c_phi)


@jit
def euler_quaternion(phi, theta, psi):
    """The unit quaternion (x, y, z, w) of R = Rz(psi) Ry(theta) Rx(phi) from the half angles of
    ZYX Euler angles [rad], scalar last as geometry_msgs orders it: the one form of it
    (`odometry_rows`; msgvalues.quaternion runs its uncompiled form, kinematics
    .quaternion_from_euler `euler_quaternions`)."""
    half_roll, half_pitch, half_yaw = 0.5 * phi, 0.5 * theta, 0.5 * psi
    sr, cr = math.sin(half_roll), math.cos(half_roll)
    sp, cp = math.sin(half_pitch), math.cos(half_pitch)
    sy, cy = math.sin(half_yaw), math.cos(half_yaw)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


@jit
def euler_rotations(angles, out):
    """`euler_rotation` of each row of angles (m, 3) [rad] into out (m, 9)."""
    for k in range(angles.shape[0]):
        (out[k, 0], out[k, 1], out[k, 2], out[k, 3], out[k, 4], out[k, 5], out[k, 6], out[k, 7],
         out[k, 8]) = euler_rotation(angles[k, 0], angles[k, 1], angles[k, 2])


@jit
def euler_quaternions(angles, out):
    """`euler_quaternion` of each row of angles (m, 3) [rad] into out (m, 4)."""
    for k in range(angles.shape[0]):
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = euler_quaternion(angles[k, 0], angles[k, 1],
                                                                      angles[k, 2])


@jit
def quaternion_eulers(quaternions, out):
    """`quaternion_euler` of each row (w, x, y, z) of quaternions (m, 4) into out (m, 3) [rad]."""
    for k in range(quaternions.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = quaternion_euler(
            quaternions[k, 0], quaternions[k, 1], quaternions[k, 2], quaternions[k, 3])
