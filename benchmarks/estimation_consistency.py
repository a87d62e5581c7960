"""The EKF's consistency over a Monte Carlo (issue 33 item 2; docs/estimation.md): N runs of a
scenario with an estimator (default twin_lift_realistic, its first `--duration` seconds), each
with its own sensor seeds (imu.seed = mocap.seed = run index + 1), flown together in one Engine;
at every control tick the NEES of each UAV's position and attitude (3 dof each) averaged over
the runs, and at each update the NIS (6 dof) averaged over the runs that updated; the share of
ticks where each mean lies inside its 95 % chi-square interval, and a figure.

    python benchmarks/estimation_consistency.py [--runs 50] [--duration 30] [--png out.png]
"""
from __future__ import annotations

import argparse

import numpy as np

from multilift_sim import kernels  # noqa: F401 - NUMBA_CACHE_DIR before numba loads
from multilift_sim.estimators.consistency import UPDATE_DOF, mean_bounds, share_inside
from multilift_tools.estimation_study import monte_carlo, nis_inside


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--scenario', default='twin_lift_realistic')
    parser.add_argument('--runs', type=int, default=50)
    parser.add_argument('--duration', type=float, default=30.0)
    parser.add_argument('--png', default='')
    args = parser.parse_args()
    result = monte_carlo(args.scenario, args.runs, args.duration)
    bounds = mean_bounds(3, args.runs)
    print(f'{args.runs} runs of {args.scenario}, {args.duration:g} s; 95 % interval of the '
          f'mean NEES (3 dof): [{bounds[0]:.3f}, {bounds[1]:.3f}]')
    nis = nis_inside(result, args.runs)
    for i in range(result['position'].shape[1]):
        print(f'  uav{i + 1}: position NEES inside at '
              f'{100 * share_inside(result["position"][1:, i], bounds):.1f} % of ticks '
              f'(mean {np.mean(result["position"][1:, i]):.2f}), attitude '
              f'{100 * share_inside(result["attitude"][1:, i], bounds):.1f} % '
              f'(mean {np.mean(result["attitude"][1:, i]):.2f}), NIS (6 dof) '
              f'{100 * nis[i]:.1f} % of updates (mean {np.nanmean(result["nis"][:, i]):.2f})')
    if args.png:
        plot(result, bounds, args)


def plot(result: dict, bounds: tuple[float, float], args) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    figure, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    t = result['t']
    for ax, key, label, (low, high) in (
            (axes[0], 'position', 'mean NEES, position (3 dof)', bounds),
            (axes[1], 'attitude', 'mean NEES, attitude (3 dof)', bounds),
            (axes[2], 'nis', 'mean NIS, update (6 dof)', mean_bounds(UPDATE_DOF, args.runs))):
        for i in range(result[key].shape[1]):
            ax.plot(t, result[key][:, i], lw=0.6, label=f'uav{i + 1}')
        ax.axhline(low, color='k', ls='--', lw=0.8)
        ax.axhline(high, color='k', ls='--', lw=0.8, label='95 % interval')
        ax.set_ylabel(label)
        ax.legend(loc='upper right', fontsize=7)
    axes[2].set_xlabel('t [s]')
    axes[0].set_title(f'{args.scenario}: {args.runs} runs, {args.duration:g} s')
    figure.tight_layout()
    figure.savefig(args.png, dpi=110)
    print(f'  figure: {args.png}')


if __name__ == '__main__':
    main()
