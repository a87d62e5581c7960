#!/usr/bin/env python3
"""`multilift run SCENARIO --bag` with and without `--compose` (every controller node in one
process): whole commands, timed as a user would, the two alternating so that the machine's
drift falls on both alike.

    scripts/setup && source scripts/env.sh && python benchmarks/compose.py
        [--scenario v10] [--seconds 20] [--repeats 3] [--domain 93]

`v10` (the default) is the "V" of ten of benchmarks/commands.py (25 m cables); any other
SCENARIO is a name in scenarios/ or a YAML path. For each run: the whole command's wall time
and its real-time factor (simulated / whole wall), the simulator's own factor (its loop, start-up
and bag close excluded: summary.json), and the CPU seconds of every process of the run by role
(sampled with psutil every 0.1 s) per simulated second. Then the medians; nothing is kept.
"""
from __future__ import annotations

import os

for _var in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_var, '1')

import argparse  # noqa: E402 - after the BLAS thread setting
import json  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import psutil  # noqa: E402
import yaml  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'benchmarks'))
from compare import v_formation_data  # noqa: E402

ROLES = ('sim_node', 'controllers_node', 'leader_node', 'follower_node', 'recorder_node')


def role(process: psutil.Process) -> str:
    """The executable a process of the run runs (`multilift` for the launcher)."""
    try:
        argv = process.cmdline()
    except psutil.Error:
        return '?'
    names = [Path(a).name for a in argv[:2]]
    return next((r for r in ROLES if r in names), 'multilift')


def run(args: list[str], env: dict) -> tuple[float, dict, dict[str, float]]:
    """(wall time of the whole command [s], its summary.json, CPU seconds by role)."""
    cpu: dict[int, tuple[str, float]] = {}
    start = time.monotonic()
    launcher = psutil.Popen([str(ROOT / 'scripts' / 'multilift'), *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    while launcher.poll() is None:
        try:
            family = [launcher, *launcher.children(recursive=True)]
        except psutil.Error:
            family = []
        for process in family:
            try:
                times = process.cpu_times()
            except psutil.Error:
                continue
            name = cpu[process.pid][0] if process.pid in cpu else role(process)
            if name != '?':  # not yet known (exec under way) or gone: the next sample
                cpu[process.pid] = (name, times.user + times.system)
        time.sleep(0.1)
    wall = time.monotonic() - start
    out, err = launcher.communicate()
    if launcher.returncode != 0:
        raise SystemExit(f'{" ".join(args)} failed ({launcher.returncode}): {err[-2000:]}')
    bag = Path(args[args.index('--bag') + 1])
    by_role: dict[str, float] = {}
    for name, seconds in cpu.values():
        by_role[name] = by_role.get(name, 0.0) + seconds
    return wall, json.loads((bag / 'summary.json').read_text()), by_role


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--scenario', default='v10')
    parser.add_argument('--seconds', type=float, default=20.0)
    parser.add_argument('--repeats', type=int, default=3)
    parser.add_argument('--domain', type=int, default=93)
    args = parser.parse_args(argv)
    env = dict(os.environ, ROS_DOMAIN_ID=str(args.domain),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    results: dict[str, list[tuple[float, float, float, dict]]] = {'separate': [], 'compose': []}
    with tempfile.TemporaryDirectory(prefix='multilift-compose-') as tmp:
        work = Path(tmp)
        scenario = args.scenario
        if scenario == 'v10':
            scenario = str(work / 'v10.yaml')
            Path(scenario).write_text(yaml.safe_dump(v_formation_data(10)[0]))
        for k in range(args.repeats):
            for mode in results:
                bag = work / f'{mode}{k}'
                command = ['run', scenario, '--duration', f'{args.seconds:g}', '--bag', str(bag)]
                command += ['--compose'] if mode == 'compose' else []
                wall, summary, cpu = run(command, env)
                sim = summary['sim']
                factor = args.seconds / wall
                loop = sim['simulated_time'] / sim['wall_time']
                results[mode].append((wall, factor, loop, cpu))
                shown = ', '.join(f'{r} {s / args.seconds:.2f}' for r, s in sorted(cpu.items()))
                print(f'multilift {" ".join(command)}: {wall:.2f} s wall, {factor:.2f}x real '
                      f'time (simulator loop {loop:.2f}x); CPU s per simulated s: {shown}; '
                      f'load {os.getloadavg()[0]:.1f}', flush=True)
    print(f'\n{args.scenario}, {args.seconds:g} s simulated, --bag, medians of {args.repeats}:')
    print('| run | wall [s] | x real time (whole command) | simulator loop | CPU s / sim s |')
    print('| --- | ---: | ---: | ---: | ---: |')
    for mode, rows in results.items():
        cpu = statistics.median(sum(r[3].values()) for r in rows) / args.seconds
        print(f'| {mode} | {statistics.median(r[0] for r in rows):.2f} | '
              f'{statistics.median(r[1] for r in rows):.2f} | '
              f'{statistics.median(r[2] for r in rows):.2f} | {cpu:.2f} |')
    return 0


if __name__ == '__main__':
    sys.exit(main())
