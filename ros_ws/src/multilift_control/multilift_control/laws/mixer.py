"""Body wrench -> rotor speeds with saturation (the inverse of seed Eq. 2.14, Eq. 2.15), and
the collective thrust of rotor speeds (Eq. 2.9)."""
import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import MIXER_COLLECTIVE, MIXER_WRENCH


@jit
def rotor_speeds(mixer, square_min, square_max, wrench):
    """(omega (n_rotors,) [rad/s], saturated (n_rotors,) bool) for wrench = (u_T [N], body
    torque (3) [N m]); mixer (n_rotors, MIXER_SIZE), square_min/max = omega_min^2, omega_max^2
    [rad^2/s^2].

    Attitude comes first: when a rotor would leave [omega_min, omega_max], the collective part
    is shifted (equal omega^2 on every rotor changes thrust only) to bring the request inside;
    what still does not fit is clipped. `saturated` flags the rotors held at a limit the
    allocator wanted them beyond: clipped, or the rotor that set the shift (at its limit
    after it); not a rotor whose request the shift brought inside (issue 37: a hexa after a
    rotor failure counted 88.85 s saturated with its fastest rotor at 1996 of 2100 rad/s).

    After a rotor fails (`RotorMixer` of an effectiveness, issue 21) its row is 0: it is held
    at omega_min and takes no part; a rotor that carries no collective share (the failed
    one's opposite in a hexa's reallocation) is clipped but cannot take part in the shift:
    it is pinned at omega_min by the reallocation, not saturated."""
    n_rotors = mixer.shape[0]
    request = np.empty(n_rotors)
    saturated = np.zeros(n_rotors, dtype=np.bool_)
    # np.argmax, np.argmin over the rotors with a collective share: the first of equals
    highest = lowest = -1
    for k in range(n_rotors):
        total = 0.0
        live = False
        for j in range(4):
            total += mixer[k, MIXER_WRENCH + j] * wrench[j]
            live = live or mixer[k, MIXER_WRENCH + j] != 0.0
        if not live:
            request[k] = square_min
            continue
        request[k] = total
        if mixer[k, MIXER_COLLECTIVE] <= 0.0:
            continue
        if highest < 0 or total > request[highest]:
            highest = k
        if lowest < 0 or total < request[lowest]:
            lowest = k
    high, low = request[highest], request[lowest]
    shift = 0.0
    if high > square_max or low < square_min:
        if high - low <= square_max - square_min:
            # shift along the collective direction until every rotor fits
            above = (high - square_max) / mixer[highest, MIXER_COLLECTIVE]
            below = (square_min - low) / mixer[lowest, MIXER_COLLECTIVE]
            shift = -above if above > 0 else (below if below > 0 else 0.0)
            for k in range(n_rotors):
                request[k] = request[k] + shift * mixer[k, MIXER_COLLECTIVE]
    # a rotor a downward shift left at omega_max (an upward one at omega_min) was wanted
    # beyond it: at the limit to rounding
    at_limit = 1e-12 * square_max
    for k in range(n_rotors):  # what does not fit (a no-op for a request within the range)
        value = request[k]
        if mixer[k, MIXER_COLLECTIVE] > 0.0:  # takes part (not failed, not pinned)
            saturated[k] = (value > square_max or value < square_min
                            or (shift < 0.0 and value > square_max - at_limit)
                            or (shift > 0.0 and value < square_min + at_limit))
        request[k] = min(max(value, square_min), square_max)
    return np.sqrt(request), saturated


@jit
def collective_thrust(thrust_coefficient, speeds):
    """u_T = k_T sum_k omega_k^2 [N] (seed Eq. 2.9) of rotor speeds [rad/s], k_T [N s^2/rad^2].
    Summed in order: numpy's sum of fewer than 8 terms (multirotor.collective_thrust) to the
    bit; an octo's may differ in the last bit (numpy sums 8 or more pairwise)."""
    total = 0.0
    for k in range(speeds.shape[0]):
        total += speeds[k] * speeds[k]
    return thrust_coefficient * total
