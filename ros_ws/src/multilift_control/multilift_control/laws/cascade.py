"""The multirotor cascade (seed Ch. 3): position loop -> the force the thrust should produce
-> attitude setpoint and thrust (Eq. 3.13) -> attitude loop -> body torques -> `mixer`; and a
leader's tick along the mission (`reference`).

constants: CASCADE_* slots, memory: CASCADE_INTEGRAL, CASCADE_LAST_T (layout); a UAV's state
is a row of UAV_* slots (world, z up; body FLU; ZYX Euler angles [rad])."""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (CASCADE_ATT_KD, CASCADE_ATT_KP, CASCADE_GRAVITY,
                                           CASCADE_HOVER_MASS, CASCADE_INERTIA,
                                           CASCADE_INTEGRAL, CASCADE_INTEGRAL_LIMIT, CASCADE_KD,
                                           CASCADE_KI, CASCADE_KP, CASCADE_LAST_T,
                                           CASCADE_MAX_TILT, CASCADE_SQUARE_MAX,
                                           CASCADE_SQUARE_MIN, CASCADE_SWING_DAMPING,
                                           CASCADE_SWING_STIFFNESS, REFERENCE_ACCELERATION,
                                           REFERENCE_POSITION, REFERENCE_VELOCITY,
                                           REFERENCE_YAW, UAV_BODY_RATES, UAV_EULER,
                                           UAV_POSITION, UAV_VELOCITY)
from multilift_control.laws.mixer import rotor_speeds
from multilift_control.laws.reference import mission_reference
from multilift_control.laws.swing import swing_feedback


# the swing feedback's tries at a share 1, 1/2, 1/4 of itself before it yields (leader_update)
YIELD_STEPS = 3


@jit
def clipped(value, limit):
    """value within [-limit, limit] (NaN stays NaN): np.minimum(np.maximum(value, -limit),
    limit) of one float."""
    if value < -limit:
        value = -limit
    if value > limit:
        value = limit
    return value


