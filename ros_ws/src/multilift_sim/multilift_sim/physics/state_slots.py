"""The formation state's offsets (physics.layout's `uav_slot`, `payload_slot`, `n_coordinates`,
`uav_attitude_slot`, `attitude_slot`) compiled, for the kernels: numba calls no plain
function, so these are layout's own functions under numba's njit (one source;
`kernels.uncompiled` runs the originals). numpy code uses formation_params.StateLayout instead."""
from multilift_sim.kernels import jit
from multilift_sim.physics import layout

uav_slot = jit(layout.uav_slot)             # UAV i's r_i in q (its velocity: + rates_slot)
payload_slot = jit(layout.payload_slot)     # r_p in q (v_p: + rates_slot)
rates_slot = jit(layout.n_coordinates)      # where q_dot starts in x: 3n + 3
uav_attitude_slot = jit(layout.uav_attitude_slot)  # UAV i's attitude block (BODY_*)
attitude_slot = jit(layout.attitude_slot)   # a rigid payload's attitude block: after the UAVs'
chain_node_slot = jit(layout.chain_node_slot)   # cable i's inner node k (cable_model: chain)
chain_inner_nodes = jit(layout.chain_inner_nodes)   # N - 1 of a chain's state, else 0
rigid_payload_state = jit(layout.rigid_payload_state)  # a state with a rigid payload's block
