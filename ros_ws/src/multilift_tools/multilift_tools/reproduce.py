"""`multilift reproduce [--out DIR] [--jobs N] [--bags DIR]`: the seed's §2.8 and Ch. 4, rerun.

Runs the seed's cases headless (multilift_control.headless: the physics, control laws and bag of
the ROS stack in one process) in parallel worker processes; multilift_tools.reproduce_report
then draws a counterpart of every figure of the seed's §2.8 (Fig. 2.12) and Ch. 4 (Fig.
4.1-4.17) with the figure functions of multilift_tools.figures, .compare, .modal_cli and
.studies, measures every number and qualitative claim of those sections, and writes
DIR/reproduction.md (default docs/) with the figures as PNG under DIR/figures/ (relative
links). World frame, z up, SI units; the seed's frame is z down, (x, y, z)_world = (x, -y,
-z)_seed (multilift_sim.frames).

This module also holds `single_lift_table`, the single-lift numbers (seed §2.8.1, §4.1) that
tests/unit/test_reproduction.py regenerates and compares with the committed report.

Cases (one worker process each, longest first): the twin-lift and the "V" of three flying the
§4.2 mission (bags), the V again in still air (how far the gusts move its payload), the
single-lift table (`single_lift_table`: release, modal, periods, Baumgarte study, static
tension), the single-lift swing (bag, Fig. 4.1) and the twin-lift and V modal analyses.

Exit codes: 0 done, 1 a case failed (named on stderr), 2 bad input, 130 interrupted.
"""
from __future__ import annotations

import argparse
import concurrent.futures as futures
import dataclasses
import json
import math
import multiprocessing
import os
import shutil
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from multilift_sim.scenario import Scenario, ScenarioError, load

# -- what the seed says (quoted from ../shared/seed, §2.8 and Ch. 4) -------------------------
SEED_RELEASE = (1.02, -0.65, 2.19)      # r_p(0) [m], seed frame (z down), §4.1
SEED_PERIOD = 2.94                      # pendulum period [s], §2.8.1 and §4.1
SEED_EIGENVALUE = 2.13                  # lambda_1 = lambda_2 = +/- 2.13j [1/s], §2.8.1

# -- how the single-lift table is computed ---------------------------------------------------
SWING = 'single_lift_swing'
TWIN, MULTI = 'twin_lift', 'multi_lift'
SMALL_RELEASE_DEG = 1.0        # alpha = beta [deg] of the small-amplitude swing
BAUMGARTE_DURATION = 20.0      # [s] the Baumgarte study's span (the scenario's 20 s swing)
BAUMGARTE_GAINS = (0.0, 20.0, 100.0)
REST_DURATION = 1.0            # [s] of the hanging-at-rest run for the static tension


# =============================================================================================
# Single-lift (seed §2.8.1 and §4.1): the table the test regenerates
# =============================================================================================
def _swing_scenario(alpha_deg: float | None = None, beta_deg: float | None = None,
                    duration: float | None = None) -> Scenario:
    """single_lift_swing, optionally released at other angles [deg] or run for `duration` [s]."""
    scenario = load(SWING)
    payload, simulation = scenario.payload, scenario.simulation
    if alpha_deg is not None:
        payload = dataclasses.replace(payload, alpha=math.radians(alpha_deg),
                                      beta=math.radians(beta_deg or 0.0))
    if duration is not None:
        simulation = dataclasses.replace(simulation, duration=duration)
    return dataclasses.replace(scenario, payload=payload, simulation=simulation)


@dataclass(frozen=True)
class SwingHistory:
    """A headless single-lift run at every control tick: t (T,) [s], UAV and payload positions
    (T, 3) [m] (world), cable tension (T,) [N]."""

    t: np.ndarray
    uav: np.ndarray
    payload: np.ndarray
    tension: np.ndarray


