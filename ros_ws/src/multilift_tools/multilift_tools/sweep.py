"""`multilift sweep`: many headless runs of one scenario over a grid of parameter values.

    multilift sweep SCENARIO --set KEY=V1,V2,... [--set KEY2=...] [--jobs N] [--out FILE.csv]
                    [--duration S]

KEY is a dotted path into the scenario's YAML (world frame, SI units, as the file), with list
indices in brackets: payload.mass, formation.alpha_vc, simulation.baumgarte_alpha,
vehicle.mass, uavs[0].cable_length, mission.segments[1].duration. A `uavs` list the file does
not have is made (formation.n empty entries) so that per-UAV keys can be set. Values are
numbers, true/false, strings, or YAML lists in brackets (vehicle.inertia=[1,1,2],[1,1,3]).
Every variant (the cartesian product of the --set values) is applied to the YAML data and
checked by the scenario loader before anything runs: a typo or a bad value is one line on
stderr and exit code 2.

The variants run headless (`multilift_control.headless.run_headless`: the simulator core and
every controller in one process, the same laws and tick order as the ROS stack) in `--jobs`
worker processes (default: the number of CPUs; each with one BLAS thread unless
OPENBLAS_NUM_THREADS is set), with a progress bar on stderr. Ctrl-C or SIGTERM stops the
workers and writes the rows finished so far. The CSV (FILE, or
stdout) has one row per variant, in the order of the product, with the parameters and:
simulated_time [s], max_abs_g [m^2], max_abs_g_dot [m^2/s], max_rotor_speed [rad/s] (over
every UAV), saturated_time [s] (summed over the UAVs), min_tension/max_tension [N],
tracking_error_max/tracking_error_rms [m] (leader against the mission reference, every tick;
empty without a mission path), formation_error_max (largest |g_vc| of any follower row, m or
m^2) and formation_error_mean (mean over ticks and followers of the norm of its rows, as the
follower node reports; empty for n = 1), wall_time [s], error (why the run stopped, empty if
it reached t_max; the figures then cover the time flown).

Exit codes: 0 every variant ran (stopped ones are rows with an error), 2 bad input,
130 interrupted (the rows finished so far are written).
"""
from __future__ import annotations

import argparse
import copy
import csv
import io
import itertools
import json
import math
import multiprocessing
import os
import re
import signal
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import yaml

from multilift_sim import scenario as scenario_io

METRICS = ('simulated_time', 'max_abs_g', 'max_abs_g_dot', 'max_rotor_speed', 'saturated_time',
           'min_tension', 'max_tension', 'tracking_error_max', 'tracking_error_rms',
           'formation_error_max', 'formation_error_mean', 'wall_time', 'error')

BLAS_THREAD_VARIABLES = ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS')
_STEP = re.compile(r'([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$')


class SweepError(ValueError):
    """Bad sweep input; the message is the one line printed."""


# ------------------------------------------------------------------------------------ input
def parse_key(key: str) -> list[str | int]:
    """'uavs[0].cable_length' -> ['uavs', 0, 'cable_length']."""
    path: list[str | int] = []
    for part in key.split('.'):
        match = _STEP.match(part)
        if not match:
            raise SweepError(f'--set {key}: {part!r} is not a key (letters, digits, _ and '
                             '[index])')
        path.append(match.group(1))
        path += [int(i) for i in re.findall(r'\[(\d+)\]', match.group(2))]
    return path


def _split_values(text: str) -> list[str]:
    """Split at commas outside brackets: '1,[1,2,3],x' -> ['1', '[1,2,3]', 'x']."""
    items, depth, current = [], 0, ''
    for ch in text:
        if ch == ',' and depth == 0:
            items.append(current)
            current = ''
            continue
        depth += {'[': 1, ']': -1}.get(ch, 0)
        current += ch
    items.append(current)
    return [item.strip() for item in items]


