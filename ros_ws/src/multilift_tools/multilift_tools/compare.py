"""`multilift compare BAG_A BAG_B [--out DIR] [--labels A B] [--scenario-a S]
[--scenario-b S]`: two recorded runs on the same axes (seed Fig. 4.15-4.17) and a table of
differences (metrics.comparison_rows). World frame, z up, SI units. Exit codes: 0 done, 2 bad
input.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np

from multilift_sim.topics import PAYLOAD_ODOM, ROTOR_CMD, uav_topic
from multilift_tools.bagdata import Run, rotor_limits
from multilift_tools.metrics import comparison_rows, common_end, until
from multilift_tools.plot_style import (AXES_XYZ, SATURATION_GREY, WORLD, Parser,
                                        finish_time_axes, finish_time_plot, formation_row_labels,
                                        legend, load_bag, parse_args, plot_context, plt,
                                        save_figure, uav_color)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from multilift_sim.scenario import Scenario


def fig_compare_payload(runs: Sequence[Run], labels: Sequence[str]) -> Figure:
    """Payload x, y, z [m] of both runs on the same axes (seed Fig. 4.15)."""
    t_end = common_end(runs)
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 7), layout='constrained')
    for run, label, style in zip(runs, labels, ('-', '--')):
        keep = until(run.payload_time, t_end)
        p = run.payload_position()[keep]
        for k, ax in enumerate(axes):
            ax.plot(run.payload_time[keep], p[:, k], ls=style, lw=1.2,
                    label=f'$ {AXES_XYZ[k]}_p$ | {label}')
    for k, ax in enumerate(axes):
        ax.set_ylabel(f'${AXES_XYZ[k]}_p$ [m]')
        legend(ax, loc='best')
    axes[0].set_title(f'payload position ({WORLD}): {labels[0]} vs {labels[1]}',
                      fontsize='medium')
    finish_time_axes(axes)
    return fig


def fig_compare_formation_error(runs: Sequence[Run], labels: Sequence[str],
                                scenarios: Sequence[Scenario | None]) -> Figure:
    """Virtual-constraint errors of every follower of both runs (seed Fig. 4.16): the x, y, z
    rows [m] where both runs have them, and the norm |g_vc| per follower."""
    t_end = common_end(runs)
    by_axis = all(formation_row_labels(s, i, r.formation_errors(i).shape[1])[1] == 'm'
                  for r, s in zip(runs, scenarios) for i in r.followers)
    rows = 4 if by_axis else 1
    fig, axes = plt.subplots(rows, 1, sharex=True, squeeze=False, figsize=(9, 1.8 + 1.9 * rows),
                             layout='constrained')
    axes = axes[:, 0]
    for run, label, style in zip(runs, labels, ('-', '--')):
        for i in run.followers:
            keep = until(run.formation_error_time(i), t_end)
            t, e = run.formation_error_time(i)[keep], run.formation_errors(i)[keep]
            color = uav_color(i)
            if by_axis:
                for k in range(3):
                    axes[k].plot(t, e[:, k], ls=style, color=color, lw=1.1,
                                 label=f'UAV {i} | {label}')
            axes[-1].plot(t, np.linalg.norm(e, axis=1), ls=style, color=color, lw=1.1,
                          label=f'UAV {i} | {label}')
    unit = 'm' if by_axis else 'm or m²'
    if by_axis:
        for k in range(3):
            axes[k].set_ylabel(f'$g_{{vc}}$ {AXES_XYZ[k]} [m]')
            axes[k].axhline(0.0, color='0.3', lw=0.6)
    axes[-1].set_ylabel(f'$|g_{{vc}}|$ [{unit}]')
    for ax in axes:
        legend(ax, loc='best', ncols=2)
    axes[0].set_title(f'virtual-constraint error per follower ({WORLD}): solid {labels[0]}, '
                      f'dashed {labels[1]}', fontsize='medium')
    finish_time_axes(axes)
    return fig


def fig_compare_leader_rotors(runs: Sequence[Run], labels: Sequence[str],
                              scenarios: Sequence[Scenario | None]) -> Figure:
    """The leader's rotor speeds [rad/s] of both runs (seed Fig. 4.17): the mean over its rotors
    and their range, with the saturation band shaded."""
    t_end = common_end(runs)
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    top, bottom, lowest = -math.inf, math.inf, math.inf
    for run, label, color in zip(runs, labels, ('tab:blue', 'tab:orange')):
        keep = until(run.rotor_time(1), t_end)
        t, omega = run.rotor_time(1)[keep], run.rotor_speeds(1)[keep]
        ax.fill_between(t, omega.min(axis=1), omega.max(axis=1), color=color, alpha=0.25,
                        lw=0, label=f'range over rotors | {label}')
        ax.plot(t, omega.mean(axis=1), color=color, lw=1.2,
                label=f'mean $\\omega_{{r,1}}$ | {label} ({omega.mean():.0f} rad/s)')
        # the axis ends at the 1st percentile: brief dips at segment switches would
        # otherwise squash the few-% difference this figure is about
        top = max(top, float(omega.max()))
        bottom = min(bottom, float(np.percentile(omega.min(axis=1), 1)))
        lowest = min(lowest, float(omega.min()))
    ax.set_ylim(bottom - 0.08 * (top - bottom), None)
    if lowest < bottom - 0.08 * (top - bottom):
        ax.text(0.99, 0.02, f'axis cut: brief dips down to {lowest:.0f} rad/s', ha='right',
                transform=ax.transAxes, fontsize='x-small', color='0.3')
    limits = [rotor_limits(r, s, 1) for r, s in zip(runs, scenarios)]
    known = [lim for lim in limits if lim is not None]
    if known:
        w_max = min(lim[1] for lim in known)
        margin = 0.08 * max(max(top, w_max) - bottom, 1.0)
        ax.axhspan(w_max, max(top, w_max) + margin, color=SATURATION_GREY, zorder=0,
                   label=f'saturation ω ≥ ω_max = {w_max:g} rad/s')
        ax.set_ylim(bottom - margin, max(top, w_max) + margin)
    finish_time_plot(ax, 'leader rotor speed ω [rad/s]',
                     f'leader (UAV 1) rotor speeds: {labels[0]} vs {labels[1]}',
                     loc='lower left', ncols=2)
    return fig


def _percent(a: float, b: float) -> str:
    return f'{(b - a) / a * 100:+.2f} %' if a and math.isfinite(a) and math.isfinite(b) else '-'


def comparison_numbers(runs: Sequence[Run], labels: Sequence[str],
                       scenarios: Sequence[Scenario | None]) -> list[str]:
    """The table `compare` prints: payload swing, leader rotor speed, virtual-constraint error
    per follower, over the common time span; the last column is (B - A) / A."""
    t_end = common_end(runs)
    width = max(10, max(len(label) for label in labels) + 2)
    lines = [f'compared over t = 0 .. {t_end:.1f} s (the shorter run)',
             f'{"":34}{labels[0]:>{width}}{labels[1]:>{width}}{"B vs A":>10}']
    for name, a, b in comparison_rows(runs, scenarios):
        cells = [f'{v:.3f}' if abs(v) < 100 else f'{v:.1f}' for v in (a, b)]
        cells = [c if c != 'nan' else '-' for c in cells]
        lines.append(f'{name:34}{cells[0]:>{width}}{cells[1]:>{width}}{_percent(a, b):>10}')
    lines.append("swing: the payload's horizontal distance from its static-equilibrium place "
                 'under the UAVs (multilift_sim.statistics.payload_swing)')
    lines.append("|g_vc|: norm of a follower's virtual-constraint rows")
    return lines


def _compare_needs(run: Run) -> list[str]:
    need = [PAYLOAD_ODOM, uav_topic(1, ROTOR_CMD)]
    return [t for t in need if not run.has(t)]


def compare_main(argv: list[str]) -> int:
    """`multilift compare BAG_A BAG_B [--out DIR] [--labels A B]`: seed Fig. 4.15-4.17 with both
    runs on the same axes, and a few numbers. Returns the exit code (0 done, 2 bad input)."""
    parser = Parser(prog='multilift compare', description='compare two recorded runs')
    parser.add_argument('bags', nargs=2, metavar='BAG', help='two bag directories: A and B')
    parser.add_argument('--out', help='output directory (default: BAG_A/compare_<name of B>)')
    parser.add_argument('--labels', nargs=2, metavar=('A', 'B'),
                        help='legend names (default: the scenario names)')
    parser.add_argument('--scenario-a', help='scenario of A if its summary.json has none')
    parser.add_argument('--scenario-b', help='scenario of B if its summary.json has none')
    args = parse_args(parser, argv)
    if isinstance(args, int):
        return args
    runs = [load_bag(bag) for bag in args.bags]
    if any(r is None for r in runs):
        return 2
    for run in runs:
        missing = _compare_needs(run)
        if missing:
            print(f'error: bag {run.path} has no {", ".join(missing)}', file=sys.stderr)
            return 2
    labels = list(args.labels) if args.labels else [r.label for r in runs]
    if labels[0] == labels[1]:
        labels = [f'{labels[0]} (A)', f'{labels[1]} (B)']
    scenarios = [plot_context(r, s).scenario for r, s in zip(runs, (args.scenario_a,
                                                                   args.scenario_b))]
    out = Path(args.out) if args.out else runs[0].path / f'compare_{runs[1].path.name}'
    out.mkdir(parents=True, exist_ok=True)
    written = [save_figure(fig_compare_payload(runs, labels), out / 'compare_payload.png')]
    if any(r.followers for r in runs):
        written.append(save_figure(fig_compare_formation_error(runs, labels, scenarios),
                                   out / 'compare_formation_error.png'))
    else:
        print('skipped compare_formation_error: neither run has followers', file=sys.stderr)
    written.append(save_figure(fig_compare_leader_rotors(runs, labels, scenarios),
                               out / 'compare_leader_rotor_speed.png'))
    for path in written:
        print(path)
    print('\n'.join(comparison_numbers(runs, [f'A: {labels[0]}', f'B: {labels[1]}'],
                                         scenarios)))
    return 0
