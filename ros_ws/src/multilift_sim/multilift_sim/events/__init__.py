"""Event kinds as registered parts (issue 31): one module per kind, `EVENT_KINDS` the registry
(name -> module) that the scenario's validation, `schedules`, the physics' tick
(`physics.events`, through the dispatcher generated from it), the messages and the summary
read; nothing else names a kind. docs/extending.md, "An event kind", adds one.

A kind's module declares:
- `NAME`, the scenario's `type:`, and `KEYS`, its keys besides `time` and `type`;
- `parse(e, uavs, earlier) -> dict`: its keys read from `e` (the event's
  `scenario.reading.Section`, one-line errors naming the key) as `scenario.EventConfig` fields
  (`uav` from 1, 0: none; `rotor` from 1, 0: none; a kind's own numbers in `values`);
  `earlier`: the events read before it;
- `pack(event, row, rate)`: its slots of the event's row (physics.layout EVENT_*) beyond the
  common ones (tick, time, kind, uav, rotor), `rate` the control rate [Hz];
- `apply(row, tick, effectiveness, taut, released, silent_until, reel)`: compiled
  (`kernels.jit`), what it changes in the physics' memory at its tick (one formation's
  arrays: the rotors' effectiveness (n, rotors), taut (n,) bool, released (n,) bool,
  silent_until (n,) int, reel (n, REEL_COLUMNS): each winch's length, rate and command);
- `describe(row) -> (uav, rotor, value, sentence)`: what /formation/events and the summary say;
- optionally `unsteady_wind(event, starts, period) -> (K, 3)`: air it blows [m/s], world, over
  each control period (`schedules.wind_series`), and `RELEASES_CABLE = True` when it lets a
  cable go (plots draw the cable detached from then on).

A kind's index in the registry is the row's EVENT_KIND. `register` adds one (a test's toy
kind, at test time: `registered`); the compiled dispatcher follows (`physics.events.EVENTS`).
"""
from __future__ import annotations

from types import ModuleType

from multilift_sim.events import (cable_release, controller_silence, gust, rotor_effectiveness,
                                  winch_rate)
from multilift_sim.registry import Registry


def _changed() -> None:
    from multilift_sim.physics import events  # numba's side, loaded only when kinds change
    events.EVENTS.refresh()


EVENT_KINDS = Registry('event kind', ('NAME', 'KEYS', 'parse', 'pack', 'apply', 'describe'),
                       (rotor_effectiveness, cable_release, controller_silence, gust, winch_rate),
                       changed=_changed)
register, unregister, registered = (EVENT_KINDS.register, EVENT_KINDS.unregister,
                                    EVENT_KINDS.registered)


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
