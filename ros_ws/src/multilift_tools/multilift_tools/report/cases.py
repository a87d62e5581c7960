"""The cases of `multilift reproduce`, one worker process each (spawned), longest first: the
twin-lift and the "V" of three flying the §4.2 mission (bags), the V again in still air (how far
the gusts move its payload), the single-lift table (single_lift.single_lift_table: release,
modal, periods, Baumgarte study, static tension), the single-lift swing (bag, Fig. 4.1) and the
twin-lift and V modal analyses. `run_cases` runs them in a pool, with a line of progress the
parent reads from the workers' files. Times [s].
"""
from __future__ import annotations

import concurrent.futures as futures
import dataclasses
import json
import multiprocessing
import shutil
import sys
import time
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from multilift_sim.physics.layout import seed_coordinates
from multilift_sim.scenario import load
from multilift_tools.report.seed import MULTI, SWING, TWIN
from multilift_tools.report.single_lift import single_lift_table

CASES = ('twin_lift', 'multi_lift', 'multi_lift_still_air', 'single_lift_table',
         'single_lift_swing', 'modal', 'swing_feedback', 'load_sharing')


class _ProgressFile:
    """A worker's progress, one line 'done total' in a file the parent polls."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def __call__(self, done: float, total: float) -> None:
        tmp = self.path.with_suffix('.tmp')
        tmp.write_text(f'{done} {total}')
        tmp.replace(self.path)


def _ticker(progress: _ProgressFile, total: float) -> Callable[..., None]:
    """An on_tick for run_headless reporting simulated time."""
    def on_tick(sim: Any, *_: Any) -> None:
        if sim.tick % 200 == 0 or sim.finished:
            progress(sim.t, total)
    return on_tick


def _record(name: str, bag: Path, progress: _ProgressFile) -> dict:
    """Fly scenario `name` headless into `bag` with its summary.json (as `run --headless`)."""
    from multilift_tools.headless_bag import record_headless

    scenario = load(name)
    if bag.exists():
        shutil.rmtree(bag)
    bag.parent.mkdir(parents=True, exist_ok=True)
    run = record_headless(scenario, bag, progress)  # progress(t, t_max) every chunk of ticks
    (bag / 'summary.json').write_text(json.dumps(run.summary(), indent=1, sort_keys=True))
    return {'bag': str(bag), 'wall_time': run.wall_time}


def _still_air(name: str, progress: _ProgressFile) -> dict:
    """The scenario without its gusts: payload positions at every tick (t, (T, 3))."""
    from multilift_control.headless import run_headless

    scenario = dataclasses.replace(load(name), gusts=())
    report = _ticker(progress, scenario.simulation.duration)
    times, payload = [], []

    def tick(sim: Any, snap: Any, answers: list) -> None:
        times.append(sim.t)
        payload.append(snap.payload_position)
        report(sim)

    run_headless(scenario, tick)
    return {'t': np.array(times), 'payload': np.array(payload)}


def _modal_case(figures: Path, progress: _ProgressFile) -> dict:
    """Modal analyses of the twin-lift (Fig. 2.12) and the V at their Eq. 2.73 equilibria."""
    from multilift_sim.formation_params import StateLayout
    from multilift_sim.analysis.coordinates import coordinate_names
    from multilift_sim.analysis.modal import scenario_modal_analysis
    from multilift_tools.modal_cli import plot_eigenvalues

    out = {}
    for k, name in enumerate((TWIN, MULTI)):
        progress(k, 2)
        analysis = scenario_modal_analysis(load(name))
        if name == TWIN:
            plot_eigenvalues(analysis, figures / 'fig2_12_twin_lift_eigenvalues.png',
                             'twin_lift: eigenvalues, linearised at rest, open loop '
                             '(seed Fig. 2.12)')
        n = analysis.params.n_uavs
        euler = StateLayout(n).uav_euler(analysis.equilibrium.state)
        tilt = np.degrees(np.arccos(np.cos(euler[:, 0]) * np.cos(euler[:, 1])))
        names = coordinate_names(n)
        out[name] = {'periods': [float(p) for p in analysis.pendulum_periods],
                     'rigid': analysis.rigid_count,
                     'unstable': len(analysis.indices('unstable')),
                     'free': int(analysis.basis.shape[1]), 'coordinates': seed_coordinates(n),
                     'dependent': [names[k] for k in analysis.dependent],
                     'tilt_deg': [float(t) for t in tilt],
                     'tensions': [float(t) for t in analysis.equilibrium.tensions]}
    progress(2, 2)
    return out


def _table_case(study_dir: Path, progress: _ProgressFile) -> dict:
    """single_lift_table, its Baumgarte study written to `study_dir` (Fig. 4.2, 4.3)."""
    progress(0, 1)
    rows = single_lift_table(study_dir)
    progress(1, 1)
    return {'rows': rows}


def _swing_feedback_case(study_dir: Path, figure_dir: Path, progress: _ProgressFile) -> dict:
    """Beyond the seed (issue 20): `multilift study swing_feedback` written to `study_dir`, its
    figures copied to `figure_dir` as swing_feedback_<mission>.png."""
    from multilift_control.controllers import swing_period
    from multilift_tools.swing_study import swing_feedback_study

    progress(0, 1)
    study = swing_feedback_study(study_dir)
    figure_dir.mkdir(parents=True, exist_ok=True)
    figures = []
    for mission in study['rows']:
        source = Path(study['files'][mission])
        shutil.copyfile(source, figure_dir / source.name)
        figures.append(source.name)
    progress(1, 1)
    periods = {mission: swing_period(load(mission)) for mission in study['rows']}
    return {'table': study['table'], 'rows': study['rows'], 'figures': figures,
            'periods': periods}


def _load_sharing_case(study_dir: Path, figure_dir: Path, progress: _ProgressFile) -> dict:
    """Beyond the seed (issue 35): `multilift study load_sharing` written to `study_dir`, its
    figure copied to `figure_dir` as load_sharing.png."""
    from multilift_tools.load_study import load_sharing_study

    progress(0, 1)
    study = load_sharing_study(study_dir)
    figure_dir.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(study['files']['figure'], figure_dir / 'load_sharing.png')
    progress(1, 1)
    return {'table': study['table'], 'rows': study['rows']}


def run_case(case: str, work: str, figures: str) -> dict:
    """Run one case of CASES in this process; `work` holds bags and progress files. Returns
    what the report needs (picklable), with 'wall_time' [s]."""
    work_dir, figure_dir = Path(work), Path(figures)
    progress = _ProgressFile(work_dir / 'progress' / case)
    start = time.monotonic()
    if case in (TWIN, MULTI, SWING):
        result = _record(case, work_dir / 'bags' / case, progress)
    elif case == 'multi_lift_still_air':
        result = _still_air(MULTI, progress)
    elif case == 'single_lift_table':
        result = _table_case(work_dir / 'baumgarte', progress)
    elif case == 'modal':
        result = _modal_case(figure_dir, progress)
    elif case == 'swing_feedback':
        result = _swing_feedback_case(work_dir / 'swing_feedback', figure_dir, progress)
    elif case == 'load_sharing':
        result = _load_sharing_case(work_dir / 'load_sharing', figure_dir, progress)
    else:
        raise ValueError(f'unknown case {case!r}')
    result['wall_time'] = time.monotonic() - start
    return result


class ProgressBoard:
    """Per-case progress from the workers' files: one redrawn line on a terminal, else a line
    per case at every quarter and at the end."""

    def __init__(self, cases: Sequence[str], directory: Path, tty: bool) -> None:
        self.cases, self.directory, self.tty = list(cases), directory, tty
        self.quarters = {c: -1 for c in cases}
        self.done: dict[str, float] = {}
        self.start = time.monotonic()

    def fraction(self, case: str) -> float:
        """How far `case` is, 0..1, from its progress file."""
        if case in self.done:
            return 1.0
        try:
            done, total = (float(v) for v in (self.directory / case).read_text().split())
        except (OSError, ValueError):
            return 0.0
        return min(1.0, done / total) if total > 0 else 0.0

    def finished(self, case: str, wall: float) -> None:
        """Record that `case` ended after `wall` seconds."""
        self.done[case] = wall
        if not self.tty:
            print(f'  [{len(self.done)}/{len(self.cases)}] {case} done in {wall:.1f} s',
                  flush=True)
        self.draw()

    def draw(self) -> None:
        """Show the progress (redraw the line, or print quarter lines)."""
        elapsed = time.monotonic() - self.start
        if self.tty:
            total = sum(self.fraction(c) for c in self.cases) / len(self.cases)
            bar = '#' * int(round(20 * total))
            cells = '  '.join(f'{c} {self.fraction(c) * 100:3.0f}%' for c in self.cases
                              if c not in self.done)
            print(f'\r\033[K  [{bar:<20}] {len(self.done)}/{len(self.cases)} cases, '
                  f'{elapsed:5.0f} s  {cells}', end='', flush=True)
            return
        for case in self.cases:
            quarter = int(4 * self.fraction(case))
            if case not in self.done and 0 < quarter < 4 and quarter > self.quarters[case]:
                self.quarters[case] = quarter
                print(f'  {case}: {quarter * 25} %  ({elapsed:.0f} s)', flush=True)

    def close(self) -> None:
        """End the progress line."""
        if self.tty:
            print()


def run_cases(cases: Sequence[str], work: Path, figures: Path, jobs: int) -> dict[str, dict]:
    """Every case in a pool of `jobs` worker processes (spawned), with progress; raises
    RuntimeError naming the first case that failed (the others are cancelled)."""
    (work / 'progress').mkdir(parents=True, exist_ok=True)
    board = ProgressBoard(cases, work / 'progress', sys.stdout.isatty())
    results: dict[str, dict] = {}
    context = multiprocessing.get_context('spawn')
    with futures.ProcessPoolExecutor(max_workers=jobs, mp_context=context) as pool:
        pending = {pool.submit(run_case, case, str(work), str(figures)): case for case in cases}
        try:
            while pending:
                done, _ = futures.wait(pending, timeout=1.0,
                                       return_when=futures.FIRST_COMPLETED)
                for future in done:
                    case = pending.pop(future)
                    try:
                        results[case] = future.result()
                    except Exception as exc:  # noqa: BLE001 - any failure names its case
                        raise RuntimeError(f'case {case} failed: {type(exc).__name__}: '
                                           f'{exc}') from exc
                    board.finished(case, results[case]['wall_time'])
                board.draw()
        except BaseException:
            for future in pending:
                future.cancel()
            raise
        finally:
            board.close()
    return results
