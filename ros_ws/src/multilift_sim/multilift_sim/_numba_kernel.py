"""The compiled float kernel (numba): see multilift_sim.kernels, which imports this module
only when the compiled kernel is used (NUMBA_CACHE_DIR is set there first)."""
import math

import numba
import numpy as np

jit = numba.njit(cache=True, fastmath=False, nogil=True)


@jit
def force_per_mass(px, py, pz, pvx, pvy, pvz, gusts, inv_payload_mass, has_drag, drag):
    if not has_drag:
        return 0.0, 0.0, 0.0
    air_x = air_y = air_z = 0.0
    for k in range(gusts.shape[0]):
        radius = math.hypot(px - gusts[k, 0], py - gusts[k, 1])
        h = gusts[k, 5]
        if radius > h:
            speed = 0.0
        else:
            speed = 0.5 * gusts[k, 6] * (1.0 + math.cos(math.pi * radius / h))
        if speed != 0.0:
            air_x += speed * gusts[k, 2]
            air_y += speed * gusts[k, 3]
            air_z += speed * gusts[k, 4]
    rel_x, rel_y, rel_z = pvx - air_x, pvy - air_y, pvz - air_z
    scale = (-drag * inv_payload_mass
             * math.sqrt(rel_x * rel_x + rel_y * rel_y + rel_z * rel_z))
    return scale * rel_x, scale * rel_y, scale * rel_z


@jit
def solve(x, wrenches, uavs, gusts, payload_mass, inv_payload_mass, gravity, two_alpha,
          beta_sq, has_drag, drag, acc, multipliers, cables):
    """dynamics.FormationModel._solve_floats; writes acc (nq,) and multipliers (n,)."""
    n = uavs.shape[0]
    nq = 6 * n + 3
    p = 6 * n
    px, py, pz = x[p], x[p + 1], x[p + 2]
    pvx, pvy, pvz = x[nq + p], x[nq + p + 1], x[nq + p + 2]
    drag_ax, drag_ay, drag_az = force_per_mass(px, py, pz, pvx, pvy, pvz, gusts,
                                               inv_payload_mass, has_drag, drag)
    s00 = s11 = s22 = 0.25 * payload_mass
    s01 = s02 = s12 = sb0 = sb1 = sb2 = 0.0
    for i in range(n):
        mass, length_sq = uavs[i, 0], uavs[i, 1]
        inv_ixx, inv_iyy, inv_izz = uavs[i, 2], uavs[i, 3], uavs[i, 4]
        gyro_x, gyro_y, gyro_z = uavs[i, 5], uavs[i, 6], uavs[i, 7]
        base = 6 * i
        rx, ry, rz = x[base], x[base + 1], x[base + 2]
        phi, theta, psi = x[base + 3], x[base + 4], x[base + 5]
        vx, vy, vz = x[nq + base], x[nq + base + 1], x[nq + base + 2]
        phi_dot, theta_dot, psi_dot = x[nq + base + 3], x[nq + base + 4], x[nq + base + 5]
        thrust, torque_x = wrenches[i, 0], wrenches[i, 1]
        torque_y, torque_z = wrenches[i, 2], wrenches[i, 3]
        s_phi, c_phi = math.sin(phi), math.cos(phi)
        s_theta, c_theta = math.sin(theta), math.cos(theta)
        s_psi, c_psi = math.sin(psi), math.cos(psi)

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
        yaw_part = s_phi * w_eta_ddot_y + c_phi * w_eta_ddot_z
        acc[base + 3] = w_eta_ddot_x + s_theta / c_theta * yaw_part
        acc[base + 4] = c_phi * w_eta_ddot_y - s_phi * w_eta_ddot_z
        acc[base + 5] = yaw_part / c_theta

        thrust_per_mass = thrust / mass
        s_theta_c_phi = s_theta * c_phi
        thrust_ax = (c_psi * s_theta_c_phi + s_psi * s_phi) * thrust_per_mass
        thrust_ay = (s_psi * s_theta_c_phi - c_psi * s_phi) * thrust_per_mass
        thrust_az = c_theta * c_phi * thrust_per_mass

        dx, dy, dz = px - rx, py - ry, pz - rz
        dvx, dvy, dvz = pvx - vx, pvy - vy, pvz - vz
        offset_sq = dx * dx + dy * dy + dz * dz
        cable_rhs = (2.0 * (dx * (drag_ax - thrust_ax) + dy * (drag_ay - thrust_ay)
                            + dz * (drag_az - thrust_az))
                     + 2.0 * (dvx * dvx + dvy * dvy + dvz * dvz)
                     + two_alpha * 2.0 * (dx * dvx + dy * dvy + dz * dvz)
                     + beta_sq * (offset_sq - length_sq))
        inv_delta = 0.25 * mass / offset_sq
        s00 += dx * dx * inv_delta
        s01 += dx * dy * inv_delta
        s02 += dx * dz * inv_delta
        s11 += dy * dy * inv_delta
        s12 += dy * dz * inv_delta
        s22 += dz * dz * inv_delta
        weighted_rhs = cable_rhs * inv_delta
        sb0 += dx * weighted_rhs
        sb1 += dy * weighted_rhs
        sb2 += dz * weighted_rhs
        cables[i, 0], cables[i, 1], cables[i, 2] = dx, dy, dz
        cables[i, 3], cables[i, 4] = cable_rhs, inv_delta
        cables[i, 5], cables[i, 6], cables[i, 7] = thrust_ax, thrust_ay, thrust_az
    c00 = s11 * s22 - s12 * s12
    c01 = s02 * s12 - s01 * s22
    c02 = s01 * s12 - s02 * s11
    c11 = s00 * s22 - s02 * s02
    c12 = s01 * s02 - s00 * s12
    c22 = s00 * s11 - s01 * s01
    inv_det = 1.0 / (s00 * c00 + s01 * c01 + s02 * c02)
    y0 = (c00 * sb0 + c01 * sb1 + c02 * sb2) * inv_det
    y1 = (c01 * sb0 + c11 * sb1 + c12 * sb2) * inv_det
    y2 = (c02 * sb0 + c12 * sb1 + c22 * sb2) * inv_det
    sum_x = sum_y = sum_z = 0.0
    for i in range(n):
        dx, dy, dz = cables[i, 0], cables[i, 1], cables[i, 2]
        multiplier = (cables[i, 3] - dx * y0 - dy * y1 - dz * y2) * cables[i, 4]
        multipliers[i] = multiplier
        pull = 2.0 * multiplier / uavs[i, 0]
        base = 6 * i
        acc[base] = cables[i, 5] + pull * dx
        acc[base + 1] = cables[i, 6] + pull * dy
        acc[base + 2] = cables[i, 7] + pull * dz - gravity
        sum_x += multiplier * dx
        sum_y += multiplier * dy
        sum_z += multiplier * dz
    pull = 2.0 * inv_payload_mass
    acc[p] = drag_ax - pull * sum_x
    acc[p + 1] = drag_ay - pull * sum_y
    acc[p + 2] = drag_az - pull * sum_z - gravity


