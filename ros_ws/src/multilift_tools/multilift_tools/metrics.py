"""Numbers measured on recorded runs, shared by the figures, `compare` and the reproduction
report: interpolation onto another time base, time windows, cable lengths, payload swing
(multilift_sim.statistics.payload_swing over a run), virtual-constraint error norms, the
comparison table's rows. No matplotlib. World frame, z up, SI units.
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


def cable_lengths(run: Run, scenario: Scenario | None) -> np.ndarray:
    """l_i [m] per cable: the scenario's, or else the mean UAV-payload distance over the run
    (a rigid cable keeps its length)."""
    if scenario is not None:
        return np.array([u.cable_length for u in scenario.uavs], dtype=float)
    p = interp_rows(run.t, run.payload_time, run.payload_position())
    return np.linalg.norm(run.uav_positions() - p[None], axis=2).mean(axis=1)


def swing_series(run: Run, scenario: Scenario | None) -> tuple[np.ndarray, np.ndarray]:
    """Payload swing over the run: the UAVs' odometry times t (T,) [s] and
    multilift_sim.statistics.payload_swing (T,) [m], the horizontal distance of the payload
    from its static-equilibrium place under the UAVs at the same tick (NaN where the cables
    cannot meet)."""
    from multilift_sim.statistics import payload_swing

    payload = interp_rows(run.t, run.payload_time, run.payload_position())
    uavs = np.moveaxis(run.uav_positions(), 0, 1)                     # (T, n, 3)
    return run.t, payload_swing(uavs, payload, cable_lengths(run, scenario))


def peak_rms(values: np.ndarray) -> tuple[float, float]:
    """(max, rms) of the finite `values`; NaN, NaN when there are none."""
    values = values[np.isfinite(values)]
    if values.size == 0:
        return math.nan, math.nan
    return float(values.max()), float(np.sqrt(np.mean(values ** 2)))


def swing_metrics(run: Run, scenario: Scenario | None, t_end: float) -> dict[str, float]:
    """Payload swing (swing_series) over t <= t_end [s]: its max and rms [m]."""
    t, swing = swing_series(run, scenario)
    peak, rms = peak_rms(swing[until(t, t_end)])
    return {'max': peak, 'rms': rms}


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
