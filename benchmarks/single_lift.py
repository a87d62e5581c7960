#!/usr/bin/env python3
"""Simulated seconds per wall second of the 120 s `single_lift` mission:
(a) the physics core alone (formation DAE at hover rotor speeds, no controller),
(a') the headless stack (physics core + cascade controller in one process),
(b) the full ROS stack in lockstep (`scripts/multilift run single_lift`, separate processes).

Run: scripts/setup && source scripts/env.sh && python benchmarks/single_lift.py
"""
from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from multilift_control.headless import hover_speeds, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator

ROOT = Path(__file__).resolve().parents[1]


def physics_only(name: str) -> float:
    scenario = scenario_io.load(name)
    sim = FormationSimulator(scenario)
    speeds = hover_speeds(scenario)
    flags = [s * False for s in speeds]
    start = time.perf_counter()
    while not sim.finished:
        sim.advance(speeds, flags)
    return sim.t / (time.perf_counter() - start)


def headless(name: str) -> float:
    scenario = scenario_io.load(name)
    start = time.perf_counter()
    sim = run_headless(scenario).simulator
    return sim.t / (time.perf_counter() - start)


def ros_stack(name: str) -> float:
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, ROS_DOMAIN_ID=os.environ.get('ROS_DOMAIN_ID', '61'),
                   ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
        bag = Path(tmp) / 'bag'
        subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', name, '--bag', str(bag)],
                       check=True, env=env, stdout=subprocess.DEVNULL)
        sim = json.loads((bag / 'summary.json').read_text())['sim']
        return sim['simulated_time'] / sim['wall_time']


def main() -> int:
    name = sys.argv[1] if len(sys.argv) > 1 else 'single_lift'
    print(f'{name}, 120 s mission, {platform.processor() or platform.machine()}, '
          f'{os.cpu_count()} cores, Python {platform.python_version()}')
    print(f'(a)  physics core alone         {physics_only(name):8.1f} simulated s / wall s')
    print(f"(a') headless core + controller {headless(name):8.1f} simulated s / wall s")
    print(f'(b)  ROS stack in lockstep      {ros_stack(name):8.1f} simulated s / wall s '
          '(sim_node wall time, recorder on)')
    return 0


if __name__ == '__main__':
    sys.exit(main())
