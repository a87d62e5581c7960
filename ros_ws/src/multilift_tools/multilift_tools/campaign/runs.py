"""The runs of a campaign, flown headless: one run (`run_one`, what a Dask worker unpickles: a
top-level function with plain arguments) or a task's runs as engine batches (`run_chunk`), each
a result {status, message, STATISTICS..., wall_time, bag} and never raising for the run's own
faults.

wall_time [s] is what the run cost its worker: loading its scenario and flying it (its share
of an engine batch's flight, the batch's time over its runs), with its bag written when it has
one. A worker's first flight of each kind (engine batch, tick by tick, recorded) also loads
the compiled code from numba's cache, about 0.4 s that is no run's own: each worker pays it
once, untimed, before its first timed run (`warm_up`), so that the first run a worker flies
does not report 0.4 s more than the rest (issue 37: 0.6 s against 0.035 s).
"""
from __future__ import annotations

import math
import shutil
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any

import numpy as np

from multilift_sim import scenario as scenario_io
from multilift_sim.statistics import summary_row
from multilift_tools.campaign.spec import SweepError, _label, edited

# run statistics, in table order (`run_statistics_row`; units: multilift_sim.units)
STATISTICS = tuple(summary_row({}))
STATUSES = ('ok', 'stopped', 'error')


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
    scenario = scenario_io.from_mapping(data, _label(source, edits))
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


_WARM: set[str] = set()   # the kinds of flight this process has flown once already


def warm_up(kind: str, scenario, bag: bool = False) -> None:
    """Once per process and `kind` ('engine', 'ticks'): fly one control period of `scenario`
    that way (with a bag to a temporary directory when `bag`), untimed and unreported, so the
    loading of the compiled code falls on no run's wall_time. A fault here is left to the
    timed run to report."""
    key = kind + ('+bag' if bag else '')
    if key in _WARM:
        return
    _WARM.add(key)
    short = scenario.with_duration(1.0 / scenario.simulation.control_rate)
    try:
        if kind == 'engine':
            from multilift_control.headless import fly_batch
            fly_batch([short])
        elif bag:
            with tempfile.TemporaryDirectory(prefix='multilift-warm-') as where:
                run_statistics_row(short, Path(where) / 'bag')
        else:
            run_statistics_row(short)
    except Exception:  # noqa: BLE001,S110 - the run itself reports what is wrong
        pass


def run_one(source: str, base: dict, edits: list, duration: float | None = None,
            bag: str | None = None) -> dict[str, Any]:
    """One run, never raising for the run's own faults: {status, message, STATISTICS...,
    wall_time, bag}. `edits` are (key, path, value) for `apply_edit`; the drawn values are
    checked here (a rejected value is status `error` with the loader's line). A top-level
    function with plain arguments: what a Dask worker unpickles."""
    try:
        warm_up('ticks', _scenario(source, base, edits, duration), bag is not None)
    except Exception:  # noqa: BLE001,S110 - reported below, timed
        pass
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
    alone), a run's wall time its scenario's loading and its share of its batch's flight (the
    worker's first batch warmed up untimed: `warm_up`); runs with a bag one by one. `runs`:
    (edits, bag or None) each. A batch that raises is flown again run by run, so a fault is
    the row of the run that has it."""
    from multilift_control.engine.arrays import shape_groups
    from multilift_control.headless import fly_batch

    results: list[dict[str, Any] | None] = [None] * len(runs)
    flights = []  # (position in runs, scenario)
    loading = {}  # position in runs -> its scenario's loading time [s]
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
        loading[k] = time.perf_counter() - start
        flights.append((k, scenario))
    for group, fields in shape_groups([scenario for _, scenario in flights]):
        members = [flights[i] for i in group]
        warm_up('engine', members[0][1])
        start = time.perf_counter()
        try:
            flown = fly_batch([scenario for _, scenario in members], fields)
        except Exception:  # noqa: BLE001 - find the run at fault: one by one
            for k, _ in members:
                results[k] = run_one(source, base, runs[k][0], duration)
            continue
        share = (time.perf_counter() - start) / len(members)
        for (k, _), run in zip(members, flown):
            results[k] = _result(_statistics(run.summary()), run.error or '',
                                 wall_time=loading[k] + share)
    return results


def error_message(exc: BaseException) -> str:
    """One line: the exception's type and text, and where it was raised (file:line)."""
    where = ''
    tb = traceback.extract_tb(exc.__traceback__) if exc.__traceback__ else []
    if tb and not isinstance(exc, (scenario_io.ScenarioError, SweepError)):
        frame = tb[-1]
        where = f' (at {Path(frame.filename).name}:{frame.lineno})'
    return f'{type(exc).__name__}: {exc}{where}'.replace('\n', ' ')