@jit
def wrap_angle(angle):
    """An angle [rad] wrapped to [-pi, pi) (numba's float % follows Python's)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


@jit
def elapsed(memory, slot, t):
    """The time since the tick noted in memory[slot] [s] (0 at the first: NaN there, and never
    negative); notes t [s] there."""
    t_prev = memory[slot]
    dt = 0.0 if math.isnan(t_prev) else max(0.0, t - t_prev)
    memory[slot] = t
    return dt


@jit
def position_force(constants, memory, t, state, reference):
    """The force the thrust should produce, world [N] (3,), at t [s]: PID on position with the
    reference's velocity and acceleration fed forward and gravity fed forward with the hover
    mass (the UAV and its static payload share; the cable's pull beyond it is a disturbance
    the integral absorbs, as in the seed). Advances the integral (clamped per axis to
    CASCADE_INTEGRAL_LIMIT) in memory. reference: REFERENCE_* slots."""
    dt = elapsed(memory, CASCADE_LAST_T, t)
    limit = constants[CASCADE_INTEGRAL_LIMIT]
    force = np.empty(3)
    for axis in range(3):
        error = reference[REFERENCE_POSITION + axis] - state[UAV_POSITION + axis]
        slot = CASCADE_INTEGRAL + axis
        memory[slot] = clipped(memory[slot] + constants[CASCADE_KI + axis] * error * dt, limit)
        accel = (reference[REFERENCE_ACCELERATION + axis] + constants[CASCADE_KP + axis] * error
                 + constants[CASCADE_KD + axis] * (reference[REFERENCE_VELOCITY + axis]
                                                   - state[UAV_VELOCITY + axis])
                 + memory[slot])
        gravity = constants[CASCADE_GRAVITY] if axis == 2 else 0.0  # gravity e_z
        force[axis] = constants[CASCADE_HOVER_MASS] * (accel + gravity)
    return force


@jit
def attitude_from_force(force, yaw, max_tilt):
    """(roll [rad], pitch [rad], thrust [N]) that point the thrust along `force` (world) [N] at
    heading `yaw` [rad]: seed Eq. 3.13 with u_T = |force|, R e_z = (c_phi s_theta c_psi +
    s_phi s_psi, c_phi s_theta s_psi - s_phi c_psi, c_phi c_theta) for ZYX angles. The tilt is
    limited to `max_tilt` [rad] by shrinking the horizontal part (and f_z kept >= 1e-6 N)."""
    fx, fy, fz = force[0], force[1], force[2]
    if fz < 1e-6:
        fz = 1e-6
    # not math.hypot: Python's and numba's (the C library's) may round differently
    horizontal = math.sqrt(fx * fx + fy * fy)
    limit = fz * math.tan(max_tilt)
    if horizontal > limit:
        fx, fy = fx * (limit / horizontal), fy * (limit / horizontal)
    thrust = math.sqrt(fx * fx + fy * fy + fz * fz)
    s_psi, c_psi = math.sin(yaw), math.cos(yaw)
    roll = math.asin(max(-1.0, min(1.0, (fx * s_psi - fy * c_psi) / thrust)))
    pitch = math.atan2(fx * c_psi + fy * s_psi, fz)
    return roll, pitch, thrust


@jit
def body_rates_and_gyro(constants, state):
    """(omega (3,) [rad/s], omega x J omega (3,) [N m]) of one UAV's state, body FLU, J its
    CASCADE_INERTIA: what its attitude and rate loops both add to J omega_dot."""
    p = state[UAV_BODY_RATES]
    q = state[UAV_BODY_RATES + 1]
    r = state[UAV_BODY_RATES + 2]
    jp = constants[CASCADE_INERTIA] * p
    jq = constants[CASCADE_INERTIA + 1] * q
    jr = constants[CASCADE_INERTIA + 2] * r
    return (p, q, r), (q * jr - r * jq, r * jp - p * jr, p * jq - q * jp)


@jit
def attitude_torque(constants, state, setpoint):
    """Body torque [N m] (3,) driving the Euler angles to `setpoint` (roll, pitch, yaw) [rad]:
    PD on each angle, J-scaled, plus the gyroscopic omega x J omega."""
    rates, gyro = body_rates_and_gyro(constants, state)
    torque = np.empty(3)
    for axis in range(3):
        error = wrap_angle(setpoint[axis] - state[UAV_EULER + axis])
        accel = (constants[CASCADE_ATT_KP + axis] * error
                 - constants[CASCADE_ATT_KD + axis] * rates[axis])
        torque[axis] = constants[CASCADE_INERTIA + axis] * accel + gyro[axis]
    return torque


@jit
def attitude_command(constants, mixer, state, setpoint, thrust):
    """(rotor speeds [rad/s], saturated) holding `setpoint` (roll, pitch, yaw) [rad] with
    collective `thrust` [N]: the attitude loop, then the mixer (the cascade's inner half)."""
    torque = attitude_torque(constants, state, setpoint)
    wrench = np.array((thrust, torque[0], torque[1], torque[2]))
    return rotor_speeds(mixer, constants[CASCADE_SQUARE_MIN], constants[CASCADE_SQUARE_MAX],
                        wrench)


@jit
def command(constants, mixer, state, force, yaw):
    """(rotor speeds [rad/s], saturated, setpoint (roll, pitch, yaw) [rad], thrust [N]) that
    produce `force` (world) [N] at heading `yaw` [rad]: Eq. 3.13, the attitude loop, the mixer.
    The thrust is asked along the current body z."""
    roll, pitch, thrust = attitude_from_force(force, yaw, constants[CASCADE_MAX_TILT])
    setpoint = np.array((roll, pitch, yaw))
    speeds, saturated = attitude_command(constants, mixer, state, setpoint, thrust)
    return speeds, saturated, setpoint, thrust


@jit
def cascade_update(constants, mixer, memory, t, state, reference, yaw):
    """One tick of the cascade at t [s] tracking `reference` (REFERENCE_* slots) at heading
    `yaw` [rad]: `position_force`, then `command`."""
    force = position_force(constants, memory, t, state, reference)
    return command(constants, mixer, state, force, yaw)


@jit
def leader_update(constants, mixer, memory, mission, segments, steps, t, states,
                  payload_position, payload_velocity):
    """A leader's tick at t [s]: the mission reference (`reference.mission_reference`) tracked
    by the cascade at the reference's heading (REFERENCE_YAW; the seed's segments: 0). With
    CASCADE_SWING_STIFFNESS or _DAMPING not 0 the swing feedback (`swing.swing_feedback`) adds
    m a_s to the position loop's force (as a_s added to the reference's acceleration) unless
    that asks a rotor beyond its limits: then the force without it goes (the feedback yields
    to the mission). states (n, UAV_STATE_SIZE): every
    UAV's, the leader's first; payload_position [m], payload_velocity [m/s] (3,), world (read
    only with the feedback on). Returns (speeds, saturated, setpoint, thrust, reference)."""
    reference = mission_reference(mission, segments, steps, t)
    state = states[0]
    force = position_force(constants, memory, t, state, reference)
    if constants[CASCADE_SWING_STIFFNESS] != 0.0 or constants[CASCADE_SWING_DAMPING] != 0.0:
        feedback = swing_feedback(constants, states, payload_position, payload_velocity)
        share = 1.0
        for _ in range(YIELD_STEPS):
            pushed = force.copy()
            for axis in range(2):
                pushed[axis] += share * constants[CASCADE_HOVER_MASS] * feedback[axis]
            speeds, saturated, setpoint, thrust = command(constants, mixer, state, pushed,
                                                          reference[REFERENCE_YAW])
            if not saturated.any():
                return speeds, saturated, setpoint, thrust, reference
            share *= 0.5
    speeds, saturated, setpoint, thrust = command(constants, mixer, state, force,
                                                  reference[REFERENCE_YAW])
    return speeds, saturated, setpoint, thrust, reference
