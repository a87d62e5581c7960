"""The controllers a scenario can pick, which its validation reads: one registry per kind,
`LEADER_CONTROLLERS` (`control.mode`: UAV 1's law) and `FOLLOWER_CONTROLLERS`
(`control.follower`: the law of UAVs 2..n), each name -> its part.

The parts are multilift_control's (their compiled laws: `multilift_control.controllers`,
docs/extending.md); they register here, and a process that reads a scenario before it
imported them finds them through `multilift_sim.parts.load` (the `multilift.parts` entry
points; a part of one's own: the scenario's `parts:`). What validation reads of a part:
`NAME`, `KEYS` (its own keys in the `control:` section) and, with keys, `parse(c) -> dict`
(c: the `control:` section, a `scenario.reading.Section`; the dict: `ControlConfig` fields, a
part's own numbers in `values`).
"""
from __future__ import annotations

from typing import Any

from multilift_sim import parts

LEADER_CONTROLLERS: dict[str, Any] = {}
FOLLOWER_CONTROLLERS: dict[str, Any] = {}
DEFAULT_FOLLOWER = 'virtual_constraints'  # the seed's (Ch. 3)


def leader_controllers() -> dict[str, Any]:
    """The leader controllers registered in this process (after `parts.load`)."""
    parts.load()
    return LEADER_CONTROLLERS


def follower_controllers() -> dict[str, Any]:
    """The follower controllers registered in this process (after `parts.load`)."""
    parts.load()
    return FOLLOWER_CONTROLLERS
