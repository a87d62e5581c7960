"""Numerical studies behind `multilift study NAME`: pure numpy/scipy/matplotlib, no ROS.

swing_feedback (beyond the seed, issue 20): multilift_tools.swing_study.

baumgarte: the seed's Sec. 4.1 study (Fig. 4.2 and 4.3) on the open-loop single-lift swing.
The formation DAE is integrated with Baumgarte gains alpha_f = beta_f = 0, 20, 100 (Eq. 2.59,
dynamics.FormationModel) and with the null-space formulation (Eq. 2.71-2.72,
nullspace.NullSpaceModel, with and without its projection), each compared with the reduced
single-lift model in independent coordinates (Eq. 2.34, reduced_model, solved by DOP853 to
rtol 1e-10) from the same release. Outputs, world frame, SI units: |g| against time on a log
axis (Fig. 4.2), the UAV and payload position errors against the reduced model (Fig. 4.3, for
every integrator rather than alpha_f = 100 alone), and a markdown table.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from multilift_sim.analysis.equilibrium import scenario_equilibrium
from multilift_sim.analysis.reduced_model import ReducedSingleLiftModel, rest_state
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import StateLayout
from multilift_sim.frames import world_to_seed_euler, world_to_seed_vector
from multilift_sim.nullspace import NullSpaceModel
from multilift_sim.scenario import Scenario, ScenarioError, load
from multilift_sim.start import initial_state

# multilift_tools.swing_study, .load_study, .comms_study
STUDIES = ('baumgarte', 'swing_feedback', 'load_sharing', 'comms')
DEFAULT_DURATION = 60.0   # [s] the drift of alpha_f = 0 needs time to show (Fig. 4.2)
DEFAULT_STEP = 0.01       # [s] RK4 step; see baumgarte_study
RESIDUAL_FLOOR = 1e-18    # [m^2] |g| below this is drawn at this value on the log axis


@dataclass(frozen=True)
class IntegratorRun:
    """One integrator's run of the study, sampled at every step."""

    label: str
    times: np.ndarray             # (k,) [s]
    residuals: np.ndarray         # |g| (k,) [m^2]
    uav_error: np.ndarray         # |r - r_ref| of the UAV (k,) [m]
    payload_error: np.ndarray     # |r_p - r_p,ref| (k,) [m]
    wall_per_second: float        # wall time per simulated second [s/s]

    def row(self) -> dict:
        """The table's numbers."""
        return {'integrator': self.label,
                'max_abs_g': float(self.residuals.max()),
                'final_abs_g': float(self.residuals[-1]),
                'max_uav_error': float(self.uav_error.max()),
                'max_payload_error': float(self.payload_error.max()),
                'wall_per_simulated_second': self.wall_per_second}


