#!/usr/bin/env python3
"""Whole user commands against the targets of issue 11, timed as a user would (wall clock of
the process, start-up included), one after the other on this machine.

    scripts/setup && source scripts/env.sh && python benchmarks/commands.py [--domain 12]
        [--ros-seconds 20] [--scaling-seconds 5]

- `scripts/multilift run twin_lift --headless` (120 s mission), without and with `--bag`;
- `scripts/multilift run twin_lift --bag` through ROS (120 s) and a "V" of ten (25 m cables,
  `--ros-seconds` simulated);
- the ROS cost per tick for V formations of n = 3, 10, 30 (`--scaling-seconds` simulated,
  the simulator's own wall clock from the bag's summary.json, start-up excluded) and the
  exponent of a least-squares fit cost ~ n^p;
- the headless cost per tick at n = 10 and n = 100 (in process, 10 s simulated).
Prints a markdown table; nothing is written.
"""
from __future__ import annotations

import os

for _var in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_var, '1')

import argparse  # noqa: E402 - after the BLAS thread setting
import json  # noqa: E402
import math  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import yaml  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'benchmarks'))
from compare import compile_ahead, v_formation_data, with_duration  # noqa: E402

from multilift_control.headless import run_headless  # noqa: E402
from multilift_sim import scenario as scenario_io  # noqa: E402

MULTILIFT = str(ROOT / 'scripts' / 'multilift')


def timed(args: list[str], env: dict) -> tuple[float, dict]:
    """(wall seconds of the whole command, the summary.json of its bag or {})."""
    start = time.perf_counter()
    out = subprocess.run([MULTILIFT, *args], env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if out.returncode != 0:
        raise SystemExit(f'{" ".join(args)} failed: {out.stderr[-600:]}')
    if '--bag' in args:
        bag = Path(args[args.index('--bag') + 1])
        return wall, json.loads((bag / 'summary.json').read_text())
    return wall, {}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--domain', type=int, default=12)
    parser.add_argument('--ros-seconds', type=float, default=20.0)
    parser.add_argument('--scaling-seconds', type=float, default=5.0)
    args = parser.parse_args(argv)
    compile_ahead()  # the engine's kernels in the cache: no first use timed
    env = dict(os.environ, ROS_DOMAIN_ID=str(args.domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    rows = []

    def row(what: str, simulated: float, wall: float, target: float | None) -> None:
        rate = simulated / wall
        verdict = '' if target is None else (
            'met' if rate >= target else f'missed by {target / rate:.1f}x')
        rows.append((what, simulated, wall, rate, target, verdict))
        print(f'{what}: {simulated:g} s simulated in {wall:.2f} s wall = {rate:.1f}x '
              f'{verdict}', flush=True)

    with tempfile.TemporaryDirectory(prefix='multilift-commands-') as tmp:
        work = Path(tmp)
        wall, _ = timed(['run', 'twin_lift', '--headless'], env)
        row('run twin_lift --headless', 120.0, wall, 100.0)
        wall, _ = timed(['run', 'twin_lift', '--headless', '--bag', str(work / 'h')], env)
        row('run twin_lift --headless --bag', 120.0, wall, 50.0)
        wall, _ = timed(['run', 'twin_lift', '--bag', str(work / 'r')], env)
        row('run twin_lift --bag (ROS)', 120.0, wall, 5.0)
        scenarios = {}
        for n in (3, 10, 30):
            data, _ = v_formation_data(n)
            path = work / f'v{n}.yaml'
            path.write_text(yaml.safe_dump(data))
            scenarios[n] = path
        wall, _ = timed(['run', str(scenarios[10]), '--duration', f'{args.ros_seconds:g}',
                         '--bag', str(work / 'v10')], env)
        row(f'run V n=10 --bag (ROS, {args.ros_seconds:g} s)', args.ros_seconds, wall, 1.0)
        costs = {}
        for n, path in scenarios.items():
            _, summary = timed(['run', str(path), '--duration', f'{args.scaling_seconds:g}',
                                '--bag', str(work / f'scale{n}')], env)
            sim = summary['sim']
            ticks = round(sim['simulated_time'] * 100) + 1
            costs[n] = sim['wall_time'] / ticks
            print(f'ROS n={n}: {1e3 * costs[n]:.2f} ms per tick', flush=True)
    ns = sorted(costs)
    exponent = float(np.polyfit(np.log(ns), np.log([costs[n] for n in ns]), 1)[0])
    print(f'ROS cost per tick ~ n^{exponent:.2f} over n = {ns} (target <= 1.2)')
    headless = {}
    for n in (10, 100):
        data, _ = v_formation_data(n)
        scenario = with_duration(scenario_io.loads(yaml.safe_dump(data), f'v{n}'), 10.0)
        start = time.perf_counter()
        run = run_headless(scenario)
        headless[n] = (time.perf_counter() - start) / (run.simulator.tick + 1)
        print(f'headless n={n}: {1e3 * headless[n]:.2f} ms per tick', flush=True)
    ratio = headless[100] / headless[10]
    print(f'headless per tick n=100 / n=10: {ratio:.1f} (target <= 12)')
    print('\n| command | simulated [s] | wall [s] | x real time | target |')
    print('| --- | ---: | ---: | ---: | --- |')
    for what, simulated, wall, rate, target, verdict in rows:
        goal = '' if target is None else f'>= {target:g}: {verdict}'
        print(f'| `{what}` | {simulated:g} | {wall:.2f} | {rate:.1f} | {goal} |')
    print('| ROS cost per tick, n = 3 / 10 / 30 | | '
          + ' / '.join(f'{1e3 * costs[n]:.2f} ms' for n in ns)
          + f' | n^{exponent:.2f} | <= n^1.2: {"met" if exponent <= 1.2 else "missed"} |')
    print(f'| headless per tick, n = 10 / 100 | | {1e3 * headless[10]:.2f} / '
          f'{1e3 * headless[100]:.2f} ms | {ratio:.1f}x | <= 12x: '
          f'{"met" if ratio <= 12 else "missed"} |')
    return 0 if math.isfinite(exponent) else 1


if __name__ == '__main__':
    sys.exit(main())
