"""What every multilift figure shares (`plot`, `compare`, `animate`, the report): the Agg
backend, colours, labels and line widths per UAV, axis helpers, PNG output, and the bag and
argument handling of the plotting commands. World frame, z up, SI units.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from multilift_tools.bagdata import Run, load_run, run_scenario  # noqa: E402

if TYPE_CHECKING:
    from multilift_sim.multirotor import MultirotorParams
    from multilift_sim.scenario import Scenario

WORLD = 'world frame, z up'
TIME_LABEL = 't [s] (simulated)'
PAYLOAD_COLOR = 'black'
DPI = 120
SATURATION_GREY = '0.82'
EVENT_COLOR = 'tab:red'  # a scenario event's line (mark_events)
AXES_XYZ = ('x', 'y', 'z')
FLAG_STRIP = 0.06  # a `shade_flags` strip's height, share of the axes


def uav_color(i: int) -> str:
    """Matplotlib colour of UAV i (1 = leader), the same in every figure."""
    return f'C{(i - 1) % 10}'


def uav_width(i: int, base: float = 1.2) -> float:
    """Line width of UAV i: the leader widest, so that followers drawn on top of an identical
    curve (symmetric formations) leave it visible."""
    return base + 0.9 * max(0, 3 - i) / 2


def uav_label(i: int) -> str:
    """Legend text of UAV i."""
    return 'UAV 1 (leader)' if i == 1 else f'UAV {i}'


@dataclass(frozen=True)
class Context:
    """What a figure function needs: the run, and its scenario if found (else None)."""

    run: Run
    scenario: Scenario | None


# -- small helpers ---------------------------------------------------------------------------
def finish_time_axes(axes: Sequence[Axes]) -> None:
    """Grid on every axes; the simulated-time label under the last."""
    for ax in axes:
        ax.grid(True, alpha=0.35)
    axes[-1].set_xlabel(TIME_LABEL)


def finish_time_plot(ax: Axes, ylabel: str, title: str, **legend_options: Any) -> None:
    """A one-axes figure against time finished: its y label, its title (medium), the legend
    (`legend`, with legend_options) and `finish_time_axes`."""
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize='medium')
    legend(ax, **legend_options)
    finish_time_axes([ax])


def mark_events(axes: Sequence[Axes], events: Sequence[tuple[float, str]]) -> None:
    """A dashed line at each event's time [s] on every time axes, its description written
    along the line on the first."""
    for t, text in events:
        for k, ax in enumerate(axes):
            ax.axvline(t, color=EVENT_COLOR, ls='--', lw=0.9, alpha=0.85)
            if k == 0:
                ax.text(t, 0.98, f' {text}', transform=ax.get_xaxis_transform(), rotation=90,
                        fontsize='x-small', color=EVENT_COLOR, ha='right', va='top')


def legend(ax: Axes, **kwargs: Any) -> None:
    """The legend style of every figure (small, nearly opaque)."""
    ax.legend(fontsize='small', framealpha=0.85, **kwargs)


def value_span(values: np.ndarray) -> tuple[float, float]:
    """(min, max) of `values`, NaN ignored."""
    lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
    return lo, hi


def shade_flags(ax: Axes, t: np.ndarray, mask: np.ndarray, label: str,
                color: str = 'tab:red', side: str = 'top') -> None:
    """A strip along the top (or `side='bottom'`) of `ax` where `mask` is True (time
    intervals); its height FLAG_STRIP of the axes."""
    if not mask.any():
        return
    low, high = (1.0 - FLAG_STRIP, 1.0) if side == 'top' else (0.0, FLAG_STRIP)
    ax.fill_between(t, low, high, where=mask, step='mid', color=color, alpha=0.8,
                    transform=ax.get_xaxis_transform(), label=label, linewidth=0)


def equal_3d(ax: Any, points: np.ndarray, pad: float = 0.5) -> None:
    """Axis limits with equal scale on x, y, z, holding `points` (k, 3) [m]."""
    lo, hi = points.min(axis=0) - pad, points.max(axis=0) + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)


def formation_row_labels(scenario: Scenario | None, i: int, m: int) -> tuple[list[str], str]:
    """Labels and unit of follower i's m virtual-constraint rows (multilift_control.formation
    row order); generic 'row k' when the geometry is unknown."""
    kind = scenario.formation.geometry if scenario is not None and scenario.formation else None
    if kind in ('linear', 'v') and m == 3:
        return [f'$g_{{vc}}$ {a}: $(r_1 - r_{i})_{a}$ - $d_{a}$' for a in AXES_XYZ], 'm'
    if kind == 'distance' and m == 1:
        return [f'$|r_1 - r_{i}|^2 - d^2$'], 'm²'
    if kind == 'circle':
        n = scenario.n_uavs
        pairs = [(1, j) for j in range(2, n + 1)] + [(j, j + 1) for j in range(2, n)]
        mine = [p for p in pairs if i in p]
        if len(mine) == m:
            return [f'$|r_{a} - r_{b}|^2 - c_{b}^2$' if a == 1 else f'$|r_{a} - r_{b}|^2 - d^2$'
                    for a, b in mine], 'm²'
    return [f'row {k + 1}' for k in range(m)], 'm, or m² for distance rows'


def vehicle_of(ctx: Context, i: int) -> MultirotorParams | None:
    """UAV i's vehicle parameters from the scenario, None without one."""
    return ctx.scenario.uavs[i - 1].vehicle if ctx.scenario is not None else None


def save_figure(fig: Figure, path: Path) -> Path:
    """Write `fig` as PNG to `path` and close it."""
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


# -- command line ----------------------------------------------------------------------------
class Parser(argparse.ArgumentParser):
    """argparse that raises instead of exiting, so the *_main functions return exit codes."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise UsageError(f'{self.prog}: {message}')


class UsageError(Exception):
    """A bad command line (exit code 2)."""


def parse_args(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace | int:
    """The parsed arguments, or the exit code: 2 with usage and one `error:` line, 0 after
    --help."""
    try:
        return parser.parse_args(argv)
    except UsageError as exc:
        print(parser.format_usage().rstrip(), file=sys.stderr)
        print(f'error: {exc}', file=sys.stderr)
        return 2
    except SystemExit as exc:  # --help
        return int(exc.code or 0)


def load_bag(bag: str) -> Run | None:
    """The run of bag directory `bag`, or None after one `error:` line on stderr."""
    try:
        return load_run(bag)
    except (FileNotFoundError, ValueError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return None


def plot_context(run: Run, scenario: str | None) -> Context:
    """The run with its scenario (`scenario`, else the bag's summary.json); a note on stderr
    when none is found."""
    found, note = run_scenario(run, scenario)
    if found is None:
        print(f'note: {note}; rotor limits inferred from the saturation flags, no gusts or '
              'max thrust drawn', file=sys.stderr)
    return Context(run, found)


def parse_and_load(parser: argparse.ArgumentParser, argv: list[str], default_out: str
                   ) -> tuple[argparse.Namespace, Run, Path] | int:
    """Parse `argv` (a positional `bag`, an optional `--out`) and load the bag: (arguments,
    run, where the output goes: `--out`, else `default_out` in the bag's folder), or the exit
    code (parse_args's, or 2 after load_bag's `error:` line)."""
    args = parse_args(parser, argv)
    if isinstance(args, int):
        return args
    run = load_bag(args.bag)
    if run is None:
        return 2
    return args, run, Path(args.out) if args.out else run.path / default_out
