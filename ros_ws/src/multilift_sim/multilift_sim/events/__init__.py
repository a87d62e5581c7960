"""Event kinds as registered parts (issue 31): one module per kind, `EVENT_KINDS` the registry
(name -> module) that the scenario's validation, `schedules`, the physics' tick
(`physics.events`, through `compiled`), the messages and the summary read; nothing else names
a kind. docs/extending.md, "An event kind", adds one.

A kind's module declares:
- `NAME`, the scenario's `type:`, and `KEYS`, its keys besides `time` and `type`;
- `parse(e, uavs, earlier) -> dict`: its keys read from `e` (the event's
  `scenario.reading.Section`, one-line errors naming the key) as `scenario.EventConfig` fields
  (`uav` from 1, 0: none; `rotor` from 1, 0: none; a kind's own numbers in `values`);
  `earlier`: the events read before it;
- `pack(event, row, rate)`: its slots of the event's row (physics.layout EVENT_*) beyond the
  common ones (tick, time, kind, uav, rotor), `rate` the control rate [Hz];
- `apply(row, tick, effectiveness, taut, released, silent_until)`: compiled (`kernels.jit`),
  what it changes in the physics' memory at its tick (one formation's arrays: the rotors'
  effectiveness (n, rotors), taut (n,) bool, released (n,) bool, silent_until (n,) int);
- `describe(row) -> (uav, rotor, value, sentence)`: what /formation/events and the summary say;
- optionally `unsteady_wind(event, starts, period) -> (K, 3)`: air it blows [m/s], world, over
  each control period (`schedules.wind_series`), and `RELEASES_CABLE = True` when it lets a
  cable go (plots draw the cable detached from then on).

A kind's index in the registry is the row's EVENT_KIND. `register` adds one (a test's toy
kind, at test time: `registered`); the compiled dispatcher follows (`compiled.refresh`).
"""
from __future__ import annotations

import contextlib
from types import ModuleType
from typing import Iterator

from multilift_sim.events import cable_release, controller_silence, gust, rotor_effectiveness

SHIPPED: tuple[ModuleType, ...] = (rotor_effectiveness, cable_release, controller_silence, gust)
EVENT_KINDS: dict[str, ModuleType] = {kind.NAME: kind for kind in SHIPPED}
REQUIRED = ('NAME', 'KEYS', 'parse', 'pack', 'apply', 'describe')


def kind_index(name: str) -> int:
    """The registry's index of kind `name`: its rows' EVENT_KIND."""
    return list(EVENT_KINDS).index(name)


def kind_at(index: int) -> ModuleType:
    """The kind of a row's EVENT_KIND."""
    return list(EVENT_KINDS.values())[index]


def moves_air(name: str) -> bool:
    """Whether kind `name` blows air through the run's wind series."""
    return getattr(EVENT_KINDS[name], 'unsteady_wind', None) is not None


def releases_cable(name: str) -> bool:
    """Whether kind `name` lets a cable go (`RELEASES_CABLE`: plots draw it detached)."""
    return getattr(EVENT_KINDS.get(name), 'RELEASES_CABLE', False)


def register(kind: ModuleType) -> None:
    """Add an event kind (a module, or any object, with REQUIRED's names) after the others."""
    missing = [name for name in REQUIRED if not hasattr(kind, name)]
    if missing:
        raise ValueError(f'event kind {kind!r} lacks {", ".join(missing)}')
    if kind.NAME in EVENT_KINDS:
        raise ValueError(f'event kind {kind.NAME!r} is registered already')
    EVENT_KINDS[kind.NAME] = kind
    _changed()


def unregister(name: str) -> None:
    """Remove kind `name` (one `register` added)."""
    if any(kind.NAME == name for kind in SHIPPED):
        raise ValueError(f'event kind {name!r} ships with multilift_sim')
    del EVENT_KINDS[name]
    _changed()


@contextlib.contextmanager
def registered(kind: ModuleType) -> Iterator[ModuleType]:
    """`kind` registered for the block (a test's toy kind)."""
    register(kind)
    try:
        yield kind
    finally:
        unregister(kind.NAME)


def _changed() -> None:
    from multilift_sim.events import compiled  # numba's side, loaded only when kinds change
    compiled.refresh()
