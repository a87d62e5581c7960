"""`winch_rate`: from its tick on the UAV's winch (`uavs[i].winch`) is commanded to reel at `rate`
[m/s] (positive pays out, negative hauls in; 0 stops it), within the winch's rate and
acceleration limits and its stops (physics.winch)."""
from __future__ import annotations

from multilift_sim.events.keys import read_uav
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_UAV, EVENT_VALUE, REEL_COMMAND

NAME = 'winch_rate'
KEYS = ('uav', 'rate')


def parse(e, uavs, earlier):
    """Its keys as EventConfig fields; a UAV without a winch is an error."""
    uav = read_uav(e, uavs)
    if uavs[uav - 1].winch is None:
        raise e.fail('uav', uav, f'has no winch (uavs[{uav - 1}].winch)')
    return dict(uav=uav, values=(('rate', e.number('rate')),))


def pack(event, row, rate):
    """Its slots: the commanded reel rate [m/s]."""
    row[EVENT_VALUE] = event.value('rate')


@jit
def apply(row, tick, effectiveness, taut, released, silent_until, reel):
    """The UAV's commanded reel rate (reel (n, REEL_COLUMNS)) set."""
    reel[int(row[EVENT_UAV]), REEL_COMMAND] = row[EVENT_VALUE]


def describe(row):
    """(uav (from 1), rotor 0, rate [m/s], sentence)."""
    uav, value = int(row[EVENT_UAV]) + 1, float(row[EVENT_VALUE])
    what = 'stops' if value == 0.0 else f'pays out at {value:g} m/s' if value > 0.0 \
        else f'hauls in at {-value:g} m/s'
    return uav, 0, value, f'uav{uav} winch {what}'
