"""What a cable sensor at a UAV's attach point senses of its cable (issue 33 item 1;
docs/estimation.md): the cable's unit direction and its tension, beside the UAV's measured
state in the rows the sensor models read (physics.layout SENSED_*). Units: SI, world z up."""
import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import quaternion_rotation
from multilift_sim.physics.layout import (POSITION, SENSED_CABLE_DIRECTION, SENSED_CABLE_TENSION,
                                          UAV_ATTACH, UAV_PAYLOAD_ATTACH)
from multilift_sim.physics.state_slots import (attitude_slot, payload_slot, uav_attitude_slot,
                                               uav_slot)


@jit
def cable_truths(x, uavs, tension, out):
    """Every cable's unit direction d_i = (a_p,i - a_i) / |a_p,i - a_i| (world), from its attach
    point on UAV i a_i = r_i + R_i a_i,body to the payload's a_p,i (r_p for a point payload,
    r_p + R_p b_i for a rigid one), and its tension T_i [N] (tension (n,): the last tick's),
    into out (n, >= SENSED_COLUMNS) at SENSED_CABLE_DIRECTION and SENSED_CABLE_TENSION; the
    formation state x (a point or rigid payload, physics.layout), uavs (n, UAV_COLUMNS)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    rigid = x.shape[0] > attitude_slot(n)
    payload_rotation = quaternion_rotation(x, attitude_slot(n)) if rigid else np.eye(3)
    for i in range(n):
        rotation = quaternion_rotation(x, uav_attitude_slot(n, i))
        d = np.empty(3)
        for row in range(3):
            end = x[p + row]
            if rigid:
                for c in range(3):
                    end += payload_rotation[row, c] * uavs[i, UAV_PAYLOAD_ATTACH + c]
            start = x[uav_slot(i) + POSITION + row]
            for c in range(3):
                start += rotation[row, c] * uavs[i, UAV_ATTACH + c]
            d[row] = end - start
        length = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        for row in range(3):
            out[i, SENSED_CABLE_DIRECTION + row] = d[row] / length
        out[i, SENSED_CABLE_TENSION] = tension[i]


@jit
def gimbal_angles(dx, dy, dz):
    """The two angles [rad] a two-axis gimbal's encoders read of a cable of unit direction
    (dx, dy, dz) in the UAV's body frame FLU: the outer axis along body x (alpha), the inner
    along the outer's y (beta), zero with the cable hanging straight down the body's -z:
    d = Rx(alpha) Ry(beta) (0, 0, -1) = (-sin beta, sin alpha cos beta, -cos alpha cos beta)
    (`gimbal_direction`, the inverse)."""
    return math.atan2(dy, -dz), math.atan2(-dx, math.sqrt(dy * dy + dz * dz))


@jit
def gimbal_direction(alpha, beta):
    """The cable's unit direction (3 floats) in the body frame FLU of gimbal angles alpha,
    beta [rad] (`gimbal_angles`)."""
    return (-math.sin(beta), math.sin(alpha) * math.cos(beta),
            -math.cos(alpha) * math.cos(beta))


@jit
def gimbal_jacobian(alpha, beta, out):
    """d(direction)/d(alpha, beta) of `gimbal_direction` into out (3, 2), body frame."""
    sa, ca, sb, cb = math.sin(alpha), math.cos(alpha), math.sin(beta), math.cos(beta)
    out[0, 0], out[1, 0], out[2, 0] = 0.0, ca * cb, sa * cb
    out[0, 1], out[1, 1], out[2, 1] = -cb, -sa * sb, ca * sb
