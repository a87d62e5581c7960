"""`multilift sweep`: a campaign of headless runs of one scenario on a Dask cluster.

    multilift sweep SCENARIO [--set KEY=V1,V2,...] [--sample KEY=DIST ...] [--samples N]
                    [--seed S] [--scheduler tcp://HOST:PORT | --workers N] [--out FILE]
                    [--bags DIR] [--duration S] [--no-progress]

--set gives a grid (the cartesian product of the values, as YAML scalars or [lists]);
--sample draws KEY from uniform(a,b), normal(mu,sigma) or choice(v1,v2,...), --samples N times
for every grid point, each run from its own seeded generator (`multilift_tools.campaign`: the
same --seed, default 0, gives the same campaign on any cluster). A typo, a bad value or a bad
distribution is one line on stderr and exit code 2 before anything starts; a drawn value the
scenario rejects is that run's `error` row.

Without --scheduler the runs go to a local Dask cluster on 127.0.0.1 of --workers processes
(default: the number of CPUs; --jobs is the same option), one thread and one BLAS thread each,
no dashboard. With --scheduler tcp://HOST:PORT they go to that cluster unchanged (its workers
need this repo, `scripts/setup` and `source scripts/env.sh`: see docs/cluster.md). The runs are
headless (`multilift_control.headless`: the simulator core and every controller in one
process, the laws and tick order of the ROS stack).

The table (FILE: Parquet when it ends in .parquet, CSV otherwise; CSV on stdout without
--out) has one row per run in input order: run (index), the parameters, seed, status (`ok`;
`stopped`: the simulation stopped itself, e.g. a cable left its tolerance; `error`: an
exception), message (why, one line), then the statistics (`multilift_sim.statistics
.summary_row`, what `run` reports): simulated_time [s], max_abs_g [m^2],
max_abs_g_dot [m^2/s], max_rotor_speed [rad/s] (over every UAV), saturated_time [s] (summed
over the UAVs), min_tension/max_tension [N], payload_swing_max/payload_swing_rms [m] (the
payload's distance from its equilibrium place under the UAVs), max_gust_speed [m/s] (met by
the payload), tracking_error_max/tracking_error_rms [m] (leader
against the mission reference, every tick; empty without a mission path), formation_error_max
(largest |g_vc| of any follower row, m or m^2), formation_error_mean (mean over ticks and
followers of the norm of its rows; empty for n = 1); a stopped run's figures cover the time
flown (every column's unit: `multilift_sim.units`). Then wall_time [s] (what the run cost its
worker: `campaign.runs`) and, with --bags DIR, bag (DIR/run_NNNNN, a rosbag2 directory written
by the worker on its own host's filesystem). Which parameters are grid axes and which sampled
(`Campaign.metadata`) is in the Parquet file's metadata, or beside a CSV FILE in
FILE.campaign.json (`campaign.table`).

A worker (or a whole worker host) that dies mid-run: Dask runs its task again on another
worker; each result is read once and released, so no row is lost or doubled. A run that kills
its worker three times is an `error` row (KilledWorker). Progress on stderr: runs done,
failed (stopped or error), ETA. Exit codes: 0 the campaign finished (failed runs are rows),
1 the cluster cannot be reached or went away mid-campaign (the finished rows are written),
2 bad input, 130 interrupted (Ctrl-C, SIGTERM, or SIGHUP when the terminal closes: the
finished rows are written).

The local cluster's nannies (in this process) make their worker processes' multiprocessing
queues from named POSIX semaphores, /dev/shm/sem.mp-*. They are unlinked when this process
closes the cluster, which every interruption does (a SIGTERM or SIGHUP that comes while the
cluster starts is held until it stands; a Ctrl-C then is lost: SIGINT is ignored while the
workers start, which inherit that), and else by multiprocessing's resource tracker, a child of
this process that unlinks what it registered once every process of the sweep is gone. The
tracker ignores SIGINT and SIGTERM and is started here with SIGHUP blocked, so that a closed
terminal, which hangs up the whole process group, does not kill it. Only SIGKILL of the tracker
itself (`kill -9 -PGID`: every process of the sweep at once) leaves semaphores behind.
"""
from __future__ import annotations

