"""`mission.type: file`: `mission.file`, a CSV with a header row and the columns `t,x,y,z`
(and optionally `yaw`): times [s], strictly increasing, positions [m] and yaw [rad], world
frame (z up); its path relative to the scenario file's folder. Joined by a clamped cubic
spline (`polynomials.clamped_cubic`: position, velocity and acceleration continuous, at rest
at the first and the last row); before the first time the reference holds the first row,
after the last the last."""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from multilift_sim.missions.polynomials import clamped_cubic, polynomial_mission
from multilift_sim.scenario.config import MissionConfig
from multilift_sim.scenario.reading import Section

NAME = 'file'
FORM = 'polynomial'
COLUMNS = ('t', 'x', 'y', 'z')
OPTIONAL = ('yaw',)


def read(m: Section, start: tuple[float, float, float], folder: Path) -> MissionConfig:
    """`mission.file` read and splined (a bad file: one line naming the file, the row and the
    rule)."""
    name = m.text('file')
    path = (folder / name).resolve()
    try:
        with open(path, newline='') as handle:
            rows = list(csv.reader(handle))
    except OSError as exc:
        raise m.fail('file', name, f'cannot be read ({exc.strerror})') from None
    rows = [row for row in rows if row and any(cell.strip() for cell in row)]
    header = [cell.strip() for cell in rows[0]] if rows else []
    missing = [column for column in COLUMNS if column not in header]
    if missing:
        raise m.fail('file', name, f'lacks the column {missing[0]!r} (a header row t,x,y,z'
                     f'[,yaw] is needed; it has {",".join(header) or "none"})')
    unknown = [column for column in header if column not in COLUMNS + OPTIONAL]
    if unknown:
        raise m.fail('file', name, f'has an unknown column {unknown[0]!r} (t,x,y,z[,yaw])')
    columns = [header.index(c) for c in COLUMNS + OPTIONAL if c in header]
    values = []
    for number, row in enumerate(rows[1:], start=2):
        try:
            values.append([float(row[k]) for k in columns])
        except (ValueError, IndexError):
            raise m.fail('file', name, f'row {number}: {",".join(row)!r} must hold a number '
                         f'in each column') from None
        if not all(math.isfinite(v) for v in values[-1]):
            raise m.fail('file', name, f'row {number}: values must be finite')
        if len(values) > 1 and values[-1][0] <= values[-2][0]:
            raise m.fail('file', name, f'row {number}: time {values[-1][0]:g} s must be > the '
                         f'previous row\'s ({values[-2][0]:g} s): times strictly increasing')
    if len(values) < 2:
        raise m.fail('file', name, f'has {len(values)} rows of data, at least 2 are needed')
    data = np.array(values)
    table = np.zeros((len(data), 4))
    table[:, :data.shape[1] - 1] = data[:, 1:]
    return polynomial_mission(data[:, 0], table, clamped_cubic(data[:, 0], table))
