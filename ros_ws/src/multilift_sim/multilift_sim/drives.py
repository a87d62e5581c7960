"""Prescribed UAV motion as piecewise polynomials (`uavs[i].trajectory`, issue 34 item 3): a
`Drive` splined once from a file's rows, and the drive table the compiled physics reads
(`physics.prescribed`; slots DRIVE_* of `physics.layout`). World frame (z up), SI units.

The splines (each piece a polynomial of degree 5 at most in t - t_k, `physics.layout`
DRIVE_ORDER), position, velocity and acceleration continuous:
- positions alone: the not-a-knot cubic spline (scipy's CubicSpline; no end condition imposed:
  a motion that starts moving keeps its velocity, where the mission's clamped spline would
  stop it);
- with velocities: the quintic Hermite spline through the positions and velocities, the
  accelerations at the rows those of the file or, without them, of the cubic spline of the
  velocities (so the acceleration is continuous too);
- roll, pitch, yaw: their cubic spline (not-a-knot), else level at the UAV's yaw.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from multilift_sim.physics.layout import (DRIVE_AXES, DRIVE_EULER, DRIVE_KNOTS, DRIVE_ORDER,
                                          DRIVE_PIECES, DRIVE_POSITION, FORMATION_SCALARS)


@dataclass(frozen=True)
class Drive:
    """A UAV's prescribed motion: `knots` (m + 1,) [s] and `coefficients` (m, DRIVE_AXES,
    DRIVE_ORDER) as nested tuples (a scenario is frozen): piece k, axis a (x, y, z [m], roll,
    pitch, yaw [rad]) is sum_j c[k][a][j] (t - knots[k])^j; `source` the file it came from."""
    source: str
    knots: tuple[float, ...]
    coefficients: tuple[tuple[tuple[float, ...], ...], ...]

    @property
    def start(self) -> float:
        return self.knots[0]

    @property
    def end(self) -> float:
        return self.knots[-1]

    def table(self) -> np.ndarray:
        """This drive's block of the drive table: m, the knots, the coefficients (flat)."""
        knots = np.asarray(self.knots, dtype=float)
        return np.concatenate([[len(knots) - 1.0], knots,
                               np.asarray(self.coefficients, dtype=float).ravel()])


def _cubic(times: np.ndarray, values: np.ndarray) -> np.ndarray:
    """The not-a-knot cubic spline's coefficients (m, D, DRIVE_ORDER), the lowest power first,
    of `values` (m + 1, D) at `times`."""
    from scipy.interpolate import CubicSpline  # on demand: loading a scenario imports no scipy
    spline = CubicSpline(times, values, axis=0)
    cubic = spline.c[::-1]  # (4, m, D), the lowest power first
    out = np.zeros((cubic.shape[1], cubic.shape[2], DRIVE_ORDER))
    out[:, :, :4] = cubic.transpose(1, 2, 0)
    return out


def quintic_hermite(times: np.ndarray, positions: np.ndarray, velocities: np.ndarray,
                    accelerations: np.ndarray) -> np.ndarray:
    """The quintic through each row's position, velocity and acceleration (m + 1, D) at both
    ends of each piece: coefficients (m, D, DRIVE_ORDER), the lowest power first."""
    durations = np.diff(times)
    out = np.zeros((len(durations), positions.shape[1], DRIVE_ORDER))
    out[:, :, 0], out[:, :, 1] = positions[:-1], velocities[:-1]
    out[:, :, 2] = 0.5 * accelerations[:-1]
    for k, duration in enumerate(durations):
        # c3, c4, c5 from the end's position, velocity and acceleration: the rows of
        # d^order/dt^order t^j at t = duration, j = 3, 4, 5
        system = np.array([[duration ** j for j in (3, 4, 5)],
                           [j * duration ** (j - 1) for j in (3, 4, 5)],
                           [j * (j - 1) * duration ** (j - 2) for j in (3, 4, 5)]])
        c0, c1, c2 = out[k, :, 0], out[k, :, 1], out[k, :, 2]
        right = np.stack([positions[k + 1] - (c0 + c1 * duration + c2 * duration ** 2),
                          velocities[k + 1] - (c1 + 2 * c2 * duration),
                          accelerations[k + 1] - 2 * c2])
        out[k, :, 3:6] = np.linalg.solve(system, right).T
    return out


def spline_drive(source: str, times: np.ndarray, positions: np.ndarray,
                 velocities: np.ndarray | None = None,
                 accelerations: np.ndarray | None = None,
                 euler: np.ndarray | None = None, yaw: float = 0.0) -> Drive:
    """The Drive through a file's rows (the module's docstring: which spline from which
    columns): times (N,) [s] increasing, positions (N, 3) [m], velocities (N, 3) [m/s],
    accelerations (N, 3) [m/s^2] (with velocities only), euler (N, 3) roll, pitch, yaw [rad];
    without euler the UAV is level at `yaw` [rad]."""
    times = np.asarray(times, dtype=float)
    m = len(times) - 1
    coefficients = np.zeros((m, DRIVE_AXES, DRIVE_ORDER))
    position = slice(DRIVE_POSITION, DRIVE_POSITION + 3)
    if velocities is None:
        coefficients[:, position] = _cubic(times, positions)
    else:
        if accelerations is None:
            from scipy.interpolate import CubicSpline
            accelerations = CubicSpline(times, velocities, axis=0)(times, 1)
        coefficients[:, position] = quintic_hermite(times, positions, velocities,
                                                    accelerations)
    attitude = slice(DRIVE_EULER, DRIVE_EULER + 3)
    if euler is None:
        coefficients[:, DRIVE_EULER + 2, 0] = yaw
    else:
        coefficients[:, attitude] = _cubic(times, euler)
    return Drive(source, tuple(float(t) for t in times),
                 tuple(tuple(tuple(float(c) for c in axis) for axis in piece)
                       for piece in coefficients))


def drive_table(drives: Sequence[Drive | None]) -> np.ndarray:
    """The drive table that follows the formation's scalars (`physics.layout` DRIVE_*): one
    slot per UAV (the offset of its drive in the formation's array, 0: none), then each
    drive's block."""
    n = len(drives)
    blocks = []
    offsets = np.zeros(n)
    at = FORMATION_SCALARS + n
    for i, drive in enumerate(drives):
        if drive is None:
            continue
        offsets[i] = at
        block = drive.table()
        blocks.append(block)
        at += len(block)
    assert DRIVE_PIECES == 0 and DRIVE_KNOTS == 1  # Drive.table's order
    return np.concatenate([offsets, *blocks])