import argparse
import logging
import math
import os
import signal
import socket
import sys
import threading
import time
from multiprocessing import resource_tracker
from pathlib import Path

from multilift_sim import scenario as scenario_io
from multilift_tools import campaign as cp


class _Interrupts:
    """SIGTERM (unattended) and SIGHUP (the terminal closed) as Ctrl-C: a KeyboardInterrupt,
    which closes the cluster. While `holding` (the local cluster is starting, not yet ours to
    close) one is noted and `release` raises it once the cluster stands."""

    SIGNALS = (signal.SIGTERM, signal.SIGHUP)

    def __init__(self):
        self.holding = False
        self.held = False
        self.old = {}

    def __call__(self, signum, frame) -> None:
        if self.holding:
            self.held = True
            return
        raise KeyboardInterrupt

    def install(self) -> None:
        self.old = {signum: signal.signal(signum, self) for signum in self.SIGNALS}

    def restore(self) -> None:
        for signum, handler in self.old.items():
            signal.signal(signum, handler)

    def release(self) -> None:
        self.holding = False
        if self.held:
            raise KeyboardInterrupt


class ClusterLost(RuntimeError):
    """The campaign's futures were cancelled under it (the scheduler went away)."""


class Progress:
    """A tqdm bar on a terminal, else one line per finished run: done, failed, ETA."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.done, self.failed = total, 0, 0
        self.start = time.monotonic()
        self.enabled = enabled
        self.bar = None
        if enabled and sys.stderr.isatty():
            from tqdm import tqdm
            self.bar = tqdm(total=total, unit='run', file=sys.stderr, dynamic_ncols=True)

    def note(self, text: str) -> None:
        """A line on stderr (above the bar on a terminal)."""
        if self.bar is not None:
            self.bar.write(text, file=sys.stderr)
        else:
            print(text, file=sys.stderr, flush=True)

    def update(self, status: str) -> None:
        self.done += 1
        self.failed += status != 'ok'
        if self.bar is not None:
            self.bar.set_postfix(failed=self.failed, refresh=False)
            self.bar.update(1)
        elif self.enabled:
            elapsed = time.monotonic() - self.start
            eta = elapsed / self.done * (self.total - self.done)
            print(f'[sweep] {self.done}/{self.total} done, {self.failed} failed, '
                  f'ETA {eta:.0f} s', file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


CHUNK_MAX = 64  # runs per task at most


def chunk_size(runs: int, workers: int) -> int:
    """Runs per task: about four tasks per worker (the last ones balance the load), at most
    CHUNK_MAX runs (one engine batch each: multilift_control.engine)."""
    return max(1, min(CHUNK_MAX, math.ceil(runs / (4 * max(workers, 1)))))


def run_campaign(client, campaign: cp.Campaign, duration: float | None, bags: Path | None,
                 progress: Progress, rows: dict[int, dict]) -> None:
    """Submit the runs to `client` in chunks (`chunk_size`; `campaign.run_chunk` flies a
    chunk's runs as engine batches) and put each row in `rows` (index -> row) as its chunk
    finishes (a KeyboardInterrupt leaves the finished ones there)."""
    from concurrent.futures import CancelledError

    from distributed import as_completed

    # a lost scheduler is one line at the end (ClusterLost), not the client's reconnect traces
    logging.getLogger('distributed.client').setLevel(logging.CRITICAL)
    specs = {}
    futures = []
    tag = f'{os.getpid()}-{time.time_ns()}'
    runs = list(campaign.runs)
    size = chunk_size(len(runs), len(client.scheduler_info().get('workers', {})))
    for first in range(0, len(runs), size):
        chunk = runs[first:first + size]
        work = [(campaign.edits(run),
                 str(bags / f'run_{run.index:05d}') if bags is not None else None)
                for run in chunk]
        future = client.submit(cp.run_chunk, campaign.source, campaign.base, work, duration,
                               key=f'multilift-runs-{tag}-{chunk[0].index}', pure=False)
        specs[future.key] = chunk
        futures.append(future)
    pending = as_completed(futures)
    progress.note(f'[sweep] {len(runs)} run(s) submitted in {len(futures)} task(s)')
    progress.start = time.monotonic()   # the ETA counts from here, not the cluster's start
    del futures  # as_completed holds the only reference: a read result is released below
    for future in pending:
        chunk = specs.pop(future.key)
        try:
            results = future.result()
        except CancelledError as exc:   # not the runs' fault: no row, stop the campaign
            raise ClusterLost(f'runs {chunk[0].index}..{chunk[-1].index} were cancelled: '
                              f'{exc}') from None
        except Exception as exc:  # noqa: BLE001 - KilledWorker, a result that cannot unpickle
            results = [{'status': 'error', 'message': cp.error_message(exc),
                        **dict.fromkeys(cp.STATISTICS), 'wall_time': None, 'bag': None}
                       for _ in chunk]
        future.release()
        for run, result in zip(chunk, results):
            if run.index not in rows:
                rows[run.index] = cp.make_row(run, result)
                progress.update(result['status'])


def _probe(scheduler: str) -> None:
    """OSError at once when nothing listens at a tcp:// scheduler's address (Dask's client
    would retry a refused connection for its whole 10 s timeout); other addresses pass."""
    from urllib.parse import urlsplit
    address = urlsplit(scheduler)
    if address.scheme == 'tcp' and address.hostname and address.port:
        socket.create_connection((address.hostname, address.port), timeout=10).close()


def open_client(scheduler: str | None, workers: int):
    """(client, cluster or None): a connection to `scheduler`, or a local cluster of `workers`
    processes with one thread each on 127.0.0.1, no dashboard."""
    from distributed import Client, LocalCluster

    if scheduler is not None:
        _probe(scheduler)
        return Client(scheduler, timeout='10s'), None
    # the resource tracker that unlinks the nannies' semaphores should this process die: with
    # SIGHUP blocked (a mask it inherits) it outlives a closed terminal
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGHUP})
    try:
        resource_tracker.ensure_running()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    # the worker processes start with SIGINT ignored (a disposition they inherit): Ctrl-C on
    # a terminal reaches the whole process group, and this process stops them itself
    main = threading.current_thread() is threading.main_thread()
    old = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               host='127.0.0.1', dashboard_address=None,
                               silence_logs=logging.ERROR)
    finally:
        if main:
            signal.signal(signal.SIGINT, old)
    try:
        return Client(cluster), cluster
    except BaseException:   # Ctrl-C included: the cluster is closed here, not by nobody
        cluster.close(timeout=10)
        raise


def close_client(client, cluster) -> None:
    logging.getLogger('distributed').setLevel(logging.CRITICAL)  # the workers' goodbyes
    try:
        client.close(timeout=10)
    finally:
        if cluster is not None:
            cluster.close(timeout=10)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog='multilift sweep',
                                     description='a campaign of headless runs of a scenario '
                                                 '(grid and sampled) on a Dask cluster, one '
                                                 'table row per run')
    parser.add_argument('scenario', help='a name in scenarios/ or a YAML path')
    parser.add_argument('--set', dest='sets', action='append', default=[], metavar='KEY=V1,V2',
                        help='a dotted scenario key and its values (repeatable: the grid is '
                             'the cartesian product)')
    parser.add_argument('--sample', dest='samples_of', action='append', default=[],
                        metavar='KEY=DIST',
                        help='uniform(a,b), normal(mu,sigma) or choice(v1,v2,...) (repeatable)')
    parser.add_argument('--samples', type=int, help='draws per grid point (with --sample)')
    parser.add_argument('--seed', type=int, default=0, help='campaign seed (default 0)')
    where = parser.add_mutually_exclusive_group()
    where.add_argument('--scheduler', metavar='tcp://HOST:PORT',
                       help='a running Dask scheduler (default: a local cluster)')
    where.add_argument('--workers', '--jobs', dest='workers', type=int,
                       help='local worker processes (default: the number of CPUs)')
    parser.add_argument('--out', help='table: FILE.parquet or FILE.csv (default: CSV on stdout)')
    parser.add_argument('--bags', help='record each run to DIR/run_NNNNN (rosbag2, MCAP)')
    parser.add_argument('--duration', type=float, help='simulated seconds (default: scenario)')
    parser.add_argument('--no-progress', action='store_true', help='no progress on stderr')
    return parser


def _prepare_bags(bags: str | None) -> Path | None:
    """The bag directory, absolute; a non-empty one is moved aside to DIR.1, DIR.2, ..."""
    if bags is None:
        return None
    path = Path(bags).absolute()
    if path.exists() and any(path.iterdir()):
        k = 1
        while path.with_name(f'{path.name}.{k}').exists():
            k += 1
        path.rename(path.with_name(f'{path.name}.{k}'))
    path.mkdir(parents=True, exist_ok=True)
    return path


def sweep_main(argv: list[str] | None = None) -> int:
    """`multilift sweep ...`; returns the exit code (0 done, 1 no cluster, 2 bad input,
    130 interrupted)."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # argparse printed its one line
        return 0 if exc.code == 0 else 2
    try:
        if args.workers is not None and args.workers < 1:
            raise cp.SweepError(f'--workers: {args.workers} must be >= 1')
        if args.duration is not None and not (math.isfinite(args.duration)
                                              and args.duration > 0):
            raise cp.SweepError(f'--duration: {args.duration} must be > 0')
        if args.scheduler is not None and not args.scheduler.startswith(('tcp://', 'tls://')):
            raise cp.SweepError(f'--scheduler {args.scheduler}: expected tcp://HOST:PORT')
        source, base = cp.load_base(args.scenario)
        grid = [cp.parse_set(option) for option in args.sets]
        samples = [cp.parse_sample(option) for option in args.samples_of]
        campaign = cp.build_campaign(source, base, grid, samples, args.samples, args.seed)
    except (cp.SweepError, scenario_io.ScenarioError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    total = len(campaign.runs)
    workers = min(args.workers or os.cpu_count() or 1, total)
    bags = _prepare_bags(args.bags)
    on = args.scheduler or f'a local cluster of {workers} worker(s)'
    print(f'multilift sweep {Path(source).stem}: {total} run(s) on {on}', file=sys.stderr,
          flush=True)
    progress = Progress(total, not args.no_progress)
    interrupted = False
    lost = ''
    rows: dict[int, dict] = {}
    interrupts = _Interrupts()
    interrupts.install()
    client = cluster = None
    try:
        interrupts.holding = args.scheduler is None
        try:
            client, cluster = open_client(args.scheduler, workers)
        except (OSError, TimeoutError) as exc:
            print(f'error: cannot reach the Dask scheduler {args.scheduler}: {exc}',
                  file=sys.stderr)
            return 1
        except Exception:
            if interrupts.held:   # e.g. the workers hung up with us as they started
                raise KeyboardInterrupt from None
            raise
        interrupts.release()
        run_campaign(client, campaign, args.duration, bags, progress, rows)
    except KeyboardInterrupt:
        interrupted = True
    except ClusterLost as exc:
        lost = f'error: the Dask cluster went away mid-campaign ({exc})'.replace('\n', ' ')
    finally:
        progress.close()
        if client is not None:
            try:
                close_client(client, cluster)
            except (KeyboardInterrupt, Exception):  # noqa: BLE001 - leaving anyway
                pass
        interrupts.restore()
    columns = cp.table_columns(campaign, bags is not None)
    table = [rows[i] for i in sorted(rows)]
    if args.out:
        cp.write_table(Path(args.out), columns, table, campaign.metadata())
    else:
        sys.stdout.write(cp.table_text(columns, table))
        sys.stdout.flush()
    failed = sum(row['status'] != 'ok' for row in table)
    where = f' to {args.out}' if args.out else ''
    print(f'{len(table)} of {total} run(s) written{where}; {failed} failed (stopped or error)'
          + (' (interrupted)' if interrupted else ''), file=sys.stderr)
    if lost:
        print(lost, file=sys.stderr)
        return 1
    return 130 if interrupted else 0


if __name__ == '__main__':
    sys.exit(sweep_main())
