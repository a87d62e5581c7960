"""Where a rigid-body payload hangs at rest from its UAVs' cables (issue 35: a reorganising
formation of a rigid body started at `formation.start_places`): the pose of least potential
energy along its apparent weight with every cable within its length, found by constrained
minimisation (scipy's SLSQP), the equilibrium of Eq. 2.73 solved as a minimum rather than
from its force and moment rows (which multilift_control's `laws.rigid_statics` solves by
Newton's method; the two are tested against each other). World frame z up, SI units."""
from __future__ import annotations

import math

import numpy as np


def _rotation(vector: np.ndarray) -> np.ndarray:
    """exp([vector]x) (3, 3): the rotation by the rotation vector `vector` [rad]."""
    angle = float(np.linalg.norm(vector))
    if angle == 0.0:
        return np.eye(3)
    k = vector / angle
    skew = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * skew + (1.0 - math.cos(angle)) * skew @ skew


def hanging_body(uavs: np.ndarray, lengths: np.ndarray, attach_points: np.ndarray,
                 down: np.ndarray = np.array([0.0, 0.0, -1.0])
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,) [m], quaternion (w, x, y, z) payload frame -> world) of a rigid body held
    at `attach_points` b_i (n, 3) [m], its frame, by cables of `lengths` (n,) [m] from `uavs`
    (n, 3) [m], hanging at rest under an apparent weight along the unit vector `down`: its
    centre as low along `down` as every cable lets it be (|r_i - p - R b_i| <= l_i), from the
    body level under the centroid of r_i - b_i. Raises ValueError when the minimum is not
    found to 1e-12 of a cable's length (each round of SLSQP about the last pose)."""
    uavs = np.asarray(uavs, dtype=float)
    lengths = np.asarray(lengths, dtype=float)
    attach = np.asarray(attach_points, dtype=float)
    centre = (uavs[:, :2] - attach[:, :2]).mean(axis=0)
    spans = np.linalg.norm(uavs[:, :2] - attach[:, :2] - centre, axis=1)
    if np.any(spans >= lengths):
        raise ValueError('the cables cannot reach the body level below the formation')
    depth = float(np.mean(uavs[:, 2] - np.sqrt(lengths ** 2 - spans ** 2) - attach[:, 2]))
    position = np.array([centre[0], centre[1], depth])
    rotation = np.eye(3)
    for _ in range(4):  # each round about the last pose: p + dp, exp([dtheta]x) R
        dx = _least_potential(uavs, lengths, attach, down, position, rotation)
        position, rotation = position + dx[:3], _rotation(dx[3:]) @ rotation
        if float(np.abs(dx).max()) < 1e-13 * float(lengths.max()):
            break
    gaps = uavs - position - attach @ rotation.T
    miss = np.sqrt(np.einsum('ij,ij->i', gaps, gaps)) - lengths
    if float(miss.max()) > 1e-12 * float(lengths.max()):
        raise ValueError(f'the body\'s hanging pose was not found (a cable {miss.max():.3g} m '
                         'past its length)')
    return position, _quaternion_of(rotation)


def _least_potential(uavs, lengths, attach, down, position, rotation) -> np.ndarray:
    """(dp (3,) [m], dtheta (3,) [rad]): the turn and shift of the pose (position, rotation)
    that put the body lowest along `down` with every cable within its length: SLSQP with the
    constraints' gradients (exact at the pose, first order in dtheta)."""
    from scipy.optimize import minimize  # here: scipy's import is 0.25 s of every start-up
    scale = float(lengths.max())

    def gaps(x):
        return uavs - position - x[:3] * scale - attach @ (_rotation(x[3:]) @ rotation).T

    def slack(x):  # (l_i^2 - |d_i|^2) / l^2 >= 0
        d = gaps(x)
        return (lengths ** 2 - np.einsum('ij,ij->i', d, d)) / scale ** 2

    def slope(x):  # d slack / d (dp / l, dtheta): d_i moves by -dp - dtheta x w_i
        d = gaps(x)
        arms = attach @ (_rotation(x[3:]) @ rotation).T
        return np.hstack((2.0 * d / scale, -2.0 * np.cross(d, arms) / scale ** 2))

    result = minimize(lambda x: -float(np.dot(down, x[:3])) * scale, np.zeros(6),
                      jac=lambda x: np.concatenate((-down * scale, np.zeros(3))),
                      method='SLSQP', constraints=[{'type': 'ineq', 'fun': slack,
                                                    'jac': slope}],
                      options={'ftol': 1e-16, 'maxiter': 500})
    return np.concatenate((result.x[:3] * scale, result.x[3:]))


def _quaternion_of(rotation: np.ndarray) -> np.ndarray:
    """(w, x, y, z) of a rotation matrix (3, 3), w >= 0 (Shepperd's method)."""
    trace = float(np.trace(rotation))
    k = int(np.argmax([trace, rotation[0, 0], rotation[1, 1], rotation[2, 2]]))
    if k == 0:
        w = math.sqrt(1.0 + trace) / 2.0
        q = np.array([w, (rotation[2, 1] - rotation[1, 2]) / (4 * w),
                      (rotation[0, 2] - rotation[2, 0]) / (4 * w),
                      (rotation[1, 0] - rotation[0, 1]) / (4 * w)])
    else:
        i, j, m = k - 1, k % 3, (k + 1) % 3
        v = np.zeros(3)
        v[i] = math.sqrt(1.0 + 2 * rotation[i, i] - trace) / 2.0
        w = (rotation[m, j] - rotation[j, m]) / (4 * v[i])
        v[j] = (rotation[j, i] + rotation[i, j]) / (4 * v[i])
        v[m] = (rotation[m, i] + rotation[i, m]) / (4 * v[i])
        q = np.concatenate(([w], v))
    return q if q[0] >= 0.0 else -q
