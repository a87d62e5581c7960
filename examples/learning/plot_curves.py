"""The learning curves of train_ppo.py runs (each DIR/progress.csv) in one figure: the mean
episode return and length of the last 100 episodes against environment steps, a line per run.

    python examples/learning/plot_curves.py runs/ppo_hover_s0 runs/ppo_hover_s1 \
        --out docs/figures/learning_ppo_hover.png
"""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
from matplotlib import pyplot as plt  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('runs', nargs='+', help='train_ppo.py output folders')
    parser.add_argument('--out', required=True, help='the PNG to write')
    args = parser.parse_args()
    fig, (returns, lengths) = plt.subplots(1, 2, figsize=(10, 3.8))
    for run in args.runs:
        with open(Path(run) / 'progress.csv') as handle:
            rows = [r for r in csv.DictReader(handle) if r['return_mean']]
        steps = [int(r['steps']) for r in rows]
        returns.plot(steps, [float(r['return_mean']) for r in rows], label=Path(run).name)
        lengths.plot(steps, [float(r['length_mean']) / 100 for r in rows], label=Path(run).name)
    returns.set(xlabel='environment steps', ylabel='episode return (mean of the last 100)')
    lengths.set(xlabel='environment steps', ylabel='episode length [s]')
    returns.legend()
    fig.tight_layout()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=100)
    print(args.out)


if __name__ == '__main__':
    main()
