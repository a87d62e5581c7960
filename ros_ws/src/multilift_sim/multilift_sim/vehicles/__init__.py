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

import contextlib
from typing import Any, Iterator

from multilift_sim.vehicles import planar

REQUIRED = ('NAME', 'SPINS', 'rotor_positions')
VEHICLE_FRAMES: dict[str, Any] = {frame.NAME: frame for frame in planar.FRAMES}
SHIPPED = tuple(VEHICLE_FRAMES)


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


def register(new: Any) -> None:
    """Add a vehicle frame (an object with REQUIRED's names)."""
    missing = [name for name in REQUIRED if not hasattr(new, name)]
    if missing:
        raise ValueError(f'vehicle frame {new!r} lacks {", ".join(missing)}')
    if new.NAME in VEHICLE_FRAMES:
        raise ValueError(f'vehicle frame {new.NAME!r} is registered already')
    if len(new.SPINS) < 4 or any(s not in (1, -1) for s in new.SPINS):
        raise ValueError(f'vehicle frame {new.NAME!r}: SPINS {new.SPINS!r} must be at least '
                         f'4 entries of +1 or -1')
    VEHICLE_FRAMES[new.NAME] = new


def unregister(name: str) -> None:
    """Remove frame `name` (one `register` added)."""
    if name in SHIPPED:
        raise ValueError(f'vehicle frame {name!r} ships with multilift_sim')
    del VEHICLE_FRAMES[name]


@contextlib.contextmanager
def registered(new: Any) -> Iterator[Any]:
    """`new` registered for the block (a test's toy frame)."""
    register(new)
    try:
        yield new
    finally:
        unregister(new.NAME)
