"""Sweep campaigns without an executor: parse --set and --sample, expand the grid, draw the
samples, fly one run, build and write the table. No Dask here (the executor is `sweep`), so
every piece is unit-testable and `run_one` is a plain top-level function a Dask scheduler and
its workers can unpickle by reference (its arguments are plain data: the scenario's YAML
mapping and the run's overrides).

KEY is a dotted path into the scenario's YAML (world frame, SI units, as the file), with list
indices in brackets: payload.mass, formation.alpha_vc, uavs[0].cable_length. A `uavs` list the
file does not have is made (formation.n empty entries) so that per-UAV keys can be set.

Runs: the cartesian product of the --set values (grid order: the last --set varies fastest),
each repeated for --samples N draws when --sample is given; run i (0-based, the table's input
order) draws its sampled values, in --sample order, from its own generator
`np.random.default_rng(seed_i)`, seed_i = the first 63 bits of
`np.random.SeedSequence(S).spawn(...)[i]` (the row's `seed` column): the same --seed gives the
same campaign on any cluster, in any completion order.
"""
from __future__ import annotations

import copy
import csv
import io
import itertools
import json
import math
import re
import shutil
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from multilift_sim import scenario as scenario_io
from multilift_sim.statistics import summary_row

# run statistics, in table order (`run_statistics_row`; units in the docstring of sweep)
STATISTICS = tuple(summary_row({}))
STATUSES = ('ok', 'stopped', 'error')
DISTRIBUTIONS = ('uniform', 'normal', 'choice')
_STEP = re.compile(r'([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$')
_SAMPLE = re.compile(r'\s*([A-Za-z_]+)\s*\((.*)\)\s*$', re.S)


class SweepError(ValueError):
    """Bad sweep input; the message is the one line printed."""


# ------------------------------------------------------------------------------------ input
def parse_key(key: str, option: str = '--set') -> list[str | int]:
    """'uavs[0].cable_length' -> ['uavs', 0, 'cable_length']."""
    path: list[str | int] = []
    for part in key.split('.'):
        match = _STEP.match(part)
        if not match:
            raise SweepError(f'{option} {key}: {part!r} is not a key (letters, digits, _ and '
                             '[index])')
        path.append(match.group(1))
        path += [int(i) for i in re.findall(r'\[(\d+)\]', match.group(2))]
    return path


def split_values(text: str) -> list[str]:
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


@dataclass(frozen=True)
class GridAxis:
    """One --set: a key and its values."""
    key: str
    path: tuple
    values: tuple


@dataclass(frozen=True)
class SampleSpec:
    """One --sample: a key and its distribution (uniform(a, b), normal(mu, sigma) or
    choice(v1, ...)), in the units of the key."""
    key: str
    path: tuple
    kind: str
    args: tuple

    def draw(self, rng: np.random.Generator) -> Any:
        """One value from `rng` (exactly one draw from the stream per spec)."""
        if self.kind == 'uniform':
            return float(rng.uniform(self.args[0], self.args[1]))
        if self.kind == 'normal':
            return float(rng.normal(self.args[0], self.args[1]))
        return self.args[int(rng.integers(len(self.args)))]

    def candidates(self) -> list[Any]:
        """Values to check the key with before anything runs (one must load)."""
        if self.kind == 'uniform':
            a, b = self.args
            return [(a + b) / 2, a, b]
        if self.kind == 'normal':
            return [self.args[0]]
        return list(self.args)

    def text(self) -> str:
        return f'{self.kind}({", ".join(format_value(a) for a in self.args)})'


def parse_set(option: str) -> GridAxis:
    """'payload.mass=0.4,0.8' -> GridAxis."""
    key, sep, values = option.partition('=')
    key = key.strip()
    if not sep or not key:
        raise SweepError(f'--set {option}: expected KEY=V1,V2,...')
    items = split_values(values)
    if not values.strip() or any(item == '' for item in items):
        raise SweepError(f'--set {option}: an empty value')
    return GridAxis(key, tuple(parse_key(key)), tuple(parse_value(item) for item in items))


