"""`payload.type: point` (the default): the seed's point mass on cables from the UAVs' centres
of mass (Eq. 2.38-2.46)."""
from __future__ import annotations

from typing import Any

NAME = 'point'
NEEDS: frozenset[str] = frozenset()
MIN_UAVS = 1


def parse(p: Any, payload: Any, n: int) -> Any:
    """No keys of its own: `payload` as read."""
    return payload
