#!/usr/bin/env python3
"""What our Fast DDS profile's UDP-only transport costs against Fast DDS's shared memory
(multilift_sim.ros.fastdds): whole `scripts/multilift run SCENARIO --bag` commands through ROS,
the two settings alternating so that the machine's drift falls on both alike.

    scripts/setup && source scripts/env.sh && python benchmarks/dds_transport.py
        [--scenario twin_lift] [--seconds 30] [--repeats 3] [--domain 90] [--range SUBNET]

- `udp`: our profile (UDP only; the default of every multilift process);
- `shm`: the same profile with Fast DDS's built-in transports (shared memory and UDP), what our
  nodes used before.
Prints each run's wall time and real-time factor, then the medians; nothing is kept.
"""
from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from multilift_sim.ros import fastdds

ROOT = Path(__file__).resolve().parents[1]


def profiles(directory: Path, localhost: bool) -> dict[str, Path]:
    """Our profile as it is (udp) and with the built-in transports instead of UDP alone."""
    ours = fastdds.FASTDDS_LOCALHOST_PROFILE if localhost else fastdds.FASTDDS_PROFILE
    builtin = re.sub(r'\s*<userTransports>.*?</userTransports>', '', ours, flags=re.S)
    builtin = builtin.replace('<useBuiltinTransports>false', '<useBuiltinTransports>true')
    out = {}
    for name, text in (('udp', ours), ('shm', builtin)):
        out[name] = directory / f'{name}.xml'
        out[name].write_text(text)
    return out


def run(scenario: str, seconds: float, env: dict, bag: Path) -> tuple[float, float]:
    """(wall time of the whole command [s], real-time factor of the simulation)."""
    start = time.monotonic()
    done = subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', scenario, '--duration',
                           str(seconds), '--bag', str(bag)], env=env, capture_output=True,
                          text=True, timeout=1800)
    wall = time.monotonic() - start
    if done.returncode != 0:
        raise SystemExit(f'run failed ({done.returncode}): {done.stderr[-2000:]}')
    factor = float(re.search(r'\(([\d.]+)x real time\)', done.stdout).group(1))
    return wall, factor


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--scenario', default='twin_lift')
    parser.add_argument('--seconds', type=float, default=30.0)
    parser.add_argument('--repeats', type=int, default=3)
    parser.add_argument('--domain', type=int, default=90)
    parser.add_argument('--range', default='SUBNET', choices=('SUBNET', 'LOCALHOST'))
    args = parser.parse_args()
    results: dict[str, list[tuple[float, float]]] = {'udp': [], 'shm': []}
    with tempfile.TemporaryDirectory(prefix='multilift-dds-') as tmp:
        files = profiles(Path(tmp), args.range == 'LOCALHOST')
        for k in range(args.repeats):
            for name in ('udp', 'shm') if k % 2 == 0 else ('shm', 'udp'):
                # a named profile: our processes leave it and the discovery range alone
                env = dict(os.environ, ROS_DOMAIN_ID=str(args.domain),
                           ROS_AUTOMATIC_DISCOVERY_RANGE='SUBNET',
                           FASTRTPS_DEFAULT_PROFILES_FILE=str(files[name]))
                wall, factor = run(args.scenario, args.seconds, env, Path(tmp) / f'{name}{k}')
                results[name].append((wall, factor))
                print(f'{name}  run {k + 1}: {wall:6.2f} s wall, {factor:5.1f}x real time',
                      flush=True)
    print(f'\n{args.scenario}, {args.seconds:g} s simulated with --bag, {args.range} profile, '
          f'{args.repeats} runs each (medians):')
    for name, rows in results.items():
        print(f'  {name}: {statistics.median(r[0] for r in rows):6.2f} s wall, '
              f'{statistics.median(r[1] for r in rows):5.1f}x real time')


if __name__ == '__main__':
    main()
