"""`mission.type: file`: `mission.file`, a CSV with a header row and the columns `t,x,y,z`
(and optionally `yaw`): times [s], strictly increasing, positions [m] and yaw [rad], world
frame (z up); its path relative to the scenario file's folder. Joined by a clamped cubic
spline (`polynomials.clamped_cubic`: position, velocity and acceleration continuous, at rest
at the first and the last row); before the first time the reference holds the first row,
after the last the last."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from multilift_sim.missions.polynomials import clamped_cubic, polynomial_mission
from multilift_sim.scenario.config import MissionConfig
from multilift_sim.scenario.csv_table import read_table
from multilift_sim.scenario.reading import Section

NAME = 'file'
FORM = 'polynomial'
COLUMNS = ('t', 'x', 'y', 'z')
OPTIONAL = ('yaw',)


def read(m: Section, start: tuple[float, float, float], folder: Path) -> MissionConfig:
    """`mission.file` read and splined (a bad file: one line naming the file, the row and the
    rule: `scenario.csv_table`)."""
    _, data = read_table(m, 'file', folder, COLUMNS, OPTIONAL)
    table = np.zeros((len(data), 4))
    table[:, :data.shape[1] - 1] = data[:, 1:]
    return polynomial_mission(data[:, 0], table, clamped_cubic(data[:, 0], table))
