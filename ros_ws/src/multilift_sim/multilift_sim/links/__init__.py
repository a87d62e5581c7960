"""Links between the UAVs (issue 33 item 5, `comms:`; docs/estimation.md, "Links between the
UAVs"): what a follower hears of the leader. Without `comms:` a follower reads the leader's
state and its answer at the same tick, as the seed's Algorithm 1 does; with it, over a radio
link (`radio`): late by `latency`, lost with probability `loss` per packet and receiver,
lost beyond `range` [m].

One model is shipped (`radio`); the scenario's `comms:` section is its keys, its compiled
`receive` is what both controller runtimes call (the engine's tick,
`multilift_control.engine.tick.answer_formation`, and the runtime of the nodes and the headless
loop, `multilift_control.runtime.ControllerRuntime`), so ROS and headless hear alike.
"""
from multilift_sim.links.radio import CommsConfig, read_comms  # noqa: F401
