"""The attitude-rate loop of the action mode `thrust_body_rates` (multilift_learning.batch):
body-rate set-points and a collective thrust per UAV -> rotor speeds, as a flight controller's
innermost loop under an offboard computer (PX4's rate controller, Betaflight's acro mode).

Per UAV, body frame FLU: torque = J k_w (omega_set - omega) + omega x J omega [N m], k_w the
scenario's attitude derivative gains (control.attitude_gains.kd [1/s]: the cascade's own rate
gain, `laws.cascade.attitude_torque`), J its principal inertia [kg m^2]; then the cascade's
mixer (`laws.mixer.rotor_speeds`: the allocation inverse). Thrust comes first here: the torque
is scaled down (`fitting_share`) until every rotor's request fits its speed range at the
commanded thrust, so the learner's thrust is what it gets. (The cascade's mixer puts attitude
first and lowers the collective instead: near the seed vehicles' thrust-to-weight of 1.13
any body-rate noise then costs thrust, and a policy exploring about hover fell to the ground
in 1.3 s of 0.1 noise on its actions.)
"""
import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.cascade import body_rates_and_gyro
from multilift_control.laws.layout import (CASCADE_ATT_KD, CASCADE_INERTIA, CASCADE_SQUARE_MAX,
                                           CASCADE_SQUARE_MIN, MIXER_WRENCH)
from multilift_control.laws.mixer import rotor_speeds


@jit
def rate_torque(constants, state, rates):
    """Body torque [N m] (3,) of one UAV driving its body rates (state's UAV_BODY_RATES) to
    `rates` (3,) [rad/s], FLU; constants: its CASCADE_* row."""
    now, gyro = body_rates_and_gyro(constants, state)   # omega, omega x J omega
    torque = np.empty(3)
    for axis in range(3):
        accel = constants[CASCADE_ATT_KD + axis] * (rates[axis] - now[axis])
        torque[axis] = constants[CASCADE_INERTIA + axis] * accel + gyro[axis]
    return torque


@jit
def fitting_share(mixer, square_min, square_max, thrust, torque):
    """The largest share s in [0, 1] of `torque` (3,) [N m] for which every rotor's request
    (mixer rows: omega^2 per unit of the wrench (thrust [N], torque)) at `thrust` [N] lies in
    [square_min, square_max] [rad^2/s^2] (0 where the thrust alone leaves it no room)."""
    share = 1.0
    for k in range(mixer.shape[0]):
        base = mixer[k, MIXER_WRENCH] * thrust
        turn = 0.0
        for j in range(3):
            turn += mixer[k, MIXER_WRENCH + 1 + j] * torque[j]
        if turn > 0.0:
            share = min(share, max(0.0, (square_max - base) / turn))
        elif turn < 0.0:
            share = min(share, max(0.0, (square_min - base) / turn))
    return share


@jit
def body_rate_commands(cascade, mixers, states, rates, thrust, speeds, saturated):
    """Every UAV's rotor speeds (B, n, rotors) [rad/s] and saturation flags holding body
    `rates` (B, n, 3) [rad/s] with collective `thrust` (B, n) [N], from the measured `states`
    (B, n, UAV_STATE_SIZE); cascade (B, n, CASCADE_SIZE) and mixers (B, n, rotors, MIXER_SIZE)
    the engine's arrays (`Engine.arrays.cascade`, `Engine.memory.mixers`)."""
    for b in range(states.shape[0]):
        for i in range(states.shape[1]):
            square_min = cascade[b, i, CASCADE_SQUARE_MIN]
            square_max = cascade[b, i, CASCADE_SQUARE_MAX]
            torque = rate_torque(cascade[b, i], states[b, i], rates[b, i])
            share = fitting_share(mixers[b, i], square_min, square_max, thrust[b, i], torque)
            wrench = np.array((thrust[b, i], share * torque[0], share * torque[1],
                               share * torque[2]))
            s, sat = rotor_speeds(mixers[b, i], square_min, square_max, wrench)
            speeds[b, i, :] = s
            saturated[b, i, :] = sat
