"""The control laws' per-tick arithmetic compiled with numba: `multilift_control.compiled`
imports this module only when the compiled kernels are used (NUMBA_CACHE_DIR is set there
first, by `multilift_sim.kernels`).

Each function is the pure-Python method it names, the same arithmetic in the same order in
plain floats; the pure methods stay the reference (tests/unit/test_compiled_laws.py holds
them equal). A controller's memory (integrals, the last tick's time, a follower's last lift)
lives in small float arrays the functions update in place; NaN stands for "none yet".
World frame z up, body FLU, ZYX Euler angles [rad], SI units.
"""
import math

import numba
import numpy as np

jit = numba.njit(cache=True, fastmath=False, nogil=True)

# CascadeController's constants, one float array (`cascade_constants`): the index of each
CASCADE_KP, CASCADE_KD, CASCADE_KI = 0, 3, 6          # position gains (3 each)
CASCADE_INTEGRAL_LIMIT, CASCADE_HOVER_MASS, CASCADE_GRAVITY, CASCADE_MAX_TILT = 9, 10, 11, 12
CASCADE_INERTIA, CASCADE_ATT_KP, CASCADE_ATT_KD = 13, 16, 19  # (3 each)
CASCADE_SQUARE_MIN, CASCADE_SQUARE_MAX = 22, 23
CASCADE_SIZE = 24
# FormationFollower's constants (`follower_constants`)
FOLLOWER_TWO_ALPHA, FOLLOWER_BETA_SQ, FOLLOWER_ALTITUDE_OFFSET = 0, 1, 2
FOLLOWER_HOVER_MASS, FOLLOWER_GRAVITY, FOLLOWER_KP_Z, FOLLOWER_KD_Z, FOLLOWER_KI_Z = 3, 4, 5, 6, 7
FOLLOWER_INTEGRAL_LIMIT, FOLLOWER_THRUST_COEFFICIENT, FOLLOWER_COMMANDED = 8, 9, 10
FOLLOWER_SIZE = 11


@jit
def _clipped(value, limit):
    """np.minimum(np.maximum(value, -limit), limit) of one float (NaN stays NaN)."""
    if value < -limit:
        value = -limit
    if value > limit:
        value = limit
    return value