@jit
def integrate_period(uavs, gusts, payload_mass, inv_payload_mass, gravity, two_alpha,
                     beta_sq, has_drag, drag, x, wrenches, dt, steps):
    n = uavs.shape[0]
    nq = 6 * n + 3
    size = 2 * nq
    half, sixth = 0.5 * dt, dt / 6.0
    acc = np.empty(nq)
    cables = np.empty((n, 8))
    first = np.empty(n)
    scratch = np.empty(n)
    k1, k2, k3, k4 = np.empty(size), np.empty(size), np.empty(size), np.empty(size)
    stage = np.empty(size)
    state = x.copy()
    for step in range(steps):
        solve(state, wrenches, uavs, gusts, payload_mass, inv_payload_mass, gravity,
              two_alpha, beta_sq, has_drag, drag, acc, first if step == 0 else scratch,
              cables)
        for j in range(nq):
            k1[j] = state[nq + j]
            k1[nq + j] = acc[j]
        for j in range(size):
            stage[j] = state[j] + half * k1[j]
        solve(stage, wrenches, uavs, gusts, payload_mass, inv_payload_mass, gravity,
              two_alpha, beta_sq, has_drag, drag, acc, scratch, cables)
        for j in range(nq):
            k2[j] = stage[nq + j]
            k2[nq + j] = acc[j]
        for j in range(size):
            stage[j] = state[j] + half * k2[j]
        solve(stage, wrenches, uavs, gusts, payload_mass, inv_payload_mass, gravity,
              two_alpha, beta_sq, has_drag, drag, acc, scratch, cables)
        for j in range(nq):
            k3[j] = stage[nq + j]
            k3[nq + j] = acc[j]
        for j in range(size):
            stage[j] = state[j] + dt * k3[j]
        solve(stage, wrenches, uavs, gusts, payload_mass, inv_payload_mass, gravity,
              two_alpha, beta_sq, has_drag, drag, acc, scratch, cables)
        for j in range(nq):
            k4[j] = stage[nq + j]
            k4[nq + j] = acc[j]
        for j in range(size):
            state[j] = state[j] + sixth * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j])
    g = np.empty(n)
    g_dot = np.empty(n)
    p = 6 * n
    for i in range(n):
        b = 6 * i
        dx = state[p] - state[b]
        dy = state[p + 1] - state[b + 1]
        dz = state[p + 2] - state[b + 2]
        dvx = state[nq + p] - state[nq + b]
        dvy = state[nq + p + 1] - state[nq + b + 1]
        dvz = state[nq + p + 2] - state[nq + b + 2]
        g[i] = dx * dx + dy * dy + dz * dz - uavs[i, 1]
        g_dot[i] = 2.0 * (dx * dvx + dy * dvy + dz * dvz)
    return state, first, g, g_dot


# What every caller passes (multilift_sim.kernels.integrate): the signatures compiled ahead of
# time (multilift_sim.kernels.build_ahead_of_time). Every array is read only here: the build
# fails should the code write one, and callers may pass read-only arrays.
_ARRAY = numba.types.Array(numba.float64, 1, 'C', readonly=True)
_MATRIX = numba.types.Array(numba.float64, 2, 'C', readonly=True)
_F8 = numba.float64
AHEAD_OF_TIME = {
    'integrate_period': numba.types.UniTuple(numba.float64[::1], 4)(
        _MATRIX, _MATRIX, _F8, _F8, _F8, _F8, _F8, numba.boolean, _F8, _ARRAY, _MATRIX, _F8,
        numba.int64),
}
