#!/usr/bin/env python3
"""Throughput of `multilift sweep` campaigns: runs per minute of the 120 s twin-lift.

    scripts/setup && source scripts/env.sh && python benchmarks/sweep_throughput.py
        [--runs 4] [--duration 120] [--out benchmarks/results.md]

Three clusters, one after the other, each given the same campaign (--runs twin_lift runs of
--duration simulated seconds, a grid over payload.mass so that no two runs are the same task):
a local Dask cluster of 1 worker, one of 2 workers (processes with one thread each on
127.0.0.1, as `multilift sweep --workers N`), and a command-line cluster on localhost
(`dask scheduler` and two `dask worker --nworkers 1 --nthreads 1` processes, as
docs/cluster.md starts them), reached through its address as `--scheduler` does.

For each: the start-up (cluster ready), the campaign's wall time from the first submit to the
last row, runs per minute, each run's own wall time (measured inside the worker) and the
overhead against the ideal: the ideal campaign takes sum(run wall times) / workers, so the
overhead is what scheduling, transfer, imports in fresh workers and idle tails add. Runs per
minute against one in-process run (`campaign.run_one` here, before the clusters) is printed
too: on a machine shared with other work that also shows the CPU the workers did not get.
With --out, the markdown section between this script's markers in that file is replaced (or
appended).
"""
from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from multilift_tools import campaign as cp
from multilift_tools.campaign import sweep

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / 'benchmarks'))
from compare import compile_ahead  # noqa: E402
BEGIN = '<!-- sweep_throughput: begin -->'
END = '<!-- sweep_throughput: end -->'


def campaign_for(runs: int) -> cp.Campaign:
    source, base = cp.load_base('twin_lift')
    masses = ','.join(f'{0.8 + 0.001 * k:.3f}' for k in range(runs))
    return cp.build_campaign(source, base, [cp.parse_set(f'payload.mass={masses}')], [], None,
                             0)


def measure(client, workers: int, campaign: cp.Campaign, duration: float) -> dict:
    rows: dict[int, dict] = {}
    start = time.perf_counter()
    sweep.run_campaign(client, campaign, duration, None, sweep.Progress(0, False), rows)
    wall = time.perf_counter() - start
    assert len(rows) == len(campaign.runs) and all(r['status'] == 'ok' for r in rows.values())
    run_walls = [r['wall_time'] for r in rows.values()]
    ideal = sum(run_walls) / workers
    return {'wall': wall, 'per_minute': 60 * len(rows) / wall,
            'run_mean': sum(run_walls) / len(run_walls), 'ideal': ideal,
            'overhead': wall / ideal - 1}


class CommandLineCluster:
    """`dask scheduler` + two `dask worker` processes on 127.0.0.1, ports from the OS."""

    def __init__(self, logdir: Path):
        dask = str(ROOT / '.venv' / 'bin' / 'dask')
        self.procs = []
        log = logdir / 'scheduler.log'
        self.procs.append(subprocess.Popen(
            [dask, 'scheduler', '--host', '127.0.0.1', '--port', '0', '--no-dashboard',
             '--no-show'], stdout=log.open('w'), stderr=subprocess.STDOUT,
            start_new_session=True))
        deadline = time.monotonic() + 60
        while not (match := re.search(r'Scheduler at:\s+(tcp://\S+)', log.read_text())):
            if time.monotonic() > deadline or self.procs[0].poll() is not None:
                raise RuntimeError(log.read_text())
            time.sleep(0.05)
        self.address = match.group(1)
        for k in range(2):
            self.procs.append(subprocess.Popen(
                [dask, 'worker', self.address, '--host', '127.0.0.1', '--nworkers', '1',
                 '--nthreads', '1', '--no-dashboard', '--name', f'w{k}'],
                stdout=(logdir / f'worker{k}.log').open('w'), stderr=subprocess.STDOUT,
                start_new_session=True))

    def close(self) -> None:
        for proc in self.procs:
            try:
                os.killpg(proc.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        for proc in self.procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--runs', type=int, default=4, help='runs per campaign')
    parser.add_argument('--duration', type=float, default=120.0, help='simulated seconds')
    parser.add_argument('--out', help='results file whose sweep_throughput section to replace')
    args = parser.parse_args()
    compile_ahead()  # the engine's kernels in the cache: no first use timed
    from distributed import Client

    campaign = campaign_for(args.runs)
    load_before = os.getloadavg()
    print(f'one in-process run of twin_lift, {args.duration:g} s ...', file=sys.stderr)
    single = cp.run_one(campaign.source, campaign.base, campaign.edits(campaign.runs[0]),
                        args.duration)['wall_time']
    results = []
    for workers in (1, 2):
        print(f'local cluster, {workers} worker(s) ...', file=sys.stderr)
        start = time.perf_counter()
        client, cluster = sweep.open_client(None, workers)
        client.wait_for_workers(workers)
        ready = time.perf_counter() - start
        try:
            results.append((f'local cluster, {workers} worker(s)', workers, ready,
                            measure(client, workers, campaign, args.duration)))
        finally:
            sweep.close_client(client, cluster)
    print('command-line cluster on localhost, 2 workers ...', file=sys.stderr)
    with tempfile.TemporaryDirectory() as logdir:
        start = time.perf_counter()
        cli = CommandLineCluster(Path(logdir))
        try:
            client = Client(cli.address, timeout='30s')
            client.wait_for_workers(2, timeout=120)
            ready = time.perf_counter() - start
            results.append(('`dask scheduler` + 2 `dask worker`', 2, ready,
                            measure(client, 2, campaign, args.duration)))
            client.close()
        finally:
            cli.close()
    load_after = os.getloadavg()
    lines = [BEGIN, '## Sweep campaign throughput (`benchmarks/sweep_throughput.py`)', '',
             f'`python benchmarks/sweep_throughput.py --runs {args.runs} --duration '
             f'{args.duration:g}`: {args.runs} runs of twin_lift ({args.duration:g} s '
             f'simulated) per campaign, {os.cpu_count()} CPUs, load average '
             f'{load_before[0]:.1f} before and {load_after[0]:.1f} after (the machine is '
             f'shared). One in-process run: {single:.1f} s = {60 / single:.2f} runs/min.', '',
             '| cluster | workers | ready [s] | campaign [s] | runs/min | mean run [s] | '
             'ideal [s] | overhead vs ideal |',
             '| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |']
    for name, workers, ready, m in results:
        lines.append(f'| {name} | {workers} | {ready:.1f} | {m["wall"]:.1f} | '
                     f'{m["per_minute"]:.2f} | {m["run_mean"]:.1f} | {m["ideal"]:.1f} | '
                     f'{100 * m["overhead"]:+.1f} % |')
    lines += ['', 'ideal = the sum of the runs\' own wall times (measured in the worker) / '
              'workers; overhead = campaign / ideal - 1 (scheduling, transfers, fresh '
              'workers\' imports, the idle tail when runs do not divide evenly). A run\'s own '
              'wall time grows when the workers share the cores with each other and with '
              'other work: compare the mean run with the in-process run.', END]
    text = '\n'.join(lines) + '\n'
    print(text)
    if args.out:
        path = Path(args.out)
        old = path.read_text() if path.exists() else ''
        if BEGIN in old and END in old:
            head, rest = old.split(BEGIN, 1)
            new = head + text.rstrip('\n') + rest.split(END, 1)[1]
        else:
            new = old.rstrip('\n') + '\n\n' + text
        path.write_text(new)
    return 0


if __name__ == '__main__':
    sys.exit(main())