def _number(option: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise SweepError(f'--sample {option}: {text.strip()!r} is not a number') from None
    if not math.isfinite(value):
        raise SweepError(f'--sample {option}: {text.strip()} is not finite')
    return value


def parse_sample(option: str) -> SampleSpec:
    """'payload.mass=uniform(0.4, 1.2)' -> SampleSpec (SweepError naming what is wrong)."""
    key, sep, dist = option.partition('=')
    key = key.strip()
    if not sep or not key:
        raise SweepError(f'--sample {option}: expected KEY=uniform(a,b), KEY=normal(mu,sigma) '
                         'or KEY=choice(v1,v2,...)')
    path = tuple(parse_key(key, '--sample'))
    match = _SAMPLE.match(dist)
    if not match or match.group(1) not in DISTRIBUTIONS:
        raise SweepError(f'--sample {option}: {dist.strip()!r} is not uniform(a,b), '
                         'normal(mu,sigma) or choice(v1,v2,...)')
    kind, inner = match.group(1), match.group(2)
    items = split_values(inner)
    if any(item == '' for item in items):
        raise SweepError(f'--sample {option}: an empty argument')
    if kind == 'choice':
        return SampleSpec(key, path, kind, tuple(parse_value(item) for item in items))
    if len(items) != 2:
        raise SweepError(f'--sample {option}: {kind} takes 2 numbers, got {len(items)}')
    a, b = (_number(option, item) for item in items)
    if kind == 'uniform' and not a < b:
        raise SweepError(f'--sample {option}: uniform(a,b) needs a < b')
    if kind == 'normal' and not b > 0:
        raise SweepError(f'--sample {option}: normal(mu,sigma) needs sigma > 0')
    return SampleSpec(key, path, kind, (a, b))


def apply_edit(data: dict, key: str, path, value: Any) -> None:
    """Set `value` at `path` in the YAML data (in place). Missing mappings are made (the
    loader then names an unknown key); a missing `uavs` list becomes formation.n entries."""
    node: Any = data
    for depth, step in enumerate(path[:-1]):
        nxt = path[depth + 1]
        if isinstance(step, int):
            if not isinstance(node, list):
                raise SweepError(f'{key}: {_where(path, depth)} is not a list')
            if step >= len(node):
                raise SweepError(f'{key}: index {step} is out of range ({len(node)} '
                                 f'entries in {_where(path, depth)})')
            if node[step] is None and not isinstance(nxt, int):
                node[step] = {}
            node = node[step]
            continue
        if not isinstance(node, dict):
            raise SweepError(f'{key}: {_where(path, depth)} is not a mapping')
        if step not in node or node[step] is None:
            if step == 'uavs' and depth == 0:
                formation = data.get('formation')
                n = formation.get('n', 1) if isinstance(formation, dict) else 1
                node[step] = [{} for _ in range(n if isinstance(n, int) and n > 0 else 1)]
            elif isinstance(nxt, int):
                raise SweepError(f'{key}: the scenario has no list {_where(path, depth + 1)}')
            else:
                node[step] = {}
        node = node[step]
    last = path[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise SweepError(f'{key}: index {last} is out of range')
        node[last] = value
    else:
        if not isinstance(node, dict):
            raise SweepError(f'{key}: {_where(path, len(path) - 1)} is not a mapping')
        node[last] = value


def _where(path, upto: int) -> str:
    text = ''
    for step in path[:upto]:
        text += f'[{step}]' if isinstance(step, int) else (f'.{step}' if text else step)
    return text or 'the top level'


def format_value(value: Any) -> str:
    """A parameter as the table and messages show it (lists and mappings as JSON)."""
    return json.dumps(value) if isinstance(value, (list, dict)) else str(value)


def edited(base: dict, edits: list[tuple[str, tuple, Any]]) -> dict:
    """A deep copy of `base` with every (key, path, value) applied."""
    data = copy.deepcopy(base)
    for key, path, value in edits:
        apply_edit(data, key, path, value)
    return data


# ------------------------------------------------------------------------------------ runs
@dataclass(frozen=True)
class RunSpec:
    """One run of a campaign: its index (input order), parameters (key -> value, --set keys
    then --sample keys) and its seed."""
    index: int
    params: dict = field(hash=False)
    seed: int


@dataclass(frozen=True)
class Campaign:
    """A checked campaign: the scenario's YAML mapping, its axes and its runs."""
    source: str
    base: dict = field(hash=False)
    grid: tuple
    samples: tuple
    seed: int
    runs: tuple

    @property
    def keys(self) -> list[str]:
        return [a.key for a in self.grid] + [s.key for s in self.samples]

    def edits(self, run: RunSpec) -> list[tuple[str, tuple, Any]]:
        paths = {a.key: a.path for a in self.grid} | {s.key: s.path for s in self.samples}
        return [(key, paths[key], value) for key, value in run.params.items()]

    def metadata(self) -> dict:
        """What the table's Parquet metadata says of the campaign (plot-sweep reads it)."""
        return {'scenario': self.source, 'seed': self.seed,
                'grid': {a.key: [format_value(v) for v in a.values] for a in self.grid},
                'sample': {s.key: s.text() for s in self.samples},
                'runs': len(self.runs)}


def run_seeds(seed: int, count: int) -> list[int]:
    """One 63-bit seed per run, spawned from `seed`: default_rng(seeds[i]) is run i's stream."""
    children = np.random.SeedSequence(seed).spawn(count)
    return [int(c.generate_state(1, np.uint64)[0] >> np.uint64(1)) for c in children]


def build_campaign(source: str, base: dict, grid: list[GridAxis], samples: list[SampleSpec],
                   n_samples: int | None, seed: int) -> Campaign:
    """Check the axes against the scenario loader and lay out every run (SweepError or
    ScenarioError, one line, on the first bad one). Grid points are checked whole; a sampled
    key is checked with representative values (the mean, the range's middle or ends, each
    choice: one must load), the drawn values only when their run starts (a rejected draw is
    that run's `error` row)."""
    keys = [a.key for a in grid] + [s.key for s in samples]
    dup = next((k for k in keys if keys.count(k) > 1), None)
    if dup is not None:
        raise SweepError(f'{dup}: given twice (list every value in one --set or --sample)')
    if samples and n_samples is None:
        raise SweepError('--sample needs --samples N (how many draws)')
    if n_samples is not None and not samples:
        raise SweepError('--samples without --sample: nothing to draw')
    if n_samples is not None and n_samples < 1:
        raise SweepError(f'--samples: {n_samples} must be >= 1')
    if not 0 <= seed < 2 ** 63:
        raise SweepError(f'--seed: {seed} must be in [0, 2^63)')
    points = list(itertools.product(*[a.values for a in grid]))
    for combo in points:
        edits = [(a.key, a.path, v) for a, v in zip(grid, combo)]
        _check(source, base, edits)
    for spec in samples:
        first_error = None
        for value in spec.candidates():
            try:
                _check(source, base, [(spec.key, spec.path, value)])
                break
            except (SweepError, scenario_io.ScenarioError) as exc:
                first_error = first_error or exc
        else:
            raise type(first_error)(f'--sample {spec.key}={spec.text()}: {first_error}')
    repeats = n_samples or 1
    seeds = run_seeds(seed, len(points) * repeats)
    runs = []
    for g, combo in enumerate(points):
        for j in range(repeats):
            index = g * repeats + j
            params = {a.key: v for a, v in zip(grid, combo)}
            rng = np.random.default_rng(seeds[index])
            params |= {s.key: s.draw(rng) for s in samples}
            runs.append(RunSpec(index, params, seeds[index]))
    return Campaign(source, base, tuple(grid), tuple(samples), seed, tuple(runs))


def _check(source: str, base: dict, edits) -> None:
    data = edited(base, edits)
    scenario_io.loads(yaml.safe_dump(data, sort_keys=False), _label(source, edits))


def _label(source: str, edits) -> str:
    if not edits:
        return source
    return f'{source} with ' + ', '.join(f'{k}={format_value(v)}' for k, _, v in edits)


def load_base(name_or_path: str) -> tuple[str, dict]:
    """The scenario file (by name or path) -> (its path as text, its YAML mapping)."""
    path = scenario_io.resolve(name_or_path)
    try:
        base = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise scenario_io.ScenarioError(f'{path}: not valid YAML: {exc}'
                                        .replace('\n', ' ')) from None
    if not isinstance(base, dict):
        raise scenario_io.ScenarioError(f'{path}: top level: expected a mapping')
    return str(path), base


# ------------------------------------------------------------------------------------ a run
def run_statistics_row(scenario, bag: Path | None = None) -> tuple[dict[str, Any], str]:
    """Fly `scenario` headless (recording to `bag` when given): (its statistics, keyed as
    STATISTICS, None where a figure does not apply; why it stopped, '' when it reached t_max).
    Other exceptions propagate. The one place a row's statistics come from: the run's summary
    through `multilift_sim.statistics.summary_row`, what `run` reports."""
    from multilift_control.headless import fly

    if bag is None:
        run = fly(scenario, raise_on_stop=False)
    else:
        from multilift_tools.headless_bag import record_headless
        run = record_headless(scenario, bag, raise_on_stop=False)
    return _statistics(run.summary()), run.error or ''


def _statistics(summary: dict) -> dict[str, Any]:
    return {k: _plain(v) for k, v in summary_row(summary).items()}


def _plain(value: Any) -> Any:
    """numpy scalars as Python numbers (the table's types), non-finite as None."""
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _scenario(source: str, base: dict, edits: list, duration: float | None):
    """The run's scenario: the base with its edits (checked by the loader) and duration."""
    data = edited(base, [tuple(e) for e in edits])
    scenario = scenario_io.loads(yaml.safe_dump(data, sort_keys=False), _label(source, edits))
    return scenario if duration is None else scenario.with_duration(duration)


def _result(stats: dict | None = None, stopped: str = '', error: BaseException | None = None,
            wall_time: float | None = None, bag: str | None = None) -> dict[str, Any]:
    """A run's result {status, message, STATISTICS..., wall_time, bag}."""
    out: dict[str, Any] = {'status': 'ok', 'message': '', **dict.fromkeys(STATISTICS)}
    if stats is not None:
        out.update(stats)
    if stopped:
        out.update(status='stopped', message=stopped)
    if error is not None:
        out.update(status='error', message=error_message(error))
    out['message'] = out['message'].replace('\n', ' ')
    out['wall_time'] = None if wall_time is None else round(wall_time, 3)
    out['bag'] = bag
    return out


def run_one(source: str, base: dict, edits: list, duration: float | None = None,
            bag: str | None = None) -> dict[str, Any]:
    """One run, never raising for the run's own faults: {status, message, STATISTICS...,
    wall_time, bag}. `edits` are (key, path, value) for `apply_edit`; the drawn values are
    checked here (a rejected value is status `error` with the loader's line). A top-level
    function with plain arguments: what a Dask worker unpickles."""
    start = time.perf_counter()
    try:
        scenario = _scenario(source, base, edits, duration)
        bag_path = None
        if bag is not None:
            bag_path = Path(bag)
            if bag_path.exists():  # a partial bag of this run from a worker that died
                shutil.rmtree(bag_path)
            bag_path.parent.mkdir(parents=True, exist_ok=True)
        stats, stopped = run_statistics_row(scenario, bag_path)
    except Exception as exc:  # noqa: BLE001 - one run's crash is that row's error
        return _result(error=exc, wall_time=time.perf_counter() - start, bag=bag)
    return _result(stats, stopped, wall_time=time.perf_counter() - start, bag=bag)


def run_chunk(source: str, base: dict, runs: list[tuple[list, str | None]],
              duration: float | None = None) -> list[dict[str, Any]]:
    """Several runs in one task, each result as `run_one`'s (in `runs` order): the runs
    without a bag flown together, one engine batch per shape of formation
    (`multilift_control.headless.fly_batch`: a batch gives each formation the numbers it gets
    alone), a run's wall time its share of its batch's; runs with a bag, and what the engine
    does not fly (`engine.arrays.not_flown`), one by one. `runs`:
    (edits, bag or None) each. A batch that raises is flown again run by run, so a fault is
    the row of the run that has it."""
    from multilift_control.engine.arrays import engine_flies, shape_groups
    from multilift_control.headless import fly_batch

    results: list[dict[str, Any] | None] = [None] * len(runs)
    flights = []  # (position in runs, scenario)
    for k, (edits, bag) in enumerate(runs):
        if bag is not None:
            results[k] = run_one(source, base, edits, duration, bag)
            continue
        start = time.perf_counter()
        try:
            scenario = _scenario(source, base, edits, duration)
        except Exception as exc:  # noqa: BLE001 - a rejected value is that row's error
            results[k] = _result(error=exc, wall_time=time.perf_counter() - start)
            continue
        if engine_flies(scenario):
            flights.append((k, scenario))
        else:  # another integrator: tick by tick
            results[k] = run_one(source, base, edits, duration)
    for group in shape_groups([scenario for _, scenario in flights]):
        members = [flights[i] for i in group]
        start = time.perf_counter()
        try:
            flown = fly_batch([scenario for _, scenario in members])
        except Exception:  # noqa: BLE001 - find the run at fault: one by one
            for k, _ in members:
                results[k] = run_one(source, base, runs[k][0], duration)
            continue
        share = (time.perf_counter() - start) / len(members)
        for (k, _), run in zip(members, flown):
            results[k] = _result(_statistics(run.summary()), run.error or '', wall_time=share)
    return results


def error_message(exc: BaseException) -> str:
    """One line: the exception's type and text, and where it was raised (file:line)."""
    where = ''
    tb = traceback.extract_tb(exc.__traceback__) if exc.__traceback__ else []
    if tb and not isinstance(exc, (scenario_io.ScenarioError, SweepError)):
        frame = tb[-1]
        where = f' (at {Path(frame.filename).name}:{frame.lineno})'
    return f'{type(exc).__name__}: {exc}{where}'.replace('\n', ' ')


# ------------------------------------------------------------------------------------ table
def table_columns(campaign: Campaign, bags: bool) -> list[str]:
    """run, the parameters, seed, status, message, the statistics, wall_time[, bag]."""
    return ['run', *campaign.keys, 'seed', 'status', 'message', *STATISTICS, 'wall_time',
            *(['bag'] if bags else [])]


def make_row(run: RunSpec, result: dict[str, Any]) -> dict[str, Any]:
    """A table row from a run's spec and `run_one`'s result."""
    return {'run': run.index, **run.params, 'seed': run.seed, **result}


def table_text(columns: list[str], rows: list[dict]) -> str:
    """CSV: floats in full precision (repr), None as an empty field, lists as JSON."""
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator='\n')
    writer.writerow(columns)
    for row in rows:
        writer.writerow([_csv_cell(row.get(c)) for c in columns])
    return stream.getvalue()


def _csv_cell(value: Any) -> str:
    if value is None:
        return ''
    if isinstance(value, float):
        return repr(value)
    return format_value(value)


def write_table(path: Path, columns: list[str], rows: list[dict],
                metadata: dict | None = None) -> None:
    """Parquet (pyarrow) when `path` ends in .parquet, CSV otherwise; rows as given."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix != '.parquet':
        path.write_text(table_text(columns, rows))
        return
    import pyarrow as pa
    import pyarrow.parquet as pq
    arrays = [_arrow_column(pa, [row.get(c) for row in rows]) for c in columns]
    table = pa.Table.from_arrays(arrays, names=columns)
    if metadata is not None:
        table = table.replace_schema_metadata({'multilift.campaign': json.dumps(metadata)})
    pq.write_table(table, path)


def _arrow_column(pa, values: list):
    """int64, float64, bool or string (lists and mixed kinds as their JSON text)."""
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return pa.array(values, pa.bool_())
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return pa.array(values, pa.int64())
    if present and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                       for v in present):
        return pa.array([None if v is None else float(v) for v in values], pa.float64())
    return pa.array([None if v is None else format_value(v) for v in values], pa.string())


def read_table(path: Path) -> tuple[list[str], list[dict], dict]:
    """(columns, rows, campaign metadata or {}) of a sweep table, Parquet or CSV (CSV cells:
    numbers where they parse, '' as None)."""
    if path.suffix == '.parquet':
        import pyarrow.parquet as pq
        table = pq.read_table(path)
        meta = (table.schema.metadata or {}).get(b'multilift.campaign')
        return table.column_names, table.to_pylist(), json.loads(meta) if meta else {}
    with path.open(newline='') as stream:
        reader = csv.DictReader(stream)
        rows = [{k: _csv_value(v) for k, v in row.items()} for row in reader]
        return list(reader.fieldnames or []), rows, {}


def _csv_value(text: str | None) -> Any:
    if text is None or text == '':
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text
