#!/usr/bin/env python3
"""What elastic cables and winches cost (issue 32 item 7): the simulator's advance per control
tick (the physics of a 10 ms tick: its RK4 steps and their sub-steps, the check, the
statistics) of `twin_lift` on rigid cables against `twin_lift_elastic` (2 mm Dyneema, EA =
1.5e5 N), the same twin-lift on stiffer ropes, each with the sub-steps its validation asks for,
and both with winches reeling (0.1 m/s paid out from t = 0, `uavs[i].winch`); the rotors
held at their hover speeds (no controller), CPU time per tick, the best of three passes; then
the real-time factor of a whole `scripts/multilift run twin_lift_elastic --headless` (the
process's wall time, start-up included, and the simulated time over the simulator's own).

Run: scripts/setup && source scripts/env.sh && python benchmarks/elastic_cables.py
     [--seconds 30] [--runs 3]
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

import yaml  # noqa: E402 - after the BLAS setting

from multilift_control.headless import hover_speeds  # noqa: E402
from multilift_sim import scenario as scenario_io  # noqa: E402
from multilift_sim.cables import elastic  # noqa: E402
from multilift_sim.scenario.files import resolve  # noqa: E402
from multilift_sim.simulation import FormationSimulator  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def variant(name: str, seconds: float, cable: dict | None = None):
    """Scenario `name` flown `seconds` [s]; with `cable` those keys of its `cable:` section
    changed (an elastic rope's axial_stiffness, a chain's links), at the sub-steps the
    validation asks for (the number its one-line refusal names)."""
    data = yaml.safe_load(resolve(name).read_text())
    data['simulation']['duration'] = seconds
    if cable is not None:
        data['cable'].update(cable)
        data['simulation']['substeps'] = 1
        try:
            scenario_io.loads(yaml.safe_dump(data))
        except scenario_io.ScenarioError as exc:
            needed = re.search(r'substeps >= (\d+)', str(exc))
            data['simulation']['substeps'] = int(needed.group(1))
    return scenario_io.loads(yaml.safe_dump(data))


def reeling(scenario_name: str, seconds: float):
    """Scenario `name` flown `seconds` [s] with a winch on each UAV paying out 0.1 m/s from
    t = 0 (the reel's arithmetic in every RK4 stage)."""
    data = yaml.safe_load(resolve(scenario_name).read_text())
    data['simulation']['duration'] = seconds
    for uav in data['uavs']:
        # it only pays out: the stop at the cable's length (the rope's stiffest, as stepped)
        uav['winch'] = {'rate_limit': 0.5, 'acceleration_limit': 0.5,
                        'min_length': data['cable_length'], 'max_length': 20.0}
    data['events'] = [{'time': 0.0, 'type': 'winch_rate', 'uav': i + 1, 'rate': 0.1}
                      for i in range(len(data['uavs']))]
    return scenario_io.loads(yaml.safe_dump(data))


def tick_cost(scenario) -> float:
    """CPU time [us] of the simulator's advance per control tick at hover rotor speeds, the
    best of three passes."""
    speeds = hover_speeds(scenario)
    flags = [s * False for s in speeds]
    best = float('inf')
    for _ in range(3):
        sim = FormationSimulator(scenario)
        start = time.process_time()
        while not sim.finished:
            sim.advance(speeds, flags)
        best = min(best, (time.process_time() - start) / sim.tick)
    return 1e6 * best


def omega_h(scenario) -> float:
    """The ropes' fastest mode's bound times the RK4 step [-] (0 for rigid cables)."""
    uavs, sim = scenario.uavs, scenario.simulation
    if scenario.cable_model != 'elastic':
        return 0.0
    rate = elastic.rope_rate([u.cable_stiffness for u in uavs], [u.cable_damping for u in uavs],
                             [u.vehicle.mass for u in uavs], scenario.payload.mass)
    return rate / (sim.physics_rate * sim.substeps)


def whole_run(name: str) -> tuple[float, float, float]:
    """(wall [s] of the process, its real-time factor, the summary's real-time factor) of
    `scripts/multilift run NAME --headless`."""
    start = time.perf_counter()
    out = subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', name, '--headless'],
                         capture_output=True, text=True, check=True, cwd=ROOT).stdout
    wall = time.perf_counter() - start
    simulated, own = re.search(r'([\d.]+) s simulated in ([\d.]+) s wall', out).groups()
    summary = float(re.search(r'\(([\d.]+)x real time\)', out).group(1))
    return wall, float(simulated) / wall, summary


def report(cases, seconds: float, stepping, name: str, runs: int) -> None:
    """Print each case's cost per tick (the first's the rigid reference) with its physics
    rate, sub-steps and `stepping(scenario)` (its omega h), then `runs` whole headless runs of
    scenario `name`: what benchmarks/elastic_cables.py and chain_cables.py report alike."""
    print(f'advance per control tick (100 Hz), {seconds:g} s at hover, CPU [us]:')
    width = max(len(label) for label, _ in cases)
    rigid = None
    for label, scenario in cases:
        cost = tick_cost(scenario)
        rigid = rigid or cost
        sim = scenario.simulation
        print(f'  {label:{width}s} {cost:7.1f} us  ({cost / rigid:5.2f}x rigid)  physics '
              f'{sim.physics_rate:g} Hz x {sim.substeps} sub-steps, omega h = '
              f'{stepping(scenario):.2f}', flush=True)
    print(f'scripts/multilift run {name} --headless (120 s):')
    for _ in range(runs):
        wall, rtf, summary = whole_run(name)
        print(f'  {wall:.2f} s wall, {rtf:.0f}x real time whole ({summary:.0f}x in its '
              'summary)', flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seconds', type=float, default=30.0)
    parser.add_argument('--runs', type=int, default=3)
    args = parser.parse_args()
    cases = [('twin_lift (rigid)', variant('twin_lift', args.seconds)),
             ('twin_lift_elastic (EA 1.5e5 N)', variant('twin_lift_elastic', args.seconds))]
    cases += [(f'twin_lift_elastic at EA {ea:.2g} N',
               variant('twin_lift_elastic', args.seconds, {'axial_stiffness': ea}))
              for ea in (1.5e6, 1.5e7)]
    cases += [(f'{name} with winches reeling', reeling(name, args.seconds))
              for name in ('twin_lift', 'twin_lift_elastic')]
    report(cases, args.seconds, omega_h, 'twin_lift_elastic', args.runs)
    wall, rtf, summary = whole_run('twin_lift')
    print(f'  twin_lift (rigid) for comparison: {wall:.2f} s wall, {rtf:.0f}x whole '
          f'({summary:.0f}x)')


if __name__ == '__main__':
    sys.exit(main())
