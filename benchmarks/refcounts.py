"""What numba's atomic reference counts cost the engine's tick: the same batch of twin-lift
formations flown in two fresh processes, one with numba's default atomic counts and one with
the plain counts our commands and nodes use (`multilift_sim.kernels.plain_reference_counts`,
MULTILIFT_PLAIN_REFCOUNTS=1), best of three CPU passes each, and numba's allocation counts
(NUMBA_NRT_STATS=1) of each to show the counting is the same.

Run: source scripts/env.sh && python benchmarks/refcounts.py [--batch 16] [--ticks 3000]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

CHILD = r'''
import json, sys, time
import numpy as np
from numba.core.runtime import rtsys
from multilift_sim import kernels, scenario as scenario_io
from multilift_control.engine import Engine
batch, ticks = int(sys.argv[1]), int(sys.argv[2])
engine = Engine(scenario_io.load('twin_lift'), batch=batch)
engine.step(10)  # loaded and warm
best = float('inf')
for _ in range(3):
    engine.reset()
    start = time.process_time()
    engine.step(ticks)
    best = min(best, time.process_time() - start)
stats = rtsys.get_allocation_stats()
print(json.dumps({'plain': kernels.plain_reference_counts(),
                  'us_per_formation_tick': best / (batch * ticks) * 1e6,
                  'positions': np.asarray(engine.positions).tolist(),
                  'allocations': [stats.alloc, stats.free, stats.mi_alloc, stats.mi_free]}))
'''


def fly(plain: bool, batch: int, ticks: int) -> dict:
    """One fresh process's figures (CHILD), with plain or atomic counts."""
    env = dict(os.environ, MULTILIFT_PLAIN_REFCOUNTS='1' if plain else '0', NUMBA_NRT_STATS='1',
               OPENBLAS_NUM_THREADS='1')
    out = subprocess.run([sys.executable, '-c', CHILD, str(batch), str(ticks)], env=env,
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--batch', type=int, default=16)
    parser.add_argument('--ticks', type=int, default=3000)
    args = parser.parse_args()
    runs = {plain: fly(plain, args.batch, args.ticks) for plain in (False, True)}
    for plain, run in runs.items():
        print(f'{"plain " if plain else "atomic"} counts: {run["us_per_formation_tick"]:.2f} us '
              f'per formation-tick (B = {args.batch}, {args.ticks} ticks, best of 3 CPU passes); '
              f'NRT alloc/free/meminfo alloc/free {run["allocations"]}')
    same = runs[False]['positions'] == runs[True]['positions']
    print(f'positions equal to the bit: {same}; saved '
          f'{1 - runs[True]["us_per_formation_tick"] / runs[False]["us_per_formation_tick"]:.0%}')


if __name__ == '__main__':
    main()
