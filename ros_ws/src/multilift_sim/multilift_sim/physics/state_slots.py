"""The formation state's offsets (physics.layout's `uav_slot`, `payload_slot`, `n_coordinates`,
`attitude_slot`) compiled, for the kernels: numba calls no plain function, so these are
layout's own functions under numba's njit (one source; `kernels.uncompiled` runs the
originals). numpy code uses formation_params.StateLayout instead."""
from multilift_sim.kernels import jit
from multilift_sim.physics import layout

uav_slot = jit(layout.uav_slot)             # UAV i's block in q_f (its rates: + rates_slot)
payload_slot = jit(layout.payload_slot)     # r_p in q_f (v_p: + rates_slot)
rates_slot = jit(layout.n_coordinates)      # where q_f_dot starts in x: 6n + 3
attitude_slot = jit(layout.attitude_slot)   # a rigid payload's attitude block: 2 (6n + 3)
