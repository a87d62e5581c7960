"""Numbers measured on recorded runs, shared by the figures, `compare` and the reproduction
report: interpolation onto another time base, time windows, the pendulum period, payload swing,
virtual-constraint error norms, the comparison table's rows. No matplotlib. World frame, z up,
SI units.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Sequence

import numpy as np

from multilift_tools.bagdata import Run

if TYPE_CHECKING:
    from multilift_sim.scenario import Scenario


def interp_rows(t_to: np.ndarray, t_from: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Linear interpolation of the columns of `values` (T_from, k) onto `t_to`."""
    return np.stack([np.interp(t_to, t_from, values[:, k]) for k in range(values.shape[1])],
                    axis=1)


def common_end(runs: Sequence[Run]) -> float:
    """The end [s] of the shortest run: the span every run covers."""
    return min(float(r.t[-1]) for r in runs)


def until(t: np.ndarray, t_end: float) -> np.ndarray:
    """Mask of the times `t` [s] up to `t_end` [s] (1 ns tolerance)."""
    return t <= t_end + 1e-9


def pendulum_period(run: Run, scenario: Scenario | None, gravity: float = 9.81) -> float:
    """2 pi sqrt(h/g) [s], h the cable length of the scenario or else the mean height of the
    UAVs' centroid above the payload [m]."""
    if scenario is not None:
        h = float(np.mean([u.cable_length for u in scenario.uavs]))
        gravity = scenario.simulation.gravity
    else:
        centroid = run.uav_positions().mean(axis=0)
        p = interp_rows(run.t, run.payload_time, run.payload_position())
        h = float(np.mean(centroid[:, 2] - p[:, 2]))
    return 2 * math.pi * math.sqrt(max(h, 1e-3) / gravity)


def swing_metrics(run: Run, scenario: Scenario | None, t_end: float) -> dict[str, float]:
    """Payload swing: its horizontal offset d(t) from the UAVs' centroid [m] (world x, y),
    minus the moving mean of d over one pendulum period; returns the max and RMS of |that|
    [m], and the period [s] used. Over t <= t_end."""
    keep = until(run.t, t_end)
    t = run.t[keep]
    p = interp_rows(t, run.payload_time, run.payload_position())
    d = p[:, :2] - run.uav_positions()[:, keep, :2].mean(axis=0)
    period = pendulum_period(run, scenario)
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    width = max(1, min(len(t), int(round(period / dt))))
    kernel = np.ones(width) / width
    smooth = np.stack([np.convolve(np.pad(d[:, k], (width // 2, width - 1 - width // 2),
                                          mode='edge'), kernel, mode='valid')
                       for k in range(2)], axis=1)
    swing = np.linalg.norm(d - smooth, axis=1)
    return {'max': float(swing.max()), 'rms': float(np.sqrt(np.mean(swing ** 2))),
            'period': period}


def formation_norms(run: Run, i: int, t_end: float) -> np.ndarray:
    """|g_vc| of follower i [m, or m² for distance rows] up to t_end [s]."""
    keep = until(run.formation_error_time(i), t_end)
    return np.linalg.norm(run.formation_errors(i)[keep], axis=1)


def comparison_rows(runs: Sequence[Run], scenarios: Sequence[Scenario | None]
                    ) -> list[tuple[str, float, float]]:
    """(quantity with unit, value of A, value of B) over the common time span; NaN where a run
    has no such quantity (a follower it lacks)."""
    t_end = common_end(runs)
    swings = [swing_metrics(r, s, t_end) for r, s in zip(runs, scenarios)]
    rows = [('payload swing, max [m]', swings[0]['max'], swings[1]['max']),
            ('payload swing, rms [m]', swings[0]['rms'], swings[1]['rms'])]
    means = [float(r.rotor_speeds(1)[until(r.rotor_time(1), t_end)].mean()) for r in runs]
    rows.append(('leader mean rotor speed [rad/s]', means[0], means[1]))
    followers = sorted(set(runs[0].followers) | set(runs[1].followers))
    for stat, fn in (('mean', np.mean), ('max', np.max)):
        for i in followers:
            values = [float(fn(formation_norms(r, i, t_end))) if i in r.followers else math.nan
                      for r in runs]
            rows.append((f'{stat} |g_vc| UAV {i} [m]', values[0], values[1]))
    return rows
