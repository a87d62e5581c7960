"""Where a headless tick's time goes: the loop of `run_headless` timed stage by stage (the
snapshot, the controllers' states, the controller runtime's answers, the simulator's advance),
in CPU time per tick, the best of two passes (the first also warms numba's kernel).

Run: source scripts/env.sh && python benchmarks/headless_tick.py [--scenario twin_lift]
     [--seconds 20]
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import time

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

from multilift_control.headless import uav_states  # noqa: E402 - after the BLAS setting
from multilift_control import runtime  # noqa: E402
from multilift_sim import scenario as scenario_io  # noqa: E402
from multilift_sim.simulation import FormationSimulator  # noqa: E402


def one_pass(scenario) -> dict[str, float]:
    """Per-tick CPU time [us] of each stage over one run of `scenario`."""
    sim = FormationSimulator(scenario)
    runtimes = (runtime.formation_runtimes(scenario)
                if hasattr(runtime, 'formation_runtimes')  # (so it times older code too)
                else [runtime.ControllerRuntime(scenario, i) for i in range(scenario.n_uavs)])
    stages = dict.fromkeys(('snapshot', 'states', 'answers', 'advance'), 0.0)
    clock = time.process_time
    while True:
        start = clock()
        snap = sim.snapshot()
        got_snapshot = clock()
        states = uav_states(snap)
        got_states = clock()
        answers = runtime.answer_tick(runtimes, sim.t_ns, states)
        answered = clock()
        stages['snapshot'] += got_snapshot - start
        stages['states'] += got_states - got_snapshot
        stages['answers'] += answered - got_states
        if sim.finished:
            break
        sim.advance([a.output.rotor_speeds for a in answers],
                    [a.output.saturated for a in answers])
        stages['advance'] += clock() - answered
    ticks = sim.tick + 1
    return {name: 1e6 * total / ticks for name, total in stages.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--scenario', default='twin_lift')
    parser.add_argument('--seconds', type=float, default=20.0)
    args = parser.parse_args()
    base = scenario_io.load(args.scenario)
    scenario = dataclasses.replace(base, simulation=dataclasses.replace(
        base.simulation, duration=args.seconds))
    best = min((one_pass(scenario) for _ in range(2)), key=lambda s: sum(s.values()))
    print(f'{args.scenario}, {args.seconds:g} s simulated, CPU per tick [us]:')
    for name, value in best.items():
        print(f'  {name:9s} {value:7.1f}')
    print(f'  {"total":9s} {sum(best.values()):7.1f}')


if __name__ == '__main__':
    main()
