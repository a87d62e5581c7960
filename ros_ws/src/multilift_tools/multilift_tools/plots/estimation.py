"""The estimators' figure (issue 33 item 6; docs/estimation.md): each UAV's estimated position
less the truth (/uav{i}/estimate against /uav{i}/odom at the same stamps), per world axis
[mm], inside its 3-sigma band from the estimate's pose covariance; with a payload estimator
the payload's (/payload/estimate against /payload/odom) likewise. World frame, SI units (the
errors in mm)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from multilift_sim.topics import ESTIMATE, ODOM, PAYLOAD_ESTIMATE, PAYLOAD_ODOM, uav_topic
from multilift_tools.bagdata import Run
from multilift_tools.plot_style import Context, finish_time_axes, legend, plt

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def lacks_estimates(run: Run) -> list[str]:
    """Why the bag has no estimation figure: no /uav1/estimate (no estimator)."""
    if run.has(uav_topic(1, ESTIMATE)):
        return []
    return [f'no estimates (no {uav_topic(1, ESTIMATE)}: no estimator)']


def estimate_errors(run: Run, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """((T,) stamps [s], (T, 3) estimated position less the truth [m], (T, 3) the estimate's
    position standard deviations [m]) of UAV i (from 1; 0: the payload, /payload/estimate
    against /payload/odom), at the stamps both carry."""
    estimate, truth = ((run.topic(PAYLOAD_ESTIMATE), run.topic(PAYLOAD_ODOM)) if i == 0 else
                       (run.topic(uav_topic(i, ESTIMATE)), run.topic(uav_topic(i, ODOM))))
    common, at_estimate, at_truth = np.intersect1d(estimate.t, truth.t, return_indices=True)
    error = estimate['position'][at_estimate] - truth['position'][at_truth]
    sigma = np.sqrt(np.maximum(estimate['pose_variance'][at_estimate, :3], 0.0))
    return common, error, sigma


def fig_estimation(ctx: Context) -> Figure:
    """Per UAV (and the payload, with a payload estimator), the estimate's position error [mm]
    on each world axis in its 3-sigma band."""
    run = ctx.run
    uavs = [i for i in range(1, run.n_uavs + 1) if run.has(uav_topic(i, ESTIMATE))] + (
        [0] if run.has(PAYLOAD_ESTIMATE) else [])
    fig, axes = plt.subplots(len(uavs), 1, sharex=True, squeeze=False,
                             figsize=(9, 2.6 * len(uavs) + 1.0), layout='constrained')
    for ax, i in zip(axes[:, 0], uavs):
        t, error, sigma = estimate_errors(run, i)
        for k, axis in enumerate('xyz'):
            inside = np.mean(np.abs(error[:, k]) <= 3.0 * sigma[:, k])
            ax.plot(t, 1e3 * error[:, k], color=f'C{k}', lw=0.8,
                    label=f'{axis}: rms {1e3 * np.sqrt(np.mean(error[:, k] ** 2)):.2f} mm, '
                          f'{100 * inside:.1f} % inside 3 sigma')
            ax.fill_between(t, -3e3 * sigma[:, k], 3e3 * sigma[:, k], color=f'C{k}',
                            alpha=0.12, lw=0)
        ax.axhline(0.0, color='0.3', lw=0.6)
        ax.set_ylabel(f'{f"uav{i}" if i else "payload"} estimate - truth\n[mm] (band: 3 sigma)')
        legend(ax, loc='upper right', ncols=1)
    axes[0, 0].set_title(f'{run.label}: estimated positions against the truth', fontsize='medium')
    finish_time_axes(list(axes[:, 0]))
    return fig
