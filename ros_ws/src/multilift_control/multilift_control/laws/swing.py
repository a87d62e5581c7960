"""The leader's swing feedback (`control.payload_feedback`, issue 20 item 5; not in the seed,
which names a payload-based controller that reduces the pendulum oscillations as what comes
next, §5.2). Its other half, the mission's corners shaped at the payload's pendulum period, is
the reference's (`multilift_control.mission.MissionPath`, multilift_sim.scenario.INPUT_SHAPERS):
the shaping leaves no swing after a corner, this feedback damps what else swings the payload
(a release, a gust, a turn the shaper did not foresee).

The payload hangs from the formation as a pendulum: for small swings its horizontal offset s
from its rest place under the UAVs obeys s_ddot = -(g / h) s - a_c (h its depth below them, a_c
the formation's acceleration; cf. the reduced model of seed §2.8.2). The leader adds

    a_s = k_s (s - s_0) + k_d s_dot,   s = (r_p - r_f)_xy,  s_dot = (v_p - v_f)_xy,

r_f, v_f the UAVs' mean position and velocity and s_0 the value of s at the hanging rest, its
size limited to a_max with its direction kept, to the position loop's acceleration
(`cascade.leader_update`); the followers keep their virtual constraints (Eq. 3.8-3.12) and so
move with it. Against the leader's position loop (a PID whose bandwidth is near the pendulum's
on the twin-lift) the damping comes from the two together, not from k_d alone: the gains the
study flies (k_s > 0, k_d < 0, multilift_tools.swing_study) were found by sweeping flights;
the textbook law, k_d > 0 alone, swings the twin-lift's payload more than the seed's law
(docs/reproduction.md, the study's rows). The payload's state is
what the simulator's snapshot carries (its state, not a sensor's). Vertical: nothing.

World frame z up, SI units; states (n, UAV_STATE_SIZE) as the laws' layout names them.
"""
import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import (CASCADE_SWING_DAMPING, CASCADE_SWING_LIMIT,
                                           CASCADE_SWING_REST, CASCADE_SWING_STIFFNESS,
                                           UAV_POSITION, UAV_VELOCITY)


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
