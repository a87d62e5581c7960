"""The registered event kinds compiled into the one tick: their dispatcher
`apply_event(kind, row, tick, effectiveness, taut, released, silent_until)`, one branch per
kind calling its module's `apply`, generated from the registry (`multilift_sim.part_dispatch`:
the file under numba's cache folder, the cache folder of a registry with other kinds, the
loaded callers recompiled), which `physics.events.apply_events` calls by its global
`apply_event`.
"""
from __future__ import annotations

from typing import Callable

from multilift_sim import events as registry
from multilift_sim import part_dispatch

EVENTS = part_dispatch.add(part_dispatch.GeneratedDispatcher(
    label='events', function='apply_event', selector='kind',
    arguments='row, tick, effectiveness, taut, released, silent_until', step='apply',
    caller_module='multilift_sim.physics.events', caller='apply_events',
    parts=lambda: registry.EVENT_KINDS, shipped=lambda: registry.SHIPPED))


def dispatcher() -> Callable:
    """The registry's compiled `apply_event`."""
    return EVENTS.compiled()


def refresh() -> None:
    """After the registry changed (`events.register`): see `part_dispatch.refresh`."""
    part_dispatch.refresh(EVENTS)
