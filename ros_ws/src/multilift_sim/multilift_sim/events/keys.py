"""The keys several event kinds share, read with their checks (`scenario.reading.Section`): the
UAV an event concerns and one of its rotors. Each error is one line naming the key."""
from __future__ import annotations

from typing import Any, Sequence


def read_uav(e: Any, uavs: Sequence[Any]) -> int:
    """`uav`: a UAV of the scenario, from 1 (1 = the leader)."""
    uav = e.raw('uav')
    if isinstance(uav, bool) or not isinstance(uav, int) or not 1 <= uav <= len(uavs):
        raise e.fail('uav', uav, f'must be a UAV from 1 to {len(uavs)}')
    return uav


def read_rotor(e: Any, uavs: Sequence[Any], uav: int) -> int:
    """`rotor`: a rotor of UAV `uav` (from 1), from 1 (docs/conventions.md's rotor order)."""
    rotors = uavs[uav - 1].vehicle.n_rotors
    rotor = e.raw('rotor')
    if isinstance(rotor, bool) or not isinstance(rotor, int) or not 1 <= rotor <= rotors:
        raise e.fail('rotor', rotor, f'must be a rotor of uav{uav}, from 1 to {rotors}')
    return rotor
