"""Actions of a formation (`multilift_learning.batch`), per formation flat and in [-1, 1], UAV by
UAV (uav1 first), action 0 = hover: every rotor at the speed that carries its UAV's weight and
its share of the payload's (omega_hover), held over one control period. Two modes
(multilift_learning.options.ACTION_MODES):

- `rotor_speeds`, (n * rotors,): each rotor's speed, piecewise linear about hover:
  omega = omega_hover + a (omega_max - omega_hover) for a >= 0, omega_hover + a (omega_hover -
  omega_min) below, each vehicle's rotor_speed_min and rotor_speed_max [rad/s].
- `thrust_body_rates`, (n * 4,): per UAV (thrust, roll rate, pitch rate, yaw rate): the
  collective thrust T = max(T_hover + a (T_max - T_hover), 0) [N] (T_hover = the weight
  share, T_max = k_T rotors omega_max^2: symmetric about hover, so zero-mean exploration
  keeps the mean thrust; the twin-lift's 28.4 +- 3.9 N), body rates a body_rate_limit
  [rad/s] (FLU), held by the attitude-rate loop inside (compiled, `laws.body_rates`).

The rotor_speeds mode keeps every speed a vehicle can fly (the baseline's answers round-trip
to the bit), so it is asymmetric about hover (the twin-lift's omega_hover = 1970 rad/s of
0..2100): zero-mean noise on its actions lowers the mean thrust.
"""
from __future__ import annotations

import numpy as np


def centred(a: np.ndarray, centre: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Actions a in [-1, 1] (clipped) -> values, a = 0 at `centre`, -1 at `low`, 1 at `high`
    (broadcast), piecewise linear."""
    a = np.clip(a, -1.0, 1.0)
    return centre + np.where(a >= 0.0, a * (high - centre), a * (centre - low))


def uncentred(value: np.ndarray, centre: np.ndarray, low: np.ndarray,
              high: np.ndarray) -> np.ndarray:
    """`centred`'s inverse: values -> actions."""
    return np.where(value >= centre, (value - centre) / (high - centre),
                    (value - centre) / (centre - low))
