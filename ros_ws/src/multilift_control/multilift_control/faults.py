"""What the controllers do about the scenario's faults (`events:`, docs/events.md), knowing
each at once (perfect fault detection and isolation): a UAV whose rotor loses effectiveness
allocates its wrench over what its rotors can still give (`RotorMixer` of the effectiveness,
the failed rotor's row left out) from the tick the fault falls on.

`fault_mixers` computes, once per run, the mixer rows each rotor_effectiveness event leaves
its UAV with; the engine's tick copies them in at the event's tick (`engine.tick`), and a
controller's runtime does the same (`FaultReallocation`), so both paths answer alike.
"""
from __future__ import annotations

import numpy as np

from multilift_control.cascade import RotorMixer
from multilift_control.laws.layout import MIXER_SIZE
from multilift_sim.physics.layout import (EVENT_KIND, EVENT_ROTOR, EVENT_TICK, EVENT_UAV,
                                          EVENT_VALUE, KIND_ROTOR_EFFECTIVENESS)
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import event_array


def fault_mixers(scenario: Scenario) -> np.ndarray:
    """(k, rotors, MIXER_SIZE): for each event row (`simulation.event_array`) of kind
    rotor_effectiveness the mixer rows of its UAV after it (every earlier fault of that UAV
    kept); zeros for the other kinds (unused). `rotors`: the most any UAV has."""
    rows = event_array(scenario)
    rotors = max(u.vehicle.n_rotors for u in scenario.uavs)
    effectiveness = [np.ones(u.vehicle.n_rotors) for u in scenario.uavs]
    out = np.zeros((len(rows), rotors, MIXER_SIZE))
    for k, row in enumerate(rows):
        if int(row[EVENT_KIND]) != KIND_ROTOR_EFFECTIVENESS:
            continue
        uav = int(row[EVENT_UAV])
        effectiveness[uav][int(row[EVENT_ROTOR])] = row[EVENT_VALUE]
        mixer = RotorMixer(scenario.uavs[uav].vehicle, effectiveness[uav]).rows
        out[k, :mixer.shape[0]] = mixer
    return out


class FaultReallocation:
    """UAV `index`'s controller side of the faults: `at(tick, mixer)` writes the mixer rows of
    every rotor_effectiveness event of this UAV up to `tick` into `mixer` (a RotorMixer)."""

    def __init__(self, scenario: Scenario, index: int):
        rows = event_array(scenario)
        mixers = fault_mixers(scenario)
        own = [k for k, row in enumerate(rows) if int(row[EVENT_UAV]) == index
               and int(row[EVENT_KIND]) == KIND_ROTOR_EFFECTIVENESS]
        self._pending = [(int(rows[k, EVENT_TICK]), mixers[k]) for k in own]

    def at(self, tick: int, mixer: RotorMixer) -> None:
        while self._pending and self._pending[0][0] <= tick:
            _, rows = self._pending.pop(0)
            mixer.rows[:] = rows[:mixer.rows.shape[0]]