@jit
def _wrap_angle(angle):
    """cascade.wrap_angle (numba's float % follows Python's)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


@jit
def cascade_position_force(constants, memory, t, position, velocity, position_ref,
                           velocity_ref, acceleration_ref):
    """CascadeController.position_force: the force [N] the thrust should produce, world.
    memory: (integral x, y, z [m/s^2], t of the last tick [s] or NaN), updated."""
    t_prev = memory[3]
    dt = 0.0 if math.isnan(t_prev) else max(0.0, t - t_prev)
    memory[3] = t
    limit = constants[CASCADE_INTEGRAL_LIMIT]
    force = np.empty(3)
    for axis in range(3):
        error = position_ref[axis] - position[axis]
        memory[axis] = _clipped(memory[axis] + constants[CASCADE_KI + axis] * error * dt, limit)
        accel = (acceleration_ref[axis] + constants[CASCADE_KP + axis] * error
                 + constants[CASCADE_KD + axis] * (velocity_ref[axis] - velocity[axis])
                 + memory[axis])
        gravity = constants[CASCADE_GRAVITY] if axis == 2 else 0.0  # gravity * E_Z
        force[axis] = constants[CASCADE_HOVER_MASS] * (accel + gravity)
    return force


@jit
def cascade_command(constants, pinv, collective, euler, body_rates, force, yaw):
    """CascadeController.command: (rotor speeds [rad/s], saturated, setpoint (roll, pitch,
    yaw) [rad], thrust [N]) that produce `force` (world) [N] at heading `yaw` [rad]."""
    # attitude_from_force (seed Eq. 3.13)
    fx, fy, fz = force[0], force[1], force[2]
    if fz < 1e-6:
        fz = 1e-6
    horizontal = math.hypot(fx, fy)
    limit = fz * math.tan(constants[CASCADE_MAX_TILT])
    if horizontal > limit:
        fx, fy = fx * (limit / horizontal), fy * (limit / horizontal)
    thrust = math.sqrt(fx * fx + fy * fy + fz * fz)
    s_psi, c_psi = math.sin(yaw), math.cos(yaw)
    tilt = (fx * s_psi - fy * c_psi) / thrust
    roll = math.asin(max(-1.0, min(1.0, tilt)))
    pitch = math.atan2(fx * c_psi + fy * s_psi, fz)
    setpoint = np.array((roll, pitch, yaw))
    # attitude_torque: PD on the Euler angles, J-scaled, plus omega x J omega
    p, q, r = body_rates[0], body_rates[1], body_rates[2]
    ix = constants[CASCADE_INERTIA]
    iy = constants[CASCADE_INERTIA + 1]
    iz = constants[CASCADE_INERTIA + 2]
    jp, jq, jr = ix * p, iy * q, iz * r
    gyro = (q * jr - r * jq, r * jp - p * jr, p * jq - q * jp)
    rates = (p, q, r)
    wrench = np.empty(4)
    wrench[0] = thrust
    for axis in range(3):
        error = _wrap_angle(setpoint[axis] - euler[axis])
        accel = (constants[CASCADE_ATT_KP + axis] * error
                 - constants[CASCADE_ATT_KD + axis] * rates[axis])
        wrench[1 + axis] = constants[CASCADE_INERTIA + axis] * accel + gyro[axis]
    # RotorMixer.rotor_speeds: inverse allocation, then the collective shift and the clip
    n_rotors = pinv.shape[0]
    square_min, square_max = constants[CASCADE_SQUARE_MIN], constants[CASCADE_SQUARE_MAX]
    request = np.empty(n_rotors)
    saturated = np.empty(n_rotors, dtype=np.bool_)
    highest = lowest = 0
    for k in range(n_rotors):
        total = 0.0
        for j in range(4):
            total += pinv[k, j] * wrench[j]
        request[k] = total
        saturated[k] = total > square_max or total < square_min
        if total > request[highest]:
            highest = k
        if total < request[lowest]:
            lowest = k
    high, low = request[highest], request[lowest]
    if high > square_max or low < square_min:
        if high - low <= square_max - square_min:
            above = (high - square_max) / collective[highest]
            below = (square_min - low) / collective[lowest]
            shift = -above if above > 0 else (below if below > 0 else 0.0)
            for k in range(n_rotors):
                request[k] = request[k] + shift * collective[k]
        for k in range(n_rotors):
            request[k] = min(max(request[k], square_min), square_max)
    return np.sqrt(request), saturated, setpoint, thrust


@jit
def cascade_update(constants, pinv, collective, memory, t, position, velocity, euler,
                   body_rates, position_ref, velocity_ref, acceleration_ref, yaw):
    """CascadeController.update: position_force, then command."""
    force = cascade_position_force(constants, memory, t, position, velocity, position_ref,
                                   velocity_ref, acceleration_ref)
    return cascade_command(constants, pinv, collective, euler, body_rates, force, yaw)


@jit
def linear_follower_force(constants, index, law_p, law_q, inv_m, weights, own_rows, first,
                          second, targets, row_index, memory, t, positions, velocities,
                          thrust_vectors):
    """FormationFollower.desired_force for linear (and V) rows (its O(n) law,
    `_linear_law_matrices`): (force [N] world, this follower's rows of g_vc [m], their rates
    [m/s]). memory: (altitude integral [m/s^2], t of the last tick [s] or NaN, the last lift
    asked x, y, z [N] or NaN), updated."""
    n = positions.shape[0]
    u = thrust_vectors.copy()
    if constants[FOLLOWER_COMMANDED] != 0.0 and not math.isnan(memory[2]):
        for axis in range(3):
            u[index, axis] = memory[2 + axis]
    r = positions.reshape(3 * n)
    v = velocities.reshape(3 * n)
    u_flat = u.reshape(3 * n)
    residual = np.empty(targets.shape[0])
    for k in range(targets.shape[0]):
        residual[k] = r[first[k]] - r[second[k]] - targets[k]
    rates = np.empty(own_rows.shape[0])
    for k in range(own_rows.shape[0]):
        total = 0.0
        for j in range(3 * n):
            total += own_rows[k, j] * v[j]
        rates[k] = total
    driven = np.empty(3 * n)  # M^-1 (u - f) + 2 alpha v
    for j in range(3 * n):
        driven[j] = inv_m[j] * (u_flat[j] - weights[j]) + constants[FOLLOWER_TWO_ALPHA] * v[j]
    force = np.empty(3)
    for axis in range(2):
        pushed = 0.0
        for j in range(3 * n):
            pushed += law_q[axis, j] * driven[j]
        held = 0.0
        for k in range(targets.shape[0]):
            held += law_p[axis, k] * residual[k]
        force[axis] = u[index, axis] + (pushed + constants[FOLLOWER_BETA_SQ] * held)
    t_prev = memory[1]
    dt = 0.0 if math.isnan(t_prev) else max(0.0, t - t_prev)
    memory[1] = t
    # the altitude loop to z_d,i = z_1 + offset (seed §3.2; see FormationFollower)
    error = positions[0, 2] + constants[FOLLOWER_ALTITUDE_OFFSET] - positions[index, 2]
    error_rate = -velocities[index, 2]
    memory[0] = _clipped(memory[0] + constants[FOLLOWER_KI_Z] * error * dt,
                         constants[FOLLOWER_INTEGRAL_LIMIT])
    force[2] = constants[FOLLOWER_HOVER_MASS] * (
        constants[FOLLOWER_GRAVITY] + constants[FOLLOWER_KP_Z] * error
        + constants[FOLLOWER_KD_Z] * error_rate + memory[0])
    own = np.empty(row_index.shape[0])
    for k in range(row_index.shape[0]):
        own[k] = residual[row_index[k]]
    return force, own, rates


@jit
def linear_follower_update(constants, index, law_p, law_q, inv_m, weights, own_rows, first,
                           second, targets, row_index, memory, t, positions, velocities,
                           thrust_vectors, cascade_constants, pinv, collective, euler,
                           body_rates, yaw):
    """FormationFollower.update for linear rows: desired force, the cascade's command, and
    the lift it asks for (kept in memory[2:5]). Returns (speeds, saturated, setpoint, thrust,
    rows of g_vc, their rates)."""
    force, errors, rates = linear_follower_force(
        constants, index, law_p, law_q, inv_m, weights, own_rows, first, second, targets,
        row_index, memory, t, positions, velocities, thrust_vectors)
    speeds, saturated, setpoint, thrust = cascade_command(
        cascade_constants, pinv, collective, euler, body_rates, force, yaw)
    # collective_thrust, k_T sum omega^2: numpy's sum in this order for fewer than 8 rotors
    # (it sums 8 or more pairwise: an octo's last bit may differ)
    total = 0.0
    for k in range(speeds.shape[0]):
        total += speeds[k] * speeds[k]
    lifted = constants[FOLLOWER_THRUST_COEFFICIENT] * total
    roll, pitch, heading = setpoint[0], setpoint[1], setpoint[2]
    s_phi, c_phi = math.sin(roll), math.cos(roll)
    s_theta, c_theta = math.sin(pitch), math.cos(pitch)
    s_psi, c_psi = math.sin(heading), math.cos(heading)
    memory[2] = (c_psi * s_theta * c_phi + s_psi * s_phi) * lifted  # kinematics.thrust_axis
    memory[3] = (s_psi * s_theta * c_phi - c_psi * s_phi) * lifted
    memory[4] = (c_theta * c_phi) * lifted
    return speeds, saturated, setpoint, thrust, errors, rates


@jit
def filtered_reference(t, omega, start, step_times, steps, ends, velocities, origins, starts,
                       final):
    """MissionPath._filtered: (position, velocity, acceleration) (9,) at t [s]; the raw
    path's arrays for the vertical axis (MissionPath._raw)."""
    out = np.zeros(9)
    out[0], out[1] = start[0], start[1]
    for k in range(step_times.shape[0]):
        x = t - step_times[k]
        if x <= 0.0:
            break
        decay = math.exp(-omega * x)
        moved = x - (2.0 - (2.0 + omega * x) * decay) / omega
        gained = 1.0 - (1.0 + omega * x) * decay
        pushed = omega * omega * x * decay
        for axis in range(2):
            out[axis] += steps[k, axis] * moved
            out[3 + axis] += steps[k, axis] * gained
            out[6 + axis] += steps[k, axis] * pushed
    # the vertical axis raw (MissionPath._raw): bisect_right of t in the segments' ends
    count = ends.shape[0]
    if count == 0 or t < 0.0:
        out[2] = start[2]
        return out
    k = 0
    while k < count and ends[k] <= t:
        k += 1
    if k >= count:
        out[2] = final[2]
        return out
    out[2] = origins[k, 2] + velocities[k, 2] * (t - starts[k])
    out[5] = velocities[k, 2]
    return out


