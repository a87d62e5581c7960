"""A rotor's effectiveness changed: its UAV's mixer allocates the wrench over what its rotors
can still give (`faults.fault_mixers`: `RotorMixer` of the effectiveness)."""
from __future__ import annotations

from multilift_sim.physics.layout import EVENT_ROTOR, EVENT_UAV, EVENT_VALUE

KIND = 'rotor_effectiveness'


def rotors(row, effectiveness) -> int:
    """The rotor's effectiveness set in the controllers' copy; its UAV (from 0)."""
    uav = int(row[EVENT_UAV])
    effectiveness[uav][int(row[EVENT_ROTOR])] = row[EVENT_VALUE]
    return uav
