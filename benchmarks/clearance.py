#!/usr/bin/env python3
"""The cost of the clearance checks per control tick (issue 34 item 7): `physics.clearance.
measure` alone over the states of a flown run, for `window` (2 UAVs, 4 boxes) and `forest`
(3 UAVs, 18 cylinders), and the whole engine tick of each against the same scenario without
its `world:` section (the checks skipped).

    scripts/setup && source scripts/env.sh && python benchmarks/clearance.py [--repeat 5]

Prints a markdown table; nothing is written.
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

from multilift_control.headless import fly
from multilift_sim import scenario as scenario_io
from multilift_sim.physics import layout
from multilift_sim.physics.clearance import measure
from multilift_sim.scenario.world import world_arrays
from multilift_sim.tick_arrays import physics_fields


def measure_cost(scenario, repeat: int) -> float:
    """Seconds per call of `measure` at the scenario's start state (the best of `repeat`
    batches of 2000 calls)."""
    arrays, memory = physics_fields(scenario)
    world, obstacles, radii = world_arrays(scenario)
    least = np.zeros((layout.CLEARANCE_KINDS, layout.CLEARANCE_COLUMNS))
    contact = np.full(layout.CLEARANCE_COLUMNS, -1.0)
    state, uavs = memory['state'], arrays['uavs']
    best = math.inf
    for _ in range(repeat):
        least[:, layout.CLEARANCE_VALUE] = math.inf
        start = time.perf_counter()
        for _ in range(2000):
            measure(world, obstacles, radii, uavs, state, 0.0, least, contact)
        best = min(best, (time.perf_counter() - start) / 2000)
    return best


def tick_cost(scenario, repeat: int) -> float:
    """Seconds per control tick of the engine flying the whole scenario (best of `repeat`)."""
    best = math.inf
    for _ in range(repeat):
        start = time.perf_counter()
        fly(scenario)
        best = min(best, (time.perf_counter() - start) / scenario.simulation.tick_count)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--repeat', type=int, default=5)
    args = parser.parse_args()
    print('| scenario | obstacles | measure [us/call] | engine tick with world [us] | '
          'without [us] |')
    print('| --- | --- | --- | --- | --- |')
    for name in ('window', 'forest'):
        scenario = scenario_io.load(name)
        bare = dataclasses.replace(scenario, world=None)
        fly(scenario), fly(bare)  # compiled and loaded before timing
        print(f'| {name} | {len(scenario.world.obstacles)} | '
              f'{1e6 * measure_cost(scenario, args.repeat):.2f} | '
              f'{1e6 * tick_cost(scenario, args.repeat):.1f} | '
              f'{1e6 * tick_cost(bare, args.repeat):.1f} |')


if __name__ == '__main__':
    main()
