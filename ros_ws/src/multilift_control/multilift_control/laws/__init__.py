"""The control laws, each written once: numba functions over float arrays (constants, memory,
states), compiled just in time (`numba.njit(cache=True)`, the cache under NUMBA_CACHE_DIR) or
run uncompiled (`multilift_sim.kernels.uncompiled`: their own source in Python), as
MULTILIFT_KERNEL says (`runnable`, which is `kernels.runnable`).

One concern per module: `layout` (the named slots of every array below), `reference` (the
mission reference and its prefilter), `cascade` (position loop, attitude from force, attitude
loop, a leader's tick), `mixer` (allocation inverse and saturation, collective thrust),
`linalg` (the small SVD the nonlinear rows need), `constraints` (the virtual constraint rows
g_vc, seed Eq. 3.1-3.7), `follower` (the virtual-constraint force, Eq. 3.8-3.12, and a
follower's tick). The classes of `multilift_control.cascade`, `formation`, `mission`,
`controllers` and `runtime` only build these arrays and call the laws.

World frame z up, body FLU, ZYX Euler angles [rad], SI units (docs/conventions.md).
"""
from __future__ import annotations

from multilift_sim.kernels import jit, runnable  # noqa: F401 - every law's decorator; the
# wrappers' one way to a law (compiled, or its uncompiled run, as MULTILIFT_KERNEL says)