# What every caller passes (CascadeController, FormationFollower, MissionPath): the signatures
# compiled ahead of time (multilift_sim.kernels.build_ahead_of_time). Arrays are read only but a
# controller's memory, which the code updates: the build fails should it write another, and
# callers may pass read-only arrays (a linear follower's law rows and the formation's states
# are views of frozen arrays).
_ARRAY = numba.types.Array(numba.float64, 1, 'C', readonly=True)
_MATRIX = numba.types.Array(numba.float64, 2, 'C', readonly=True)
_INDICES = numba.types.Array(numba.int64, 1, 'C', readonly=True)
_MEMORY, _OUT = numba.float64[::1], numba.float64[::1]
_F8 = numba.float64
_COMMAND = numba.types.Tuple((_OUT, numba.boolean[::1], _OUT, _F8))
AHEAD_OF_TIME = {
    'cascade_command': _COMMAND(_ARRAY, _MATRIX, _ARRAY, _ARRAY, _ARRAY, _ARRAY, _F8),
    'cascade_update': _COMMAND(_ARRAY, _MATRIX, _ARRAY, _MEMORY, _F8, _ARRAY, _ARRAY, _ARRAY,
                               _ARRAY, _ARRAY, _ARRAY, _ARRAY, _F8),
    'linear_follower_update': numba.types.Tuple(
        (_OUT, numba.boolean[::1], _OUT, _F8, _OUT, _OUT))(
        _ARRAY, numba.int64, _MATRIX, _MATRIX, _ARRAY, _ARRAY, _MATRIX, _INDICES, _INDICES,
        _ARRAY, _INDICES, _MEMORY, _F8, _MATRIX, _MATRIX, _MATRIX, _ARRAY, _MATRIX, _ARRAY,
        _ARRAY, _ARRAY, _F8),
    'filtered_reference': _OUT(_F8, _F8, _ARRAY, _ARRAY, _MATRIX, _ARRAY, _MATRIX, _MATRIX,
                               _ARRAY, _ARRAY),
}
