"""The seed's cables (`cable_model: rigid`, the default): massless two-way rods of length l_i,
the constraint g_i = |r_p - r_i|^2 - l_i^2 = 0 (Eq. 2.42) held by Lagrange multipliers with
Baumgarte stabilisation (Eq. 2.59-2.70) or the null-space form (Eq. 2.71-2.72)."""
from __future__ import annotations

from typing import Any

NAME = 'rigid'
NEEDS: frozenset[str] = frozenset()
RELEASE_LIMIT_DEG = 90.0
KEEPS_LENGTH = True
SLACKENS = False
REELS = True


def parse_cable(top: Any) -> None:
    """No `cable:` keys: a one-line error for a `cable:` section (`top` a reading.Section)."""
    if top.has('cable'):
        raise top.fail('cable', top.data['cable'], 'needs cable_model: elastic')


def parse_uav_cable(u: Any, length: float, base: None) -> tuple[float, float]:
    """(0, 0): no stiffness or damping of its own; an error for a `uavs[i].cable:`."""
    parse_cable(u)
    return 0.0, 0.0


def check(scenario: Any) -> None:
    """Carries every payload type on any attach points."""
    return None
