"""Issue 19's engine targets, one run each, figures printed (wall and CPU time; on a busy
machine the CPU figures are the fairer ones):

- `multilift run twin_lift --headless` (and `--bag`), whole commands;
- 64 twin-lift missions of 120 s (payload masses 0.6-1.1 kg, gust speeds 0-4 m/s) in one
  process on one core, one Engine: aggregate simulated s per wall s (target >= 300);
- the engine's cost per tick at n = 10 and n = 100 (V formations; target: within 10x).

    python benchmarks/engine.py [--skip-commands]
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'benchmarks'))

from multilift_sim import kernels  # noqa: E402 - NUMBA_CACHE_DIR before numba loads
from compare import compile_ahead  # noqa: E402


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def whole_command(args: list[str]) -> tuple[float, float]:
    """(wall [s], CPU [s]) of `scripts/multilift ARGS`."""
    before, start = _children_cpu(), time.monotonic()
    subprocess.run([str(ROOT / 'scripts' / 'multilift'), *args], check=True,
                   stdout=subprocess.DEVNULL)
    return time.monotonic() - start, _children_cpu() - before


def batched(count: int = 64) -> None:
    from multilift_control.engine import Engine
    from multilift_sim import scenario as scenario_io
    base = scenario_io.load('twin_lift')
    scenarios = []
    for k in range(count):
        mass = 0.6 + 0.5 * k / (count - 1)
        speed = 4.0 * ((k * 7) % count) / (count - 1)
        gusts = tuple(dataclasses.replace(g, reference_speed=speed) for g in base.gusts)
        scenarios.append(dataclasses.replace(
            base, payload=dataclasses.replace(base.payload, mass=mass), gusts=gusts))
    cpu, start = time.process_time(), time.monotonic()
    engine = Engine(scenarios)
    built = time.monotonic()
    engine.step(base.simulation.tick_count)
    wall, cpu = time.monotonic() - start, time.process_time() - cpu
    simulated = float(engine.t.sum())
    print(f'batched: {count} twin-lift missions, {simulated:.0f} simulated s in {wall:.2f} s wall '
          f'({built - start:.2f} s building the arrays), {cpu:.2f} s CPU: '
          f'{simulated / wall:.0f}x real time (wall), {simulated / cpu:.0f}x (CPU); '
          f'finished {int(engine.finished.sum())}, stopped {int(engine.stopped.sum())} '
          '(target >= 300x)')


def per_tick(n: int, ticks: int) -> float:
    """The engine's CPU [us] per tick of a V of n (after its first tick)."""
    from compare import v_formation_data
    from multilift_control.engine import Engine
    from multilift_sim import scenario as scenario_io
    import yaml
    data, _ = v_formation_data(n)
    scenario = scenario_io.loads(yaml.safe_dump(data), f'v{n}.yaml')
    engine = Engine(scenario)
    engine.step(1)
    cpu = time.process_time()
    flown = int(engine.step(ticks)[0])
    return (time.process_time() - cpu) / flown * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--skip-commands', action='store_true')
    args = parser.parse_args()
    compile_ahead()  # the engine's kernels in the cache: no first use timed
    print(f'MULTILIFT_KERNEL={kernels.mode()}, load average {os.getloadavg()}')
    if not args.skip_commands:
        for extra in ([], ['--bag']):
            with tempfile.TemporaryDirectory() as tmp:
                command = ['run', 'twin_lift', '--headless']
                if extra:
                    command += ['--bag', str(Path(tmp) / 'bag')]
                wall, cpu = whole_command(command)
            print(f'`multilift {" ".join(command[:3] + extra)}`: 120 s in {wall:.2f} s wall, '
                  f'{cpu:.2f} s CPU: {120 / wall:.0f}x real time (wall), {120 / cpu:.0f}x (CPU) '
                  f'(target >= {100 if extra else 200}x)')
    batched()
    ten, hundred = per_tick(10, 1000), per_tick(100, 200)
    print(f'per tick (engine, CPU): n = 10 {ten:.0f} us, n = 100 {hundred:.0f} us, '
          f'ratio {hundred / ten:.1f} (target <= 10)')


if __name__ == '__main__':
    main()
