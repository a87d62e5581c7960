"""What a UAV's controllers receive of its state when the scenario has `sensors:` (issue 21
item 2): a measurement, not the state. One function, which the engine's tick and
`FormationSimulator.snapshot` both call (docs/sensors.md).

Each UAV's sensors sample its exact measured state (physics.measurement, seed Eq. 2.7) every
`every` control ticks; sample s (taken at tick s * every) carries an error (white noise plus a
bias random walk, drawn before the run: `multilift_sim.sensors.sensor_errors`), arrives
`latency` ticks after it was taken, or is lost (a dropout). Between arrivals the controllers
hold the last measurement that arrived (a zero-order hold). The first sample (tick 0) always
arrives, at once: the autopilot's estimate is initialised before the run starts.
"""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import MEASURED_COLUMNS


@jit
def sensed_states(states, tick, errors, delivered, every, latency, history, seen):
    """Replace the MEASURED_* slots of every UAV's exact measured state `states` (n, >=
    MEASURED_COLUMNS) at control tick `tick` by what its controllers receive there.

    errors (S, n, MEASURED_COLUMNS): sample s's error [the slots' units]; delivered (S, n)
    bool: whether sample s arrives; every: ticks between samples; latency: ticks from a
    sample to its arrival; history (slots > latency, n, MEASURED_COLUMNS): the exact states of
    the last `slots` ticks, by tick % slots (written here); seen (n, MEASURED_COLUMNS): the
    measurement each UAV's controllers hold (NaN before the first; updated here). A second
    call at the same tick gives the same result (it reads no state of its own making but
    `seen`, which it sets to the same value)."""
    n = states.shape[0]
    slots = history.shape[0]
    row = tick % slots
    for i in range(n):
        for c in range(MEASURED_COLUMNS):
            history[row, i, c] = states[i, c]
    taken = max(tick - latency, 0)  # the tick whose sample arrives now (before: tick 0's)
    sample = taken // every
    fresh = taken % every == 0 and sample < errors.shape[0]
    for i in range(n):
        if fresh and (delivered[sample, i] or math.isnan(seen[i, 0])):
            for c in range(MEASURED_COLUMNS):
                seen[i, c] = history[taken % slots, i, c] + errors[sample, i, c]
        for c in range(MEASURED_COLUMNS):
            states[i, c] = seen[i, c]
