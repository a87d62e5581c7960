"""What the controllers measure of each UAV, from the formation state (seed Eq. 2.7)."""
import math

from multilift_sim.physics._jit import jit
from multilift_sim.physics.layout import (EULER, MEASURED_BODY_RATES, MEASURED_EULER,
                                          MEASURED_POSITION, MEASURED_VELOCITY,
                                          PAYLOAD_COORDINATES, POSITION, UAV_COORDINATES)


@jit
def measured_states(x, n, out):
    """Every UAV's measured state into out (n, MEASURED_COLUMNS) from the formation state x
    (2 (6n + 3),): position [m] and velocity [m/s] (world), ZYX Euler angles [rad] and the body
    rates omega = W(eta) eta_dot [rad/s] (Eq. 2.7, body FLU)."""
    nq = UAV_COORDINATES * n + PAYLOAD_COORDINATES
    for i in range(n):
        base = UAV_COORDINATES * i
        for axis in range(3):
            out[i, MEASURED_POSITION + axis] = x[base + POSITION + axis]
            out[i, MEASURED_VELOCITY + axis] = x[nq + base + POSITION + axis]
        phi, theta, psi = x[base + EULER], x[base + EULER + 1], x[base + EULER + 2]
        phi_dot = x[nq + base + EULER]
        theta_dot = x[nq + base + EULER + 1]
        psi_dot = x[nq + base + EULER + 2]
        out[i, MEASURED_EULER] = phi
        out[i, MEASURED_EULER + 1] = theta
        out[i, MEASURED_EULER + 2] = psi
        s_phi, c_phi = math.sin(phi), math.cos(phi)
        s_theta, c_theta = math.sin(theta), math.cos(theta)
        out[i, MEASURED_BODY_RATES] = phi_dot - s_theta * psi_dot
        out[i, MEASURED_BODY_RATES + 1] = c_phi * theta_dot + s_phi * c_theta * psi_dot
        out[i, MEASURED_BODY_RATES + 2] = -s_phi * theta_dot + c_phi * c_theta * psi_dot
