"""Swing damping (`control.payload_feedback`, issue 20 item 5; not in the seed, which names a
payload-based controller that reduces the pendulum oscillations as what comes next, §5.2).

The payload hangs from the formation as a pendulum of length l: its horizontal offset s from
its rest place under the UAVs obeys, for small swings and a formation that moves as one with
acceleration a_c, s_ddot = -(g / l) s - a_c (cf. the reduced model of seed §2.8.2). The leader
adds

    a_s = k_s (v_p - v_f)_xy,      v_f = (1/n) sum_i v_i       (the formation's velocity),

to its reference's acceleration; the followers keep their virtual constraints (Eq. 3.8-3.12)
and so accelerate with it, and s_dot = (v_p - v_f)_xy gives s_ddot + k_s s_dot + (g / l) s = 0:
the suspension point chases the swing, as a crane's trolley does, and the swing loses the
energy k_s |s_dot|^2 per unit mass. The leader's position loop pulls it back to its reference
meanwhile (the two share the corner's transient); k_s 2 sqrt(g / l) would be critical damping
of the pendulum alone. The payload's velocity is what the simulator's snapshot carries (its
state, not a sensor's). Vertical: nothing (the cables hold the payload's height).

World frame z up, SI units; states (n, UAV_STATE_SIZE) as the laws' layout names them.
"""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (CASCADE_SWING_DAMPING, CASCADE_SWING_LIMIT,
                                           CASCADE_SWING_REST, CASCADE_SWING_STIFFNESS, UAV_POSITION,
                                           UAV_VELOCITY)


@jit
def swing_feedback(constants, states, payload_position, payload_velocity):
    """a_s = k_s (s - s_0) + k_d s_dot [m/s^2] (3,), z 0, the swing s = (r_p - r_f)_xy of the
    payload from the UAVs' mean position r_f, s_dot = (v_p - v_f)_xy: constants CASCADE_SWING_*
    (k_s [1/s^2], k_d [1/s], s_0 [m] the swing at the formation's hanging rest), states (n,
    UAV_STATE_SIZE) of every UAV, payload_position r_p [m] and payload_velocity v_p [m/s] (3,),
    world."""
    n = states.shape[0]
    out = np.zeros(3)
    for axis in range(2):
        position = 0.0
        velocity = 0.0
        for i in range(n):
            position += states[i, UAV_POSITION + axis]
            velocity += states[i, UAV_VELOCITY + axis]
        swing = payload_position[axis] - position / n - constants[CASCADE_SWING_REST + axis]
        rate = payload_velocity[axis] - velocity / n
        out[axis] = (constants[CASCADE_SWING_STIFFNESS] * swing
                     + constants[CASCADE_SWING_DAMPING] * rate)
    size = math.sqrt(out[0] * out[0] + out[1] * out[1])
    if size > constants[CASCADE_SWING_LIMIT]:  # its direction kept
        out[0] *= constants[CASCADE_SWING_LIMIT] / size
        out[1] *= constants[CASCADE_SWING_LIMIT] / size
    return out