def swing_history(scenario: Scenario) -> SwingHistory:
    """Fly a single-lift scenario with run_headless (Algorithm 1, the DAE) and keep its path."""
    from multilift_control.headless import run_headless

    rows: list[tuple[float, np.ndarray, np.ndarray, float]] = []
    held: list[np.ndarray] = []  # the commands held since the tick before (the last tick's)

    def tick(sim: Any, snap: Any, answers: list) -> None:
        if answers:
            held[:] = [a.output.rotor_speeds for a in answers]
        tension = sim.cable_state(held)[0]
        rows.append((sim.t, snap.uavs[0].position, snap.payload_position, float(tension[0])))

    run_headless(scenario, tick)
    return SwingHistory(np.array([r[0] for r in rows]), np.array([r[1] for r in rows]),
                        np.array([r[2] for r in rows]), np.array([r[3] for r in rows]))


def swing_signal(uav: np.ndarray, payload: np.ndarray) -> np.ndarray:
    """The payload's horizontal offset from the UAV [m] along its initial horizontal direction
    (a swing released at rest stays in that vertical plane)."""
    offset = payload[:, :2] - uav[:, :2]
    direction = offset[0] / np.linalg.norm(offset[0])
    return offset @ direction


def upward_crossings(t: np.ndarray, signal: np.ndarray) -> np.ndarray:
    """Times [s] where `signal` crosses zero upwards, linearly interpolated between samples."""
    k = np.nonzero((signal[:-1] < 0.0) & (signal[1:] >= 0.0))[0]
    return t[k] - signal[k] * (t[k + 1] - t[k]) / (signal[k + 1] - signal[k])


def swing_period(t: np.ndarray, uav: np.ndarray, payload: np.ndarray) -> float:
    """Mean period [s] of the swing over its complete cycles (successive upward crossings)."""
    crossings = upward_crossings(t, swing_signal(uav, payload))
    if len(crossings) < 2:
        raise ValueError('the run holds less than one full swing: no period')
    return float(np.mean(np.diff(crossings)))