def reduced_swing(scenario: Scenario, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(UAV, payload) world positions (T, 3) [m] of the reduced single-lift model (seed Eq.
    2.34, DOP853 rtol 1e-10) from the scenario's release, rotor speeds held at Eq. 2.73."""
    uav = scenario.uavs[0]
    model = ReducedSingleLiftModel(uav.vehicle, scenario.payload.mass, uav.cable_length,
                                   scenario.simulation.gravity)
    x0 = initial_state(scenario)
    layout = StateLayout(1)
    start = rest_state(world_to_seed_vector(layout.uav_positions(x0)[0]),
                       world_to_seed_euler(layout.uav_euler(x0)[0]),
                       scenario.payload.alpha, scenario.payload.beta)
    solution = model.simulate(start, scenario_equilibrium(scenario).rotor_speeds[0],
                              float(times[-1]), t_eval=times)
    if not solution.success:
        raise RuntimeError(f'reduced single-lift model: {solution.message}')
    return model.to_world_positions(solution.y.T)


def _integrate(model, x0: np.ndarray, rotor_speeds: list[np.ndarray], steps: int,
               dt: float) -> tuple[np.ndarray, float]:
    """States (steps + 1, len(x0)) from x0 under held rotor speeds, and the wall time [s]."""
    states = np.empty((steps + 1, x0.size))
    states[0] = x = x0
    start = time.perf_counter()
    for k in range(steps):
        x = model.step(k * dt, x, rotor_speeds, dt)
        states[k + 1] = x
    return states, time.perf_counter() - start


def _check_single_lift(scenario: Scenario) -> None:
    if scenario.n_uavs != 1:
        raise ValueError(f'{scenario.source}: the Baumgarte study compares with the reduced '
                         f'single-lift model and needs n = 1, not {scenario.n_uavs}')
    if scenario.payload.drag_coefficient or scenario.gusts:
        raise ValueError(f'{scenario.source}: payload.drag_coefficient / gusts: the reduced '
                         'model has no payload drag; the study needs still air without drag')


def baumgarte_study(out_dir: str | Path, duration: float = DEFAULT_DURATION,
                    dt: float = DEFAULT_STEP, scenario: str = 'single_lift_swing',
                    gains: tuple[float, ...] = (0.0, 20.0, 100.0)) -> dict:
    """Run the study, write its figures and table to out_dir, return the numbers.

    duration [s] and dt [s] (RK4 step, every integrator alike). The default step is 10 ms,
    ten times the scenario's physics step: at 1 ms RK4 keeps even the unstabilised DAE within
    ~1e-10 m^2 of the cable length over 10 s, and the study would show nothing; at 10 ms over
    60 s alpha_f = 0 drifts secularly while the stabilised runs stay bounded. Baumgarte gains
    are alpha_f = beta_f (critical damping, docs and README). Rotor speeds are held at the
    static equilibrium (Eq. 2.73: the thrust balances UAV and payload weight, seed Sec. 4.1).

    Writes baumgarte.md (the table), baumgarte.json, baumgarte_constraint.png and
    baumgarte_position_error.png. Returns {'scenario', 'duration', 'dt', 'rows', 'files',
    'table'}. Raises ScenarioError / ValueError for an unusable scenario or step.
    """
    if not (duration > 0 and dt > 0 and dt <= duration):
        raise ValueError(f'need 0 < dt <= duration, got dt = {dt!r} s, duration = '
                         f'{duration!r} s')
    setup = load(scenario)
    _check_single_lift(setup)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    steps = int(round(duration / dt))
    times = np.arange(steps + 1) * dt
    rotor_speeds = list(scenario_equilibrium(setup).rotor_speeds)

    x0, layout = initial_state(setup), StateLayout(1)
    uav_reference, payload_reference = reduced_swing(setup, times)

    models = [(f'Baumgarte alpha_f = {gain:g}',
               FormationModel(setup.formation_params(gain, gain))) for gain in gains]
    models += [('null space + projection', NullSpaceModel(setup.formation_params())),
               ('null space, no projection',
                NullSpaceModel(setup.formation_params(), projection=False))]
    runs = []
    for label, model in models:
        states, wall = _integrate(model, x0, rotor_speeds, steps, dt)
        residuals = np.array([abs(model.constraint_residuals(x)[0][0]) for x in states])
        runs.append(IntegratorRun(
            label=label, times=times, residuals=residuals,
            uav_error=np.linalg.norm(layout.uav_positions(states)[:, 0] - uav_reference, axis=1),
            payload_error=np.linalg.norm(layout.payload_position(states) - payload_reference,
                                         axis=1),
            wall_per_second=wall / times[-1]))

    rows = [run.row() for run in runs]
    table = _table(rows, setup, duration, dt)
    files = {'table': out / 'baumgarte.md', 'json': out / 'baumgarte.json',
             'constraint_plot': out / 'baumgarte_constraint.png',
             'error_plot': out / 'baumgarte_position_error.png'}
    files['table'].write_text(table + '\n')
    files['json'].write_text(json.dumps({'scenario': setup.name, 'duration': duration,
                                         'dt': dt, 'rows': rows}, indent=1))
    step_text = f'RK4, dt = {dt * 1e3:g} ms'
    _plot_residuals(runs, files['constraint_plot'],
                    f'{setup.name}: constraint residual ({step_text})')
    _plot_errors(runs, files['error_plot'],
                 f'{setup.name}: position error against the reduced model ({step_text})')
    return {'scenario': setup.name, 'duration': duration, 'dt': dt, 'rows': rows,
            'files': {k: str(v) for k, v in files.items()}, 'table': table}


def _table(rows: list[dict], setup: Scenario, duration: float, dt: float) -> str:
    caption = (
        f'Baumgarte study on `{setup.name}` (seed Sec. 4.1, Fig. 4.2-4.3): every integrator is '
        f'RK4 with step dt = {dt * 1e3:g} ms ({1 / dt:g} Hz) over {duration:g} s, rotor speeds '
        'held at the weight-balancing equilibrium (Eq. 2.73), payload released at rest at '
        f'alpha = {np.degrees(setup.payload.alpha):g} deg, beta = '
        f'{np.degrees(setup.payload.beta):g} deg. Errors are against the reduced model in '
        'independent coordinates (Eq. 2.34, DOP853, rtol 1e-10). The step is chosen coarser '
        'than the scenario\'s 1 ms because at 1 ms RK4 holds even alpha_f = 0 within ~1e-10 '
        'm^2 over 10 s. g = |r_p - r|^2 - l^2; wall time is the stepping loop alone on this '
        'machine.')
    lines = [caption, '',
             '| integrator | max \\|g\\| [m^2] | final \\|g\\| [m^2] | max UAV error [m] '
             '| max payload error [m] | wall s per simulated s |',
             '| --- | ---: | ---: | ---: | ---: | ---: |']
    for row in rows:
        lines.append(f'| {row["integrator"]} | {row["max_abs_g"]:.2e} | '
                     f'{row["final_abs_g"]:.2e} | {row["max_uav_error"]:.2e} | '
                     f'{row["max_payload_error"]:.2e} | '
                     f'{row["wall_per_simulated_second"]:.4f} |')
    return '\n'.join(lines)


def _style(label: str) -> dict:
    """Line style: the unprojected null-space run retraces alpha_f = 0, so it is dashed on
    top of a wider alpha_f = 0 line."""
    if label.endswith('no projection'):
        return {'linewidth': 1.0, 'linestyle': '--'}
    if label.endswith('= 0'):
        return {'linewidth': 2.5, 'alpha': 0.6}
    return {'linewidth': 1.0}


def _plot_residuals(runs: list[IntegratorRun], path: Path, title: str) -> None:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.0, 4.5), layout='constrained')
    axes = figure.add_subplot()
    for run in runs:
        axes.semilogy(run.times, np.maximum(run.residuals, RESIDUAL_FLOOR), label=run.label,
                      **_style(run.label))
    axes.set_xlabel('time t [s]')
    axes.set_ylabel(f'|g| [m$^2$] (floored at {RESIDUAL_FLOOR:g})')
    axes.set_title(title, fontsize=10)
    axes.grid(True, which='both', alpha=0.3)
    axes.legend(fontsize=8, loc='center right')
    figure.savefig(path, dpi=120)


