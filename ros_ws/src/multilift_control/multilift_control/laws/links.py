"""The formation as a follower hears it over its link from the leader (`comms:`, issue 33 item
5; `multilift_sim.links.radio`): the measured states with the leader's row, and the thrusts
with the leader's, replaced by the last packet the follower received. Both runtimes call it
(the engine's tick and `runtime.ControllerRuntime`), then `follower.lift_vectors` of what it
heard."""
from multilift_control.laws import jit
from multilift_control.laws.layout import UAV_POSITION
from multilift_sim.links.radio import receive


@jit
def heard_formation(link, delivered, memory, tick, index, states, thrusts, heard, heard_thrusts):
    """Follower `index`'s link (constants `link`, its `delivered` (ticks + 1,) and `memory`)
    at control tick `tick`: every UAV's measured `states` (n, UAV_STATE_SIZE) and collective
    `thrusts` (n,) [N] into heard and heard_thrusts, the leader's (row 0) as the follower last
    received them (`radio.receive`; its own and its peers' as they are)."""
    heard[:, :] = states
    heard_thrusts[:] = thrusts
    heard_thrusts[0] = receive(link, delivered, memory, tick, states[0], thrusts[0],
                               states[index, UAV_POSITION:UAV_POSITION + 3], heard[0])