def reduced_swing(scenario: Scenario, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(UAV, payload) world positions (T, 3) [m] of the reduced single-lift model (seed Eq.
    2.34, DOP853 rtol 1e-10) from the scenario's release, rotor speeds held at Eq. 2.73."""
    from multilift_sim.frames import world_to_seed_euler, world_to_seed_vector
    from multilift_sim.modal import scenario_equilibrium
    from multilift_sim.reduced_model import ReducedSingleLiftModel, rest_state
    from multilift_sim.simulation import initial_state

    uav = scenario.uavs[0]
    model = ReducedSingleLiftModel(uav.vehicle, scenario.payload.mass, uav.cable_length,
                                   scenario.simulation.gravity)
    x0 = initial_state(scenario)
    start = rest_state(world_to_seed_vector(x0[0:3]), world_to_seed_euler(x0[3:6]),
                       scenario.payload.alpha, scenario.payload.beta)
    solution = model.simulate(start, scenario_equilibrium(scenario).rotor_speeds[0],
                              float(times[-1]), t_eval=times)
    if not solution.success:
        raise RuntimeError(f'reduced single-lift model: {solution.message}')
    return model.to_world_positions(solution.y.T)


def release_amplitude(scenario: Scenario) -> float:
    """Angle [rad] of the released cable from the vertical: cos = cos(alpha) cos(beta)."""
    return math.acos(math.cos(scenario.payload.alpha) * math.cos(scenario.payload.beta))


def amplitude_period_factor(amplitude: float) -> float:
    """T(amplitude) / T(0) of a plane pendulum: 2 K(sin^2(amplitude / 2)) / pi (K the complete
    elliptic integral of the first kind, parameter m = k^2)."""
    from scipy.special import ellipk
    return 2.0 * float(ellipk(math.sin(amplitude / 2.0) ** 2)) / math.pi


def table_row(key: str, quantity: str, seed: str, ours: str, command: str,
              value: Any = None) -> dict:
    """One row of a numbers table: what, the seed's value, ours, the command that gives it,
    and the raw value(s) for tests."""
    return {'key': key, 'quantity': quantity, 'seed': seed, 'ours': ours, 'command': command,
            'value': value}


def vector_text(v: Sequence[float], digits: int = 2) -> str:
    """'{a, b, c}' with `digits` decimals, as the seed writes vectors."""
    return '{' + ', '.join(f'{c + 0.0:.{digits}f}' for c in v) + '}'  # + 0.0: no '-0.00'


def single_lift_table(study_dir: str | Path | None = None) -> list[dict]:
    """The single-lift numbers of seed §2.8.1 and §4.1, computed (about 8 s on one core).

    Rows (dicts with key, quantity, seed, ours, command, value; `render_row` makes the markdown):
    the release r_p(0); size of A, eigenvalues and period of the linearised open loop
    (multilift_sim.modal); the periods of the simulated swing (run_headless, the formation DAE
    of Algorithm 1) released at 1/1 deg and at the seed's 15/25 deg, of the nonlinear reduced
    model (Eq. 2.34) at 15/25 deg and of the plane-pendulum amplitude law; the Baumgarte study
    (max |g| for alpha_f = 0, 20, 100; alpha_f = 100 against the reduced model) over
    BAUMGARTE_DURATION; the scenario's own run against the reduced model; the static tension
    against m_p g. `study_dir`: where the Baumgarte study writes its table and figures (Fig.
    4.2, 4.3); default a temporary directory, removed.
    """
    from multilift_sim.dynamics import StateLayout
    from multilift_sim.frames import world_to_seed_vector
    from multilift_sim.modal import scenario_modal_analysis
    from multilift_sim.simulation import initial_state
    from multilift_tools.studies import baumgarte_study

    rows = []
    scenario = _swing_scenario()
    x0 = initial_state(scenario)
    layout = StateLayout(1)
    release_world = layout.payload_position(x0) - layout.uav_positions(x0)[0]
    release = world_to_seed_vector(release_world)
    rows.append(table_row(
        'release', 'payload at release r_p(0) - r(0), α = 15°, β = 25°, seed frame (z down) [m]',
        vector_text(SEED_RELEASE),
        f'{vector_text(release)} (world, z up: {vector_text(release_world)})',
        f'scripts/multilift run {SWING} --headless --bag B (first /payload/odom)',
        [float(c) for c in release]))

    analysis = scenario_modal_analysis(scenario)
    omegas = sorted(float(analysis.eigenvalues[k].imag) for k in analysis.pendulum_modes)
    size = analysis.state_matrix.shape[0]
    rows.append(table_row(
        'state_matrix', 'linearised single-lift: size of A (independent coordinates)',
        '16 × 16 (8)', f'{size} × {size} ({analysis.basis.shape[1]} of 9; '
        f'{analysis.rigid_count} rigid-body zeros)', f'scripts/multilift modal {SWING}', size))
    rows.append(table_row(
        'eigenvalues', 'pendulum eigenvalues λ_1 = λ_2 [1/s]',
        f'±{SEED_EIGENVALUE:.2f}j, ±{SEED_EIGENVALUE:.2f}j',
        ', '.join(f'±{w:.4f}j' for w in omegas), f'scripts/multilift modal {SWING}', omegas))
    linear = 2.0 * math.pi / omegas[0]
    rows.append(table_row('linear_period', 'pendulum period 2π/ω of the linearised model [s]',
                          f'{SEED_PERIOD:.2f}', f'{linear:.4f}', f'scripts/multilift modal {SWING}',
                          linear))

    small = _swing_scenario(SMALL_RELEASE_DEG, SMALL_RELEASE_DEG)
    history = swing_history(small)
    period_small = swing_period(history.t, history.uav, history.payload)
    rows.append(table_row(
        'period_small', f'simulated period, released at α = β = {SMALL_RELEASE_DEG:g}° '
        '(formation DAE, Algorithm 1) [s]', '-',
        f'{period_small:.4f} ({(period_small / linear - 1) * 100:+.3f} % vs linear)',
        f'reproduce.single_lift_table (run_headless, {SWING}, α = β = 1°)', period_small))

    history = swing_history(scenario)
    period_large = swing_period(history.t, history.uav, history.payload)
    rows.append(table_row(
        'period_large', 'simulated period, released at α = 15°, β = 25° (formation DAE) [s]',
        f'{SEED_PERIOD:.2f}',
        f'{period_large:.4f} ({(period_large / linear - 1) * 100:+.2f} % vs linear)',
        f'scripts/multilift run {SWING} --headless --bag B; reproduce.swing_period',
        period_large))
    uav_ref, payload_ref = reduced_swing(scenario, history.t)
    period_reduced = swing_period(history.t, uav_ref, payload_ref)
    rows.append(table_row(
        'period_reduced', 'period of the nonlinear reduced model (Eq. 2.34) at 15°/25° [s]', '-',
        f'{period_reduced:.4f}', 'reproduce.single_lift_table (ReducedSingleLiftModel)',
        period_reduced))
    amplitude = release_amplitude(scenario)
    factor = amplitude_period_factor(amplitude)
    rows.append(table_row(
        'period_law', f'plane-pendulum amplitude law: linear period × 2K(sin²(θ_0/2))/π, '
        f'θ_0 = {math.degrees(amplitude):.1f}° [s]', '-',
        f'{linear * factor:.4f} (factor {factor:.4f})', 'reproduce.amplitude_period_factor',
        linear * factor))
    error = float(np.max(np.linalg.norm(history.payload - payload_ref, axis=1)))
    rows.append(table_row(
        'scenario_error', f'{SWING} as run (α_f = 20, RK4 1 ms) vs reduced model: max payload '
        f'position error over {history.t[-1]:.0f} s [m]', '-', f'{error:.0e}',
        f'scripts/multilift run {SWING} --headless --bag B', error))

    temporary = study_dir is None
    out = Path(tempfile.mkdtemp(prefix='multilift-baumgarte-')) if temporary else Path(study_dir)
    try:
        study = baumgarte_study(out, duration=BAUMGARTE_DURATION, gains=BAUMGARTE_GAINS)
    finally:
        if temporary:
            shutil.rmtree(out, ignore_errors=True)
    by_label = {r['integrator']: r for r in study['rows']}
    step = f'RK4 {study["dt"] * 1e3:g} ms, {BAUMGARTE_DURATION:g} s'
    seeds = {0.0: 'grows rapidly, "inaccurate"', 20.0: '< 1e-1', 100.0: '< 1e-1'}
    for gain in BAUMGARTE_GAINS:
        r = by_label[f'Baumgarte alpha_f = {gain:g}']
        rows.append(table_row(
            f'baumgarte_{gain:g}', f'Fig. 4.2: max \\|g\\| with α_f = {gain:g} ({step}) [m²]',
            seeds[gain], f'{r["max_abs_g"]:.1e} (final {r["final_abs_g"]:.1e})',
            f'scripts/multilift study baumgarte --duration {BAUMGARTE_DURATION:g}',
            r['max_abs_g']))
    r = by_label[f'Baumgarte alpha_f = {BAUMGARTE_GAINS[-1]:g}']
    rows.append(table_row(
        'dae_error', f'Fig. 4.3: α_f = 100 vs reduced model, max UAV / payload error ({step}) '
        '[m]', '"approximately equal", growing', f'{r["max_uav_error"]:.1e} / '
        f'{r["max_payload_error"]:.1e}',
        f'scripts/multilift study baumgarte --duration {BAUMGARTE_DURATION:g}',
        [r['max_uav_error'], r['max_payload_error']]))

    rest = swing_history(_swing_scenario(0.0, 0.0, REST_DURATION))
    weight = scenario.payload.mass * scenario.simulation.gravity
    tension = float(np.mean(rest.tension))
    rows.append(table_row(
        'static_tension', f'cable tension hanging at rest ({REST_DURATION:g} s) vs m_p g [N]',
        '- (Eq. 2.73)', f'{tension:.4f} vs {weight:.4f} (' + (
            'equal to 1e-9' if abs(tension / weight - 1) < 1e-9 else
            f'{(tension / weight - 1) * 100:+.2g} %') + ')',
        f'reproduce.single_lift_table (run_headless, {SWING}, α = β = 0)', [tension, weight]))
    return rows


def render_row(row: dict) -> str:
    """The markdown table line of a numbers-table row (deterministic: the test compares it)."""
    cells = [row['quantity'], row['seed'], row['ours'], f'`{row["command"]}`']
    return '| ' + ' | '.join(cells) + ' |'


TABLE_HEAD = ('| quantity | seed | ours | command |', '| --- | --- | --- | --- |')


def render_table(rows: Sequence[dict]) -> list[str]:
    """Header and one line per row (render_row)."""
    return [*TABLE_HEAD, *(render_row(r) for r in rows)]


# =============================================================================================
# The cases, run in worker processes
# =============================================================================================
CASES = ('twin_lift', 'multi_lift', 'multi_lift_still_air', 'single_lift_table',
         'single_lift_swing', 'modal')


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
    from multilift_sim.dynamics import StateLayout
    from multilift_sim.modal import coordinate_names, scenario_modal_analysis
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
                     'free': int(analysis.basis.shape[1]), 'coordinates': 6 * n + 3,
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


# =============================================================================================
# Command line
# =============================================================================================
class _UsageError(Exception):
    """A bad command line (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    """argparse raising _UsageError instead of exiting."""

    def error(self, message: str) -> None:      # one line, exit code 2 (not argparse's usage)
        raise _UsageError(message)


def _positive_int(text: str) -> int:
    """An int >= 1 for argparse."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f'{text} must be >= 1')
    return value


def reproduce_main(argv: list[str] | None = None) -> int:
    """`multilift reproduce [--out DIR] [--jobs N] [--bags DIR]` (argv without 'reproduce').

    Runs CASES in N worker processes (default: the CPU count), writes DIR/figures/*.png and
    DIR/reproduction.md (DIR default docs/), prints where and how long. Exit 0; 1 when a case
    fails (one line naming it); 2 for bad arguments; 130 on Ctrl-C.
    """
    parser = _Parser(prog='multilift reproduce', description="rerun the seed's §2.8 and Ch. 4 "
                     'and write DIR/reproduction.md with its figures')
    parser.add_argument('--out', default='docs', help='output directory (default docs/)')
    parser.add_argument('--jobs', type=_positive_int, default=os.cpu_count() or 1,
                        help='worker processes (default: the CPU count)')
    parser.add_argument('--bags', help='keep the bags and the study here (default: a temporary '
                        'directory, removed)')
    try:
        args = parser.parse_args(argv)
    except _UsageError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    started = time.monotonic()
    out = Path(args.out)
    figures = out / 'figures'
    figures.mkdir(parents=True, exist_ok=True)
    for old in [*figures.glob('fig2_*.png'), *figures.glob('fig4_*.png')]:
        old.unlink()
    work = Path(args.bags) if args.bags else Path(tempfile.mkdtemp(prefix='multilift-repro-'))
    work.mkdir(parents=True, exist_ok=True)
    jobs = min(args.jobs, len(CASES))
    print(f'multilift reproduce: {len(CASES)} cases in {jobs} processes; work in {work}',
          flush=True)
    try:
        results = run_cases(CASES, work, figures, jobs)
        print('  figures and report ...', flush=True)
        from multilift_tools.reproduce_report import write_reproduction
        report = write_reproduction(out, results, work, jobs, started)
    except KeyboardInterrupt:
        print('interrupted', file=sys.stderr)
        return 130
    except (RuntimeError, ScenarioError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 1
    finally:
        if not args.bags:
            shutil.rmtree(work, ignore_errors=True)
    pngs = sorted(figures.glob('fig*.png'))
    size = sum(p.stat().st_size for p in pngs) / 1e6
    print(f'wrote {report} and {len(pngs)} figures in {figures} ({size:.1f} MB) in '
          f'{time.monotonic() - started:.0f} s')
    return 0


if __name__ == '__main__':
    sys.exit(reproduce_main(sys.argv[1:]))
