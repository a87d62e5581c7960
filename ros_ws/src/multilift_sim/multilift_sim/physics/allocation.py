"""Rotor speeds -> body wrenches (seed Eq. 2.14), for the formation's UAVs at once."""
from multilift_sim.kernels import jit


@jit
def rotor_wrenches(allocation, speeds, effectiveness, out):
    """u_i = A_i diag(e_i) omega_i^2 into out (n, WRENCH_COLUMNS): collective thrust [N] and
    body torques [N m] (FLU) of rotor speeds (n, rotors) [rad/s] under the allocation matrices
    (n, 4, rotors) [N s^2/rad^2, N m s^2/rad^2] (multilift_sim.allocation), each rotor's
    thrust and drag moment scaled by its effectiveness e (n, rotors) in [0, 1] (1: the seed's
    rotor; a failed rotor 0: physics.actuators)."""
    n, rows, rotors = allocation.shape
    for i in range(n):
        for k in range(rows):
            total = 0.0
            for r in range(rotors):
                total += allocation[i, k, r] * (speeds[i, r] * speeds[i, r] * effectiveness[i, r])
            out[i, k] = total
