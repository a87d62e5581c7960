#!/usr/bin/env python3
"""What heavy cables cost (`cable_model: chain`, issue 32 item 7): the simulator's advance per
control tick (the physics of a 10 ms tick: its RK4 steps and their sub-steps, the check, the
statistics) of `twin_lift` on rigid cables against `twin_lift_chain` (30 links a cable, 2
sub-steps) and the same chains of 10 and 60 links, each with the sub-steps the validation asks
for; the rotors held at their hover speeds (no controller), CPU time per tick, the best of
three passes; then the real-time factor of a whole `scripts/multilift run twin_lift_chain
--headless` (the process's wall time, start-up included, and the summary's own).

Run: scripts/setup && source scripts/env.sh && python benchmarks/chain_cables.py
     [--seconds 30] [--runs 3]
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

from multilift_sim.cables import chain  # noqa: E402 - after the BLAS setting

sys.path.insert(0, str(Path(__file__).resolve().parent))
from elastic_cables import report, variant  # noqa: E402


def omega_h(scenario) -> float:
    """The chains' fastest transverse mode's bound times the RK4 step [-] (0: no chain)."""
    if scenario.cable_model != 'chain':
        return 0.0
    sim, keys = scenario.simulation, scenario.cable
    rate = chain.chain_rate([u.cable_length for u in scenario.uavs], keys['links'],
                            keys['mass_per_length'], scenario.payload.mass, sim.gravity)
    return rate / (sim.physics_rate * sim.substeps)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seconds', type=float, default=30.0)
    parser.add_argument('--runs', type=int, default=3)
    args = parser.parse_args()
    cases = [('twin_lift (rigid)', variant('twin_lift', args.seconds)),
             ('twin_lift_chain (30 links)', variant('twin_lift_chain', args.seconds))]
    cases += [(f'twin_lift_chain at {links} links',
               variant('twin_lift_chain', args.seconds, {'links': links})) for links in (10, 60)]
    report(cases, args.seconds, omega_h, 'twin_lift_chain', args.runs)


if __name__ == '__main__':
    sys.exit(main())
