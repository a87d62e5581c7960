"""What the controllers do about an event, knowing it at once (perfect fault detection and
isolation; docs/events.md), registered by the event kind's name (`multilift_sim.events`):
`REACTIONS` (name -> module). A kind without a reaction has none: the controllers fly on as
before it. `multilift_control.faults` reads this registry and names no kind.

A reaction's module declares `KIND` (the event kind's name) and any of:
- `rotors(row, effectiveness) -> uav`: the controllers' copy of every UAV's rotor
  effectiveness (a list of (rotors,) arrays) after the event row (physics.layout EVENT_*),
  and the UAV (from 0) whose mixer then reallocates (`faults.fault_mixers`);
- `lets_go(row) -> uav`: the UAV (from 0) whose cable the event lets go of: the formation's
  offsets move (`faults.release_targets`).
"""
from __future__ import annotations

from types import ModuleType

from multilift_control.reactions import cable_release, rotor_effectiveness
from multilift_sim.events import kind_at
from multilift_sim.physics.layout import EVENT_KIND

REACTIONS: dict[str, ModuleType] = {
    reaction.KIND: reaction for reaction in (rotor_effectiveness, cable_release)}


def reaction_of(row) -> ModuleType | None:
    """The reaction to an event row's kind, or None."""
    return REACTIONS.get(kind_at(int(row[EVENT_KIND])).NAME)


def reallocates(row) -> bool:
    """Whether the row's event reallocates a UAV's mixer (its reaction has `rotors`)."""
    return hasattr(reaction_of(row), 'rotors')


def lets_go(row) -> int:
    """The UAV (from 0) whose cable the row's event lets go of, or -1."""
    reaction = reaction_of(row)
    return reaction.lets_go(row) if hasattr(reaction, 'lets_go') else -1
