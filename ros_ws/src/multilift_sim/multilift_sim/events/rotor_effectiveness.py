"""`rotor_effectiveness`: from its tick on a rotor gives `effectiveness` (in [0, 1]) of its
thrust and drag moment (seed Eq. 2.14 becomes u = A diag(e) omega^2; 0: a failed rotor)."""
from __future__ import annotations

from multilift_sim.events.keys import read_rotor, read_uav
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_ROTOR, EVENT_UAV, EVENT_VALUE

NAME = 'rotor_effectiveness'
KEYS = ('uav', 'rotor', 'effectiveness')


def parse(e, uavs, earlier):
    """Its keys (`e`: the event's `scenario.reading.Section`) as EventConfig fields."""
    uav = read_uav(e, uavs)
    return dict(uav=uav, rotor=read_rotor(e, uavs, uav), effectiveness=e.number(
        'effectiveness', ..., lambda v: 0 <= v <= 1, 'must be within [0, 1]'))


def pack(event, row, rate):
    """Its slots of an event row (physics.layout EVENT_*): the new effectiveness."""
    row[EVENT_VALUE] = event.effectiveness


@jit
def apply(row, tick, effectiveness, taut, released, silent_until, reel):
    """The rotor's effectiveness (n, rotors) set."""
    effectiveness[int(row[EVENT_UAV]), int(row[EVENT_ROTOR])] = row[EVENT_VALUE]


def describe(row):
    """(uav (from 1), rotor (from 1), value, sentence) of /formation/events and the summary."""
    uav, rotor, value = int(row[EVENT_UAV]) + 1, int(row[EVENT_ROTOR]) + 1, float(row[EVENT_VALUE])
    return uav, rotor, value, f'uav{uav} rotor {rotor} at {100.0 * value:g} % of its thrust'