def _plot_errors(runs: list[IntegratorRun], path: Path, title: str) -> None:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.0, 6.0), layout='constrained')
    top, bottom = figure.subplots(2, 1, sharex=True)
    for run in runs:
        top.semilogy(run.times[1:], run.uav_error[1:], label=run.label, **_style(run.label))
        bottom.semilogy(run.times[1:], run.payload_error[1:], label=run.label,
                        **_style(run.label))
    top.set_ylabel('UAV |r - r_ref| [m]')
    bottom.set_ylabel('payload |r_p - r_p,ref| [m]')
    bottom.set_xlabel('time t [s]')
    top.set_title(title, fontsize=10)
    for axes in (top, bottom):
        axes.grid(True, which='both', alpha=0.3)
    top.legend(fontsize=8)
    figure.savefig(path, dpi=120)


class _UsageError(Exception):
    pass


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:      # one line, exit code 2 (not argparse's usage)
        raise _UsageError(message)


def study_main(argv: list[str] | None = None) -> int:
    """`multilift study NAME [--out DIR] [--duration S] [--dt S] [--scenario S]` (argv without
    the word 'study'). NAME: baumgarte, swing_feedback (multilift_tools.swing_study) or
    load_sharing (multilift_tools.load_study) or comms (multilift_tools.comms_study; these
    take --out only). Prints the table and
    writes the files to DIR (default runs/study).
    Exit 0, or 2 with one line on stderr for bad input."""
    parser = _Parser(prog='multilift study', description='numerical studies (seed Ch. 4)')
    parser.add_argument('study', choices=STUDIES)
    parser.add_argument('--out', default='runs/study', help='output directory')
    parser.add_argument('--duration', type=float, default=DEFAULT_DURATION,
                        help=f'simulated seconds (default {DEFAULT_DURATION:g})')
    parser.add_argument('--dt', type=float, default=DEFAULT_STEP,
                        help=f'RK4 step [s] (default {DEFAULT_STEP:g})')
    parser.add_argument('--scenario', default='single_lift_swing',
                        help='a single-lift scenario without drag (default single_lift_swing)')
    try:
        args = parser.parse_args(argv)
        if args.study == 'swing_feedback':
            from multilift_tools.swing_study import swing_feedback_study
            result = swing_feedback_study(args.out)
        elif args.study == 'load_sharing':
            from multilift_tools.load_study import load_sharing_study
            result = load_sharing_study(args.out)
        elif args.study == 'comms':
            from multilift_tools.comms_study import comms_study
            result = comms_study(args.out)
        else:
            result = baumgarte_study(args.out, duration=args.duration, dt=args.dt,
                                     scenario=args.scenario)
    except (_UsageError, ScenarioError, ValueError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    print(result['table'])
    print('\nwrote ' + ', '.join(result['files'].values()))
    return 0


if __name__ == '__main__':
    sys.exit(study_main())