def parse_value(text: str) -> Any:
    """A number (1e-3 too), true/false, a YAML list, or the string itself."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError:
        return text


def parse_set(option: str) -> tuple[str, list[str | int], list[Any]]:
    """'payload.mass=0.4,0.8' -> (key, path, values)."""
    key, sep, values = option.partition('=')
    key = key.strip()
    if not sep or not key:
        raise SweepError(f'--set {option}: expected KEY=V1,V2,...')
    items = _split_values(values)
    if not values.strip() or any(item == '' for item in items):
        raise SweepError(f'--set {option}: an empty value')
    return key, parse_key(key), [parse_value(item) for item in items]


def apply_edit(data: dict, key: str, path: list[str | int], value: Any) -> None:
    """Set `value` at `path` in the YAML data (in place). Missing mappings are made (the
    loader then names an unknown key); a missing `uavs` list becomes formation.n entries."""
    node: Any = data
    for depth, step in enumerate(path[:-1]):
        nxt = path[depth + 1]
        if isinstance(step, int):
            if not isinstance(node, list):
                raise SweepError(f'--set {key}: {_where(path, depth)} is not a list')
            if step >= len(node):
                raise SweepError(f'--set {key}: index {step} is out of range ({len(node)} '
                                 f'entries in {_where(path, depth)})')
            if node[step] is None and not isinstance(nxt, int):
                node[step] = {}
            node = node[step]
            continue
        if not isinstance(node, dict):
            raise SweepError(f'--set {key}: {_where(path, depth)} is not a mapping')
        if step not in node or node[step] is None:
            if step == 'uavs' and depth == 0:
                formation = data.get('formation')
                n = formation.get('n', 1) if isinstance(formation, dict) else 1
                node[step] = [{} for _ in range(n if isinstance(n, int) and n > 0 else 1)]
            elif isinstance(nxt, int):
                raise SweepError(f'--set {key}: the scenario has no list '
                                 f'{_where(path, depth + 1)}')
            else:
                node[step] = {}
        node = node[step]
    last = path[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise SweepError(f'--set {key}: index {last} is out of range')
        node[last] = value
    else:
        if not isinstance(node, dict):
            raise SweepError(f'--set {key}: {_where(path, len(path) - 1)} is not a mapping')
        node[last] = value


def _where(path: list[str | int], upto: int) -> str:
    text = ''
    for step in path[:upto]:
        text += f'[{step}]' if isinstance(step, int) else (f'.{step}' if text else step)
    return text or 'the top level'


def _fmt_value(value: Any) -> str:
    return json.dumps(value) if isinstance(value, (list, dict)) else str(value)


def build_variants(source: str, base: dict, sets: list[tuple[str, list, list]],
                   duration: float | None) -> list[tuple[dict[str, Any], str, str]]:
    """[(parameters, YAML text, where)] for the product of the --set values, each checked by
    the scenario loader (ScenarioError or SweepError on the first bad one)."""
    keys = [key for key, _, _ in sets]
    if len(set(keys)) != len(keys):
        dup = next(k for k in keys if keys.count(k) > 1)
        raise SweepError(f'--set {dup}: given twice (list every value in one --set)')
    variants = []
    for combo in itertools.product(*[values for _, _, values in sets]):
        data = copy.deepcopy(base)
        params = {}
        for (key, path, _), value in zip(sets, combo):
            apply_edit(data, key, path, value)
            params[key] = value
        where = f'{source} with ' + ', '.join(f'{k}={_fmt_value(v)}' for k, v in params.items()) \
            if params else source
        text = yaml.safe_dump(data, sort_keys=False)
        scenario_io.loads(text, where)   # raises ScenarioError naming the key
        variants.append((params, text, where))
    return variants


# ------------------------------------------------------------------------------------ a run
def run_variant(text: str, where: str, duration: float | None = None) -> dict[str, Any]:
    """Fly one scenario headless; the figures of a CSV row (METRICS, from
    `multilift_sim.statistics.summary_row`: the same as `run` reports)."""
    from multilift_control.headless import run_headless
    from multilift_sim.statistics import summary_row

    scenario = scenario_io.loads(text, where)
    if duration is not None:
        scenario = replace(scenario, simulation=replace(scenario.simulation, duration=duration))
    row: dict[str, Any] = {k: '' for k in METRICS}
    start = time.perf_counter()
    try:
        run = run_headless(scenario, raise_on_stop=False)
    except Exception as exc:  # noqa: BLE001 - one variant's crash is that row's error
        row.update(wall_time=round(time.perf_counter() - start, 3),
                   error=f'{type(exc).__name__}: {exc}'.replace('\n', ' '))
        return row
    row.update({k: v for k, v in summary_row(run.summary()).items()
                if k in METRICS and v is not None})
    row.update(wall_time=round(run.wall_time, 3), error=(run.error or '').replace('\n', ' '))
    return row


def _run_indexed(job: tuple[int, str, str, float | None]) -> tuple[int, dict[str, Any]]:
    index, text, where, duration = job
    return index, run_variant(text, where, duration)


def _worker_init() -> None:
    """Workers leave Ctrl-C and SIGTERM to the parent, which stops them."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


# ------------------------------------------------------------------------------------ output
def write_csv(stream, keys: list[str], variants, rows: dict[int, dict]) -> None:
    writer = csv.writer(stream, lineterminator='\n')
    writer.writerow([*keys, *METRICS])
    for index, (params, _, _) in enumerate(variants):
        if index in rows:
            row = rows[index]
            writer.writerow([*(_fmt_value(params[k]) for k in keys),
                             *(_csv_number(row[m]) for m in METRICS)])


def _csv_number(value: Any) -> str:
    if isinstance(value, float):
        return repr(value)
    return str(value)


