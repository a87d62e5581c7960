"""The observation of a formation, slot by slot: names and scales (multilift_learning.batch
computes it). Per formation, flat (OBSERVATION_PER_UAV n + OBSERVATION_PAYLOAD,), float32,
world frame z up, SI units; for each UAV i (uav1 first):

- position error [m] (3, scale 1): its position less the payload's target plus its start
  offset from the payload's rest place (where it would be, the formation kept, with the
  payload on target);
- velocity less the target's [m/s] (3, scale 1);
- roll, pitch, yaw [rad] (scales 0.5, 0.5, pi);
- body rates, FLU [rad/s] (3, scale 1);
- cable direction, the unit vector from the payload to the UAV (3, scale 1);
- cable tension of the last tick over its static share m_p g / n (scale 1; 0 before the
  first tick);
then the payload's position error [m] (scale 1) and velocity error [m/s] (scale 1). The
scale is a slot's typical size near hover: `normalise=True` (multilift_learning.options)
divides every slot by it and clips to +-OBSERVATION_CLIP. A slot a failed physics state left
non-finite is reported as 0 (the episode terminates at that step).
"""
from __future__ import annotations

import math

import numpy as np

OBSERVATION_PER_UAV = 16
OBSERVATION_PAYLOAD = 6
OBSERVATION_CLIP = 10.0
# (name, scale) of a UAV's slots and of the payload's, in order
UAV_SLOTS = ([(f'position_error.{a}', 1.0) for a in 'xyz']
             + [(f'velocity_error.{a}', 1.0) for a in 'xyz']
             + [('roll', 0.5), ('pitch', 0.5), ('yaw', math.pi)]
             + [(f'body_rate.{a}', 1.0) for a in 'xyz']
             + [(f'cable_direction.{a}', 1.0) for a in 'xyz']
             + [('tension_ratio', 1.0)])
PAYLOAD_SLOTS = ([(f'position_error.{a}', 1.0) for a in 'xyz']
                 + [(f'velocity_error.{a}', 1.0) for a in 'xyz'])


def observation_names(n: int) -> list[str]:
    """The name of every observation slot of a formation of n UAVs."""
    names = [f'uav{i}.{name}' for i in range(1, n + 1) for name, _ in UAV_SLOTS]
    return names + [f'payload.{name}' for name, _ in PAYLOAD_SLOTS]


def agent_observation_slots(n: int) -> np.ndarray:
    """(n, OBSERVATION_PER_UAV + OBSERVATION_PAYLOAD) int: the slots of a formation's
    observation that agent k (UAV k + 1) sees, its own UAV's then the payload's (the
    PettingZoo env's agents, `multilift_learning.parallel_env`)."""
    payload = np.arange(OBSERVATION_PER_UAV * n, OBSERVATION_PER_UAV * n + OBSERVATION_PAYLOAD)
    return np.array([np.concatenate([np.arange(OBSERVATION_PER_UAV * k,
                                               OBSERVATION_PER_UAV * (k + 1)), payload])
                     for k in range(n)])


def observation_scales(n: int) -> np.ndarray:
    """Every slot's scale (its typical size near hover, in its unit), float32 (size,)."""
    scales = [scale for _ in range(n) for _, scale in UAV_SLOTS]
    return np.array(scales + [scale for _, scale in PAYLOAD_SLOTS], dtype=np.float32)


def finished_observation(raw: np.ndarray, scales: np.ndarray | None) -> np.ndarray:
    """float64 observations (B, size) -> float32, non-finite slots 0; divided by `scales` and
    clipped to +-OBSERVATION_CLIP when given (normalise)."""
    raw = np.where(np.isfinite(raw), raw, 0.0)
    if scales is not None:
        raw = np.clip(raw / scales, -OBSERVATION_CLIP, OBSERVATION_CLIP)
    return raw.astype(np.float32)
