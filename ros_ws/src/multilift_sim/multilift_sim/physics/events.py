"""The scenario's events (`events:`, issue 21) applied to a formation's arrays at the control
tick they fall on, before that tick's state is checked and sent: the state at the tick shows
them (a released cable no longer taut) and the period from the tick on feels them. One
function, which the engine's tick and FormationSimulator both call. Rows: `physics.layout`
EVENT_*; what each kind does: its module of `multilift_sim.events` (the registry
EVENT_KINDS), reached through `apply_event`, the dispatcher generated from the registry
(`EVENTS`, `multilift_sim.part_dispatch`).
"""
import math

from multilift_sim import events as registry
from multilift_sim import part_dispatch
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_KIND, EVENT_TICK

EVENTS = part_dispatch.declare(
    'events', 'apply_event(kind, row, tick, effectiveness, taut, released, silent_until, reel)',
    step='apply', caller=f'{__name__}.apply_events', parts=lambda: registry.EVENT_KINDS)
apply_event = EVENTS.compiled()  # rebound when the registry changes (EVENTS.refresh)


@jit
def apply_events(events, next_event, tick, effectiveness, taut, released, silent_until, reel):
    """Apply every event of `events` (k, EVENT_COLUMNS) from row `next_event` on whose tick is
    at or before `tick`, each by its kind's `apply` (what it may change: the rotors'
    effectiveness (n, rotors), taut (n,) bool, released (n,) bool: the cables let go of for
    good, silent_until (n,) int: the first tick whose command arrives again, reel (n,
    REEL_COLUMNS): the winches' commands). Returns the row of the next event to come (k: none
    left)."""
    k = next_event
    while k < events.shape[0] and events[k, EVENT_TICK] <= tick:
        apply_event(int(events[k, EVENT_KIND]), events[k], tick, effectiveness, taut, released,
                    silent_until, reel)
        k += 1
    return k


@jit
def held_commands(speeds, saturated, tick, silent_until, held, held_saturated):
    """The commands the simulator applies over the period from `tick`, into held (n, rotors)
    [rad/s] and held_saturated (n, rotors) bool, which hold the last ones applied (NaN before
    any): a silent controller's (tick < silent_until (n,)) stay the last it got through, as an
    autopilot holds its last setpoint; every other UAV's are its answer `speeds`, `saturated`."""
    n, count = speeds.shape
    for i in range(n):
        if tick < silent_until[i] and not math.isnan(held[i, 0]):
            continue
        for r in range(count):
            held[i, r] = speeds[i, r]
            held_saturated[i, r] = saturated[i, r]
