"""Piecewise polynomials through timed points, solved once when a scenario is read: the
minimum-snap trajectory of `waypoints` and the clamped cubic spline of `file`.

A trajectory is `knots` (m + 1,) times [s] and `coefficients` (m, AXES, ORDER): piece k,
axis a (x, y, z [m], world z up; yaw [rad]) is sum_j c[k, a, j] (t - knots[k])^j on
[knots[k], knots[k + 1]], local time in seconds, the lowest power first. The compiled tick
evaluates it (`multilift_control.laws.reference.polynomial_reference`); before the first knot
it holds the first point, after the last the last.

Minimum snap (Mellinger & Kumar 2011, "Minimum snap trajectory generation and control for
quadrotors", ICRA): the trajectory through the points at the given times minimising the
integral of |d^4 p / dt^4|^2, at rest at both ends (velocity, acceleration and jerk 0). With the
times fixed the QP's optimum is, on each piece, a polynomial of degree 7 (its Euler-Lagrange
equation is d^8 p / dt^8 = 0) whose derivatives 1..6 are continuous at the interior points
(the optimality conditions at a point where only the position is fixed): 8 conditions a piece,
one linear system of 8 m unknowns per axis, solved here in closed form (`minimum_snap`).
"""
from __future__ import annotations

from math import factorial

import numpy as np
from scipy.interpolate import CubicSpline

from multilift_sim.scenario.config import MissionConfig

AXES = 4        # x, y, z [m], yaw [rad]
ORDER = 8       # coefficients a piece and axis: degree 7 at most
DEGREE = ORDER - 1
REST_DERIVATIVES = 3  # velocity, acceleration, jerk: 0 at both ends of a minimum-snap path
CONTINUOUS_DERIVATIVES = 6  # 1..6 continuous at an interior point of a minimum-snap path


def _derivative_row(order: int, s: float) -> np.ndarray:
    """d^order/ds^order of (1, s, s^2, ..., s^DEGREE) at s."""
    row = np.zeros(ORDER)
    for j in range(order, ORDER):
        row[j] = factorial(j) // factorial(j - order) * s ** (j - order)
    return row


def minimum_snap(times: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The minimum-snap coefficients (m, D, ORDER) through `points` (m + 1, D) at `times`
    (m + 1,) [s], increasing, at rest at both ends; the polynomial of piece k in t - times[k].

    Solved on each piece's normalised time s = (t - t_k) / T_k in [0, 1] (the system's scale
    then does not depend on the durations), then c_j = c'_j / T_k^j."""
    times = np.asarray(times, dtype=float)
    points = np.asarray(points, dtype=float)
    durations = np.diff(times)
    m = len(durations)
    size = ORDER * m
    system = np.zeros((size, size))
    right = np.zeros((size, points.shape[1]))
    row = 0
    for k in range(m):  # each piece meets its two points
        columns = slice(ORDER * k, ORDER * (k + 1))
        system[row, columns] = _derivative_row(0, 0.0)
        right[row] = points[k]
        system[row + 1, columns] = _derivative_row(0, 1.0)
        right[row + 1] = points[k + 1]
        row += 2
    for order in range(1, REST_DERIVATIVES + 1):  # at rest at both ends
        system[row, 0:ORDER] = _derivative_row(order, 0.0) / durations[0] ** order
        system[row + 1, ORDER * (m - 1):] = _derivative_row(order, 1.0) / durations[-1] ** order
        row += 2
    for k in range(m - 1):  # derivatives 1..6 continuous at interior point k + 1
        for order in range(1, CONTINUOUS_DERIVATIVES + 1):
            system[row, ORDER * k:ORDER * (k + 1)] = (_derivative_row(order, 1.0)
                                                      / durations[k] ** order)
            system[row, ORDER * (k + 1):ORDER * (k + 2)] = (-_derivative_row(order, 0.0)
                                                            / durations[k + 1] ** order)
            row += 1
    normalised = np.linalg.solve(system, right).reshape(m, ORDER, -1)
    scale = durations[:, None] ** -np.arange(ORDER)[None, :]  # (m, ORDER)
    return np.ascontiguousarray((normalised * scale[:, :, None]).transpose(0, 2, 1))


def clamped_cubic(times: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The clamped cubic spline (m, D, ORDER) through `points` (m + 1, D) at `times` (m + 1,)
    [s]: position, velocity and acceleration continuous, velocity 0 at both ends
    (scipy.interpolate.CubicSpline, bc_type='clamped'); coefficients past the cube are 0."""
    spline = CubicSpline(np.asarray(times, dtype=float), np.asarray(points, dtype=float),
                         axis=0, bc_type='clamped')
    cubic = spline.c[::-1]  # (4, m, D), the lowest power first
    out = np.zeros((cubic.shape[1], cubic.shape[2], ORDER))
    out[:, :, :4] = cubic.transpose(1, 2, 0)
    return out


def evaluate(knots: np.ndarray, coefficients: np.ndarray, t: float, order: int = 0
             ) -> np.ndarray:
    """The trajectory's `order`-th derivative at t [s], (AXES,): numpy, for tests and set-up
    (the tick's is compiled); held at the ends (derivatives 0 there)."""
    knots = np.asarray(knots, dtype=float)
    if t <= knots[0] or t >= knots[-1]:
        if order:
            return np.zeros(coefficients.shape[1])
        end = 0 if t <= knots[0] else -1
        local = 0.0 if end == 0 else knots[-1] - knots[-2]
        return coefficients[end] @ _derivative_row(0, local)
    k = int(np.searchsorted(knots, t, side='right')) - 1
    return coefficients[k] @ _derivative_row(order, t - knots[k])


def polynomial_mission(times: np.ndarray, table: np.ndarray, coefficients: np.ndarray
                       ) -> MissionConfig:
    """A `polynomial` source's MissionConfig: its knots `times` (m + 1,) [s], `coefficients`
    (m, AXES, ORDER) through `table` (m + 1, AXES): x, y, z [m], yaw [rad]; the start its
    first point."""
    return MissionConfig(
        start=tuple(float(v) for v in table[0, :3]), segments=(),
        knots=tuple(float(t) for t in times),
        coefficients=tuple(tuple(tuple(float(c) for c in axis) for axis in piece)
                           for piece in coefficients),
        points=tuple(tuple(float(v) for v in row[:3]) for row in table))
