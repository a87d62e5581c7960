"""Plain reference counts (`multilift_sim.kernels.plain_reference_counts`, set by our commands
and nodes through MULTILIFT_PLAIN_REFCOUNTS) count what numba's atomic ones count: the same
twin-lift batch flown in two fresh processes, one each way, ends at the same bits with the
same numbers of numba's allocations and frees (NUMBA_NRT_STATS; numba's own switch,
`_disable_atomicity`, would free nothing), and each process reports the counts it used."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

pytest.importorskip('numba')

CHILD = r'''
import json
import numpy as np
from numba.core.runtime import rtsys
from multilift_sim import kernels, scenario as scenario_io
from multilift_control.engine import Engine
engine = Engine(scenario_io.load('twin_lift'), batch=3)
engine.step(300)
stats = rtsys.get_allocation_stats()
print(json.dumps({'plain': kernels.plain_reference_counts(),
                  'positions': np.asarray(engine.positions).tolist(),
                  'allocations': [stats.alloc, stats.free, stats.mi_alloc, stats.mi_free]}))
'''


def _fly(plain: str) -> dict:
    env = dict(os.environ, MULTILIFT_PLAIN_REFCOUNTS=plain, NUMBA_NRT_STATS='1')
    done = subprocess.run([sys.executable, '-c', CHILD], env=env, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_plain_counts_free_what_atomic_counts_free_and_fly_the_same_bits():
    atomic, plain = _fly('0'), _fly('1')
    assert (atomic['plain'], plain['plain']) == (False, True)
    assert plain['positions'] == atomic['positions']
    assert plain['allocations'] == atomic['allocations']
    alloc, free, meminfo_alloc, meminfo_free = plain['allocations']
    assert alloc > 1000 and free > 1000  # the tick allocates and frees: the counts are live
