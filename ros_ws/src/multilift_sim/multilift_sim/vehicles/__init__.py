"""Vehicle frames as registered parts (issue 31): `VEHICLE_FRAMES` (the scenario's
`vehicle.frame_type` -> its frame) is the one registry that validation, the allocation
(`multilift_sim.allocation`, seed Eq. 2.11-2.14) and the controllers' mixers read; nothing else
names a frame. docs/extending.md, "A vehicle frame", adds one.

A frame (a module, or any object, with these names) declares:
- `NAME`: the scenario's `frame_type`;
- `SPINS`: each rotor's spin, +1 clockwise seen from above (its drag moment on the body is
  +k_D omega^2 about body +z), -1 counter-clockwise; its length is the rotor count;
- `rotor_positions(arm_length) -> (n_r, 3)`: the rotor hubs [m], body FLU, from the arm
  length l_r [m] (rotor k at row k - 1).
"""
from __future__ import annotations

from typing import Any

from multilift_sim.registry import Registry
from multilift_sim.vehicles import planar


def _check_spins(frame: Any) -> None:
    if len(frame.SPINS) < 4 or any(s not in (1, -1) for s in frame.SPINS):
        raise ValueError(f'vehicle frame {frame.NAME!r}: SPINS {frame.SPINS!r} must be at least '
                         f'4 entries of +1 or -1')


VEHICLE_FRAMES = Registry('vehicle frame', ('NAME', 'SPINS', 'rotor_positions'), planar.FRAMES,
                          check=_check_spins)
SHIPPED = tuple(VEHICLE_FRAMES)
register, unregister, registered = (VEHICLE_FRAMES.register, VEHICLE_FRAMES.unregister,
                                    VEHICLE_FRAMES.registered)


def frame_types() -> tuple[str, ...]:
    """The registered frames' names, in registry order (validation's choices)."""
    return tuple(VEHICLE_FRAMES)


def frame(name: str) -> Any:
    """The frame registered as `name` (ValueError naming the registered ones)."""
    try:
        return VEHICLE_FRAMES[name]
    except KeyError:
        raise ValueError(f'unknown frame_type {name!r}; valid frame types are '
                         f'{", ".join(VEHICLE_FRAMES)}') from None
