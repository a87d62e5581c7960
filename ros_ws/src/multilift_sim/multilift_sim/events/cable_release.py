"""`cable_release`: the UAV's cable lets go of the payload for good: its multiplier is 0, it
never snaps taut again (also under `cable_model: slack`), the DAE goes on with the others."""
from __future__ import annotations

from multilift_sim.events.keys import read_uav
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_UAV, EVENT_VALUE

NAME = 'cable_release'
KEYS = ('uav',)
RELEASES_CABLE = True  # plots draw its cable detached from its tick on


def parse(e, uavs, earlier):
    """Its keys as EventConfig fields; a second release of one cable, or the release of the
    last one holding the payload, is an error (`earlier`: the events read before it)."""
    uav = read_uav(e, uavs)
    released = {event.uav for event in earlier if event.type == NAME}
    if uav in released:
        raise e.fail('uav', uav, 'has let go of its cable already')
    if len(released) + 1 == len(uavs):
        raise e.fail('uav', uav, 'is the last cable holding the payload')
    return dict(uav=uav)


def pack(event, row, rate):
    """Its slots: the value 1 (the whole cable lets go; unused, the rows as issue 21 wrote
    them)."""
    row[EVENT_VALUE] = 1.0


@jit
def apply(row, tick, effectiveness, taut, released, silent_until, reel):
    """The cable released ((n,) bool) and no longer taut: it no longer constrains."""
    uav = int(row[EVENT_UAV])
    released[uav] = True
    taut[uav] = False


def describe(row):
    """(uav (from 1), rotor 0, value 0, sentence)."""
    uav = int(row[EVENT_UAV]) + 1
    return uav, 0, 0.0, f'uav{uav} releases its cable'
