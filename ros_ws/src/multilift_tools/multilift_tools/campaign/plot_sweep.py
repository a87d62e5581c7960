"""`multilift plot-sweep TABLE [--out DIR] [--rank METRIC] [--worst N]`: a sweep campaign's
table (Parquet or CSV from `multilift sweep`) as pictures.

One PNG per varied parameter (DIR/PARAM.png, default DIR: the table's full file name +
`_plots` beside it, so runs.csv_plots/ and runs.parquet_plots/ do not overwrite each other)
with a panel per run statistic that varies over the table against that parameter (a statistic
with one value in every run, such as simulated_time, takes no panel: it is named on stderr),
axes labelled with their units (`multilift_sim.units`): a sampled parameter is a scatter (each
run a dot), a grid parameter a line through the mean at each value with the min-max spread of
the runs there shaded; failed runs (stopped or error) that still have the figure are red
crosses. Which parameters are grid or sampled comes from the campaign's metadata (in the
Parquet file, beside a CSV as FILE.campaign.json: `campaign.table`); a CSV without it (the
table written to stdout) is guessed: a parameter with at most 12 distinct values, repeated, is
drawn as a grid. And DIR/worst_runs.md: the failed runs, then the N (default 10) worst by
METRIC (default: the first of tracking_error_max, formation_error_max, max_abs_g the table
fills), also printed. Exit codes: 0 done, 2 bad input.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from multilift_sim.units import label
from multilift_tools import campaign as cp

GRID_MAX_VALUES = 12
RANK_DEFAULTS = ('tracking_error_max', 'formation_error_max', 'max_abs_g')
FIXED = ('run', 'seed', 'status', 'message', 'wall_time', 'bag')


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def parameters(columns: list[str]) -> list[str]:
    """The parameter columns: those between `run` and `seed`."""
    return columns[columns.index('run') + 1:columns.index('seed')]


def metrics(columns: list[str], rows: list[dict]) -> list[str]:
    """The statistics columns with at least one number."""
    return [c for c in columns[columns.index('seed') + 1:] if c not in FIXED
            and any(_number(r.get(c)) is not None for r in rows)]


def varying(metric_names: list[str], rows: list[dict]) -> list[str]:
    """The statistics whose numbers are not all the same (the ones worth a panel)."""
    out = []
    for name in metric_names:
        numbers = [n for n in (_number(r.get(name)) for r in rows) if n is not None]
        if max(numbers) - min(numbers) > 1e-12 * max(1.0, abs(max(numbers))):
            out.append(name)
    return out


def is_grid(name: str, rows: list[dict], meta: dict) -> bool:
    if meta:
        return name in meta.get('grid', {})
    values = [r.get(name) for r in rows]
    distinct = {cp.format_value(v) for v in values}
    return len(distinct) <= GRID_MAX_VALUES and len(distinct) < len(values)


def _positions(name: str, rows: list[dict]) -> tuple[list[float], list[str] | None]:
    """x of each row: the value, or the index of a non-numeric value among the sorted
    distinct ones (then the tick labels)."""
    numbers = [_number(r.get(name)) for r in rows]
    if all(n is not None for n in numbers):
        return numbers, None
    labels = sorted({cp.format_value(r.get(name)) for r in rows})
    return [float(labels.index(cp.format_value(r.get(name)))) for r in rows], labels


def plot_parameter(name: str, rows: list[dict], metric_names: list[str], grid: bool,
                   path: Path) -> None:
    """`draw_parameter`'s figure as the PNG `path`."""
    import matplotlib.pyplot as plt

    fig = draw_parameter(name, rows, metric_names, grid)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def draw_parameter(name: str, rows: list[dict], metric_names: list[str], grid: bool):
    """The figure of parameter `name`: a panel per statistic of `metric_names`, x and y
    labelled with their units."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    xs, labels = _positions(name, rows)
    cols = min(3, len(metric_names))
    nrows = math.ceil(len(metric_names) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.0 * nrows), squeeze=False)
    for ax, metric in zip(axes.flat, metric_names):
        ok = [(x, _number(r.get(metric))) for x, r in zip(xs, rows) if r.get('status') == 'ok']
        ok = [(x, y) for x, y in ok if y is not None]
        bad = [(x, _number(r.get(metric))) for x, r in zip(xs, rows) if r.get('status') != 'ok']
        bad = [(x, y) for x, y in bad if y is not None]
        if grid and ok:
            at: dict[float, list[float]] = {}
            for x, y in ok:
                at.setdefault(x, []).append(y)
            keys = sorted(at)
            mean = [sum(at[k]) / len(at[k]) for k in keys]
            ax.fill_between(keys, [min(at[k]) for k in keys], [max(at[k]) for k in keys],
                            alpha=0.25, color='tab:blue', label='min-max')
            ax.plot(keys, mean, 'o-', color='tab:blue', label='mean')
        elif ok:
            ax.scatter(*zip(*ok), s=12, color='tab:blue', label='ok')
        if bad:
            ax.scatter(*zip(*bad), marker='x', color='tab:red', label='failed')
        if labels is not None:
            ax.set_xticks(range(len(labels)), labels, rotation=30, fontsize=7)
        ax.set_xlabel(label(name))
        ax.set_ylabel(label(metric))
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(metric_names):]:
        ax.axis('off')
    axes.flat[0].legend(fontsize=7)
    kind = 'grid: mean and min-max of the runs at each value' if grid else 'sampled: each run'
    fig.suptitle(f'{name} ({kind}; {len(rows)} runs)')
    fig.tight_layout()
    return fig


def worst_runs(columns: list[str], rows: list[dict], rank: str, count: int) -> str:
    """Markdown: every failed run, then the `count` worst ok runs by `rank` (largest first)."""
    params = parameters(columns)
    failed = [r for r in rows if r.get('status') != 'ok']
    ok = sorted((r for r in rows if r.get('status') == 'ok'
                 and _number(r.get(rank)) is not None), key=lambda r: -_number(r.get(rank)))
    head = ['run', *params, 'status', rank, 'message']
    lines = [f'Worst runs by {rank} ({len(failed)} failed of {len(rows)}, then the {count} '
             'largest)', '', '| ' + ' | '.join(head) + ' |',
             '|' + '---|' * len(head)]
    for row in failed + ok[:count]:
        cells = [_cell(row.get(c)) for c in head]
        lines.append('| ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines) + '\n'


def _cell(value: Any) -> str:
    if value is None:
        return ''
    if isinstance(value, float):
        return f'{value:.6g}'
    return cp.format_value(value).replace('|', '\\|')


def plot_sweep_main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog='multilift plot-sweep',
                                     description='figures and a worst-runs table of a sweep')
    parser.add_argument('table', help='a table written by `multilift sweep --out`')
    parser.add_argument('--out', help='directory (default: TABLE_plots beside the table)')
    parser.add_argument('--rank', help='the statistic that ranks the worst runs')
    parser.add_argument('--worst', type=int, default=10, help='how many worst ok runs')
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:
        return 0 if exc.code == 0 else 2
    table = Path(args.table)
    try:
        columns, rows, meta = cp.read_table(table)
    except (OSError, ValueError) as exc:
        print(f'error: {table}: {exc}'.replace('\n', ' '), file=sys.stderr)
        return 2
    if 'run' not in columns or 'seed' not in columns or 'status' not in columns:
        print(f'error: {table}: not a sweep table (no run, seed, status columns)',
              file=sys.stderr)
        return 2
    metric_names = metrics(columns, rows)
    rank = args.rank or next((m for m in RANK_DEFAULTS if m in metric_names), None)
    if rank is not None and rank not in metric_names:
        print(f'error: --rank {rank}: not a statistic with numbers in the table (have: '
              f'{", ".join(metric_names)})', file=sys.stderr)
        return 2
    out = Path(args.out) if args.out else table.with_name(table.name + '_plots')
    out.mkdir(parents=True, exist_ok=True)
    panels = varying(metric_names, rows)
    constant = [m for m in metric_names if m not in panels]
    if constant:
        print('the same in every run, no panel: ' + ', '.join(
            f'{m} = {_number(next(r[m] for r in rows if _number(r.get(m)) is not None)):g}'
            for m in constant), file=sys.stderr)
    written = []
    for name in parameters(columns):
        if panels and rows:
            path = out / f'{name}.png'
            plot_parameter(name, rows, panels, is_grid(name, rows, meta), path)
            written.append(path)
    text = worst_runs(columns, rows, rank or 'wall_time', args.worst)
    (out / 'worst_runs.md').write_text(text)
    sys.stdout.write(text)
    print(f'{len(written)} figure(s) and worst_runs.md in {out}', file=sys.stderr)
    return 0


if __name__ == '__main__':
    sys.exit(plot_sweep_main())
