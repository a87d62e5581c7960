"""Per-tick cost of the simulator's run statistics and seed Algorithm 1's check, in process:
what `FormationSimulator.advance` spends besides the integration (the commands' figures, the
tensions, the check with the swing and the gust at the payload).

    source scripts/env.sh; nice -n 19 python benchmarks/statistics_tick.py [SCENARIO ...]

Prints microseconds per tick for each scenario (process CPU time, the best of five rounds of
2000 ticks: the machine may be busy), under MULTILIFT_KERNEL as set (python: the statistics'
uncompiled run): the simulator's calls (`advance`'s statistics and `_check`, the gust at the
payload included), and the compiled functions called directly on the arrays (what a tick
calls; from Python, so mostly the call's own cost).
"""
from __future__ import annotations

import sys
import time

import numpy as np

from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator

ROUNDS, TICKS = 5, 2000


def per_tick_us(name: str) -> tuple[float, float]:
    """Best times of one tick's statistics and check [us] for scenario `name`, at its start:
    through the simulator, and the compiled functions alone (inf where there are none)."""
    sim = FormationSimulator(scenario_io.load(name))
    speeds = [np.full(u.vehicle.n_rotors, 1500.0) for u in sim.scenario.uavs]
    saturated = [np.zeros(u.vehicle.n_rotors, dtype=bool) for u in sim.scenario.uavs]
    stacked = np.asarray(speeds)           # as FormationSimulator.advance passes them
    tension, g, g_dot = sim.cable_state(speeds)
    period, t = sim.period_ns * 1e-9, sim.t
    stats = sim.stats
    best = float('inf')
    for _ in range(ROUNDS):
        start = time.process_time()
        for tick in range(TICKS):
            stats.add_commands(stacked, saturated, period)
            stats.add_tensions(tension)
            sim.tick = tick                  # the swing's sampling follows the tick
            sim._check(t, (g, g_dot))
        best = min(best, (time.process_time() - start) / TICKS)
    direct = float('inf')
    if hasattr(stats, 'run'):                 # the compiled accumulators (not before them)
        add_commands, add_tensions, check = (stats._functions[name] for name in (
            'run_add_commands', 'run_add_tensions', 'run_check'))
        flags = np.asarray(saturated)
        limits = sim.scenario.simulation
        taut, run, x, reach = sim._all_taut, stats.run, sim.state, sim._reach
        for _ in range(ROUNDS):
            start = time.process_time()
            for tick in range(TICKS):
                add_commands(run, stacked, flags, period)
                add_tensions(run, tension)
                check(run, x, g, g_dot, taut, limits.constraint_tolerance,
                      limits.constraint_rate_tolerance, t, tick, sim._swing_every, reach)
            direct = min(direct, (time.process_time() - start) / TICKS)
    return best * 1e6, direct * 1e6


def main(names: list[str]) -> None:
    for name in names or ['twin_lift', 'multi_lift', 'circle3', 'v5']:
        simulator, direct = per_tick_us(name)
        print(f'{name:12s} {simulator:7.2f} us per tick in the simulator, {direct:5.2f} us '
              'in the compiled calls alone')


if __name__ == '__main__':
    main(sys.argv[1:])
