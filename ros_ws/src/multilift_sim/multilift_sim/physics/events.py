"""The scenario's events (`events:`, issue 21) applied to a formation's arrays at the control
tick they fall on, before that tick's state is checked and sent: the state at the tick shows
them (a released cable no longer taut) and the period from the tick on feels them. One
function, which the engine's tick and FormationSimulator both call. Rows and kinds:
`physics.layout` EVENT_*.
"""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import (EVENT_END_TICK, EVENT_KIND, EVENT_ROTOR, EVENT_TICK,
                                          EVENT_UAV, EVENT_VALUE, KIND_CABLE_RELEASE,
                                          KIND_CONTROLLER_SILENCE, KIND_ROTOR_EFFECTIVENESS)


@jit
def apply_events(events, next_event, tick, effectiveness, taut, released, silent_until):
    """Apply every event of `events` (k, EVENT_COLUMNS) from row `next_event` on whose tick is
    at or before `tick`: a rotor's effectiveness (n, rotors) set; a cable released (released
    (n,) bool set, its taut flag cleared: it no longer constrains, and a slack model never
    snaps it taut again); a controller silenced (silent_until (n,) int: the first tick whose
    command arrives again). Returns the row of the next event to come (k: none left)."""
    k = next_event
    while k < events.shape[0] and events[k, EVENT_TICK] <= tick:
        kind = int(events[k, EVENT_KIND])
        uav = int(events[k, EVENT_UAV])
        if kind == KIND_ROTOR_EFFECTIVENESS:
            effectiveness[uav, int(events[k, EVENT_ROTOR])] = events[k, EVENT_VALUE]
        elif kind == KIND_CABLE_RELEASE:
            released[uav] = True
            taut[uav] = False
        elif kind == KIND_CONTROLLER_SILENCE:
            silent_until[uav] = max(silent_until[uav], int(events[k, EVENT_END_TICK]))
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