class _Progress:
    """tqdm on stderr when it is there, else a line per finished run."""

    def __init__(self, total: int, enabled: bool):
        self.total = total
        self.done = 0
        self.bar = None
        self.enabled = enabled
        if enabled:
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit='run', file=sys.stderr, dynamic_ncols=True)
            except ImportError:
                self.bar = None

    def update(self, stopped: int) -> None:
        self.done += 1
        if self.bar is not None:
            self.bar.set_postfix(stopped=stopped, refresh=False)
            self.bar.update(1)
        elif self.enabled:
            print(f'  {self.done}/{self.total} runs', file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


# ------------------------------------------------------------------------------------ main
def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog='multilift sweep',
                                     description='headless runs of a scenario over a grid of '
                                                 'parameter values, one CSV row per run')
    parser.add_argument('scenario', help='a name in scenarios/ or a YAML path')
    parser.add_argument('--set', dest='sets', action='append', default=[], metavar='KEY=V1,V2',
                        help='a dotted scenario key and its values (repeatable: the runs are '
                             'the cartesian product)')
    parser.add_argument('--jobs', type=int, default=os.cpu_count() or 1,
                        help='parallel processes (default: the number of CPUs)')
    parser.add_argument('--out', help='CSV file (default: stdout)')
    parser.add_argument('--duration', type=float, help='simulated seconds (default: scenario)')
    parser.add_argument('--no-progress', action='store_true', help='no progress bar')
    return parser


def sweep_main(argv: list[str] | None = None) -> int:
    """`multilift sweep ...`; returns the exit code (0 done, 2 bad input, 130 interrupted)."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # argparse printed its one line
        return 0 if exc.code == 0 else 2
    try:
        if args.jobs < 1:
            raise SweepError(f'--jobs: {args.jobs} must be >= 1')
        if args.duration is not None and not (math.isfinite(args.duration)
                                              and args.duration > 0):
            raise SweepError(f'--duration: {args.duration} must be > 0')
        path = scenario_io.resolve(args.scenario)
        try:
            base = yaml.safe_load(path.read_text())
        except yaml.YAMLError as exc:
            raise scenario_io.ScenarioError(f'{path}: not valid YAML: {exc}'
                                            .replace('\n', ' ')) from None
        if not isinstance(base, dict):
            raise scenario_io.ScenarioError(f'{path}: top level: expected a mapping')
        sets = [parse_set(option) for option in args.sets]
        variants = build_variants(str(path), base, sets, args.duration)
    except (SweepError, scenario_io.ScenarioError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    keys = [key for key, _, _ in sets]
    jobs = min(args.jobs, len(variants))
    print(f'multilift sweep {path.stem}: {len(variants)} run(s) in {jobs} process(es)',
          file=sys.stderr, flush=True)
    rows: dict[int, dict] = {}
    progress = _Progress(len(variants), not args.no_progress)
    stopped = 0
    interrupted = False
    old_term = signal.signal(signal.SIGTERM, _interrupt)  # unattended: SIGTERM as Ctrl-C
    pool = None
    try:
        if jobs == 1:
            for index, (_, text, where) in enumerate(variants):
                rows[index] = run_variant(text, where, args.duration)
                stopped += bool(rows[index]['error'])
                progress.update(stopped)
        else:
            # fresh worker processes with one BLAS thread each (unless the caller set it):
            # --jobs processes already use the cores, and oversubscribed OpenBLAS threads made
            # the numpy kernel (n > 20) an order of magnitude slower on a busy machine
            saved = {var: os.environ.get(var) for var in BLAS_THREAD_VARIABLES}
            for var in BLAS_THREAD_VARIABLES:
                os.environ.setdefault(var, '1')
            try:
                pool = multiprocessing.get_context('spawn').Pool(jobs, initializer=_worker_init)
            finally:
                for var, value in saved.items():
                    if value is None:
                        os.environ.pop(var, None)
                    else:
                        os.environ[var] = value
            work = [(i, text, where, args.duration) for i, (_, text, where) in enumerate(variants)]
            for index, row in pool.imap_unordered(_run_indexed, work):
                rows[index] = row
                stopped += bool(row['error'])
                progress.update(stopped)
            pool.close()
    except KeyboardInterrupt:
        interrupted = True
    finally:
        if pool is not None:
            if interrupted:
                pool.terminate()
            pool.join()
        signal.signal(signal.SIGTERM, old_term)
        progress.close()
    text = io.StringIO()
    write_csv(text, keys, variants, rows)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text.getvalue())
    else:
        sys.stdout.write(text.getvalue())
        sys.stdout.flush()
    where = f' to {args.out}' if args.out else ''
    print(f'{len(rows)} of {len(variants)} run(s) written{where}; {stopped} stopped early'
          + (' (interrupted)' if interrupted else ''), file=sys.stderr)
    return 130 if interrupted else 0


if __name__ == '__main__':
    sys.exit(sweep_main())
