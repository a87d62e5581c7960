"""`controller_silence`: for `duration` seconds no command of the UAV's controller reaches the
simulator, which holds the last one it got (`physics.events.held_commands`)."""
from __future__ import annotations

import math

from multilift_sim.events.keys import read_uav
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_END_TICK, EVENT_UAV, EVENT_VALUE

NAME = 'controller_silence'
KEYS = ('uav', 'duration')


def parse(e, uavs, earlier):
    """Its keys as EventConfig fields."""
    return dict(uav=read_uav(e, uavs), duration=e.positive('duration'))


def pack(event, row, rate):
    """Its slots: the duration [s] and the first tick whose command arrives again."""
    row[EVENT_VALUE] = event.duration
    row[EVENT_END_TICK] = math.ceil((event.time + event.duration) * rate - 1e-9)


@jit
def apply(row, tick, effectiveness, taut, released, silent_until, reel):
    """silent_until (n,) int: the first tick whose command arrives again, the later one."""
    uav = int(row[EVENT_UAV])
    silent_until[uav] = max(silent_until[uav], int(row[EVENT_END_TICK]))


def describe(row):
    """(uav (from 1), rotor 0, seconds, sentence)."""
    uav, value = int(row[EVENT_UAV]) + 1, float(row[EVENT_VALUE])
    return uav, 0, value, (f'uav{uav} controller silent for {value:g} s (the simulator holds '
                           'its last command)')
