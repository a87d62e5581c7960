"""An estimator's consistency, the standard way (Bar-Shalom, Li, Kirubarajan 2001, Sec. 5.4;
docs/estimation.md): from the true state and the `ekf`'s memory of every UAV, the normalised
estimation error squared (NEES) of position (3 dof) and of attitude (3 dof), and the
normalised innovation squared (NIS, 6 dof) of its updates; over N independent runs the mean
NEES of a consistent filter lies inside the chi-square interval `mean_bounds` at 95 % of the
time steps. numpy, no numba: an analysis of arrays the run keeps."""
from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.spatial.transform import Rotation

from multilift_sim.estimators.ekf import (COVARIANCE, DELAYED, NIS, NIS_TICK, NOMINAL,
                                          UPDATE_DOF)
from multilift_sim.estimators.error_state import (ERROR_ATTITUDE, ERROR_POSITION, ERROR_SIZE,
                                                  NOMINAL_POSITION, NOMINAL_QUATERNION)
from multilift_sim.formation_params import StateLayout


def mean_bounds(dof: int, runs: int, probability: float = 0.95) -> tuple[float, float]:
    """The two-sided `probability` interval of the mean of `runs` independent chi-square
    variables of `dof` degrees of freedom (runs * mean ~ chi2(runs * dof))."""
    tail = 0.5 * (1.0 - probability)
    low, high = stats.chi2.ppf([tail, 1.0 - tail], runs * dof)
    return float(low) / runs, float(high) / runs


def _scalar_first(q: np.ndarray) -> Rotation:
    """scipy's Rotation of quaternions (..., 4) ordered (w, x, y, z)."""
    return Rotation.from_quat(np.asarray(q)[..., [1, 2, 3, 0]])


def ekf_nees(state: np.ndarray, memory: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(position NEES (n,), attitude NEES (n,)) of every UAV of a formation state (its x) and
    the ekf's memory of each (n, M): e^T P^-1 e with e the true minus the estimated position
    [m], and the attitude error Log(q_hat^-1 q) [rad] (body; q = q_hat (x) Exp(dtheta))."""
    n = memory.shape[0]
    layout = StateLayout(n)
    nominal = memory[:, NOMINAL:NOMINAL + NOMINAL_QUATERNION + 4]
    covariance = memory[:, COVARIANCE:DELAYED].reshape(n, ERROR_SIZE, ERROR_SIZE)
    position_error = (layout.uav_positions(state)
                      - nominal[:, NOMINAL_POSITION:NOMINAL_POSITION + 3])
    estimated = _scalar_first(nominal[:, NOMINAL_QUATERNION:NOMINAL_QUATERNION + 4])
    attitude_error = (estimated.inv() * _scalar_first(layout.uav_quaternions(state))).as_rotvec()
    out = []
    for error, start in ((position_error, ERROR_POSITION), (attitude_error, ERROR_ATTITUDE)):
        block = covariance[:, start:start + 3, start:start + 3]
        out.append(np.einsum('ni,ni->n', error, np.linalg.solve(block, error[..., None])[..., 0]))
    return out[0], out[1]


def ekf_nis(memory: np.ndarray, tick: int) -> np.ndarray:
    """Every UAV's NIS of the update at `tick` (UPDATE_DOF dof), NaN where none was made."""
    return np.where(memory[:, NIS_TICK] == tick, memory[:, NIS], np.nan)


def share_inside(means: np.ndarray, bounds: tuple[float, float]) -> float:
    """The share of the values `means` (NaN ones left out) inside `bounds`."""
    values = means[np.isfinite(means)]
    return float(np.mean((values >= bounds[0]) & (values <= bounds[1])))


__all__ = ['UPDATE_DOF', 'ekf_nees', 'ekf_nis', 'mean_bounds', 'share_inside']
