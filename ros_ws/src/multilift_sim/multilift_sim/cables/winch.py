"""A UAV's winch (`uavs[i].winch`, issue 32 item 3): its cable's length becomes the state of a
reel driven by a commanded rate (events `type: winch`, or live `/uav{i}/winch_cmd`), within
the limits read here; its motion is `physics.winch`'s. docs/cables.md, "Winches".

Keys (SI): `rate_limit` [m/s] and `acceleration_limit` [m/s^2] (> 0), `min_length` and
`max_length` [m], the stops (0 < min_length <= the cable's length <= max_length).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

KEYS = ('rate_limit', 'acceleration_limit', 'min_length', 'max_length')


@dataclass(frozen=True)
class Winch:
    rate_limit: float            # the largest |l_dot| [m/s]
    acceleration_limit: float    # the largest |l_ddot| [m/s^2]
    min_length: float            # the shortest cable [m]
    max_length: float            # the longest cable [m]


def parse_winch(u: Any, length: float) -> Winch | None:
    """UAV u's `winch:` (`u` its reading.Section, `length` its cable's [m]), None without."""
    if not u.has('winch'):
        return None
    w = u.section('winch')
    winch = Winch(rate_limit=w.positive('rate_limit'),
                  acceleration_limit=w.positive('acceleration_limit'),
                  min_length=w.positive('min_length'), max_length=w.positive('max_length'))
    if winch.max_length < winch.min_length:
        raise w.fail('max_length', winch.max_length,
                     f'must be >= min_length ({winch.min_length:g} m)')
    if not winch.min_length <= length <= winch.max_length:
        raise w.fail('min_length', winch.min_length, f'and max_length ({winch.max_length:g}) '
                     f'must hold the cable\'s length {length:g} m between them')
    w.done()
    return winch


def check(scenario: Any) -> str | None:
    """What winches cannot reel, in one line (None: they fly): a cable model that declares
    REELS (the cable-model registry), no UAV prescribed (the formulations' FEATURES:
    Baumgarte's, `winch`)."""
    from multilift_sim.cables import CABLE_MODELS
    if not any(u.winch for u in scenario.uavs):
        return None
    if not CABLE_MODELS[scenario.cable_model].REELS:
        *some, last = [name for name, model in CABLE_MODELS.items() if model.REELS]
        reeled = f'{", ".join(some)} or {last}' if some else last
        return f'uavs[].winch reels {reeled} cables, not cable_model: {scenario.cable_model}'
    if scenario.prescribed:
        return 'uavs[].winch is not for a formation with prescribed UAVs (uavs[i].trajectory)'
    return None
