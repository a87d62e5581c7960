"""A CSV file a scenario names, read once with checks: a header row naming the columns, then
rows of finite numbers whose first column, time [s], strictly increases. The mission's `file`
source and the prescribed UAV motion (`uavs[i].trajectory`) read theirs here; a bad file is one
line naming the key, the file, the row and the rule (`reading.Section.fail`)."""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from multilift_sim.scenario.reading import Section


def read_table(section: Section, key: str, folder: Path, required: tuple[str, ...],
               optional: tuple[str, ...]) -> tuple[tuple[str, ...], np.ndarray]:
    """(the columns present in the order required + optional, their values (rows, columns))
    of the file `section`'s `key` names, relative to `folder`. Needs every `required` column
    (the first is the time), no column outside required + optional, and at least 2 rows."""
    name = section.text(key)
    path = (folder / name).resolve()
    try:
        with open(path, newline='') as handle:
            rows = list(csv.reader(handle))
    except OSError as exc:
        raise section.fail(key, name, f'cannot be read ({exc.strerror})') from None
    rows = [row for row in rows if row and any(cell.strip() for cell in row)]
    header = [cell.strip() for cell in rows[0]] if rows else []
    form = ','.join(required) + ''.join(f'[,{c}]' for c in optional)
    missing = [column for column in required if column not in header]
    if missing:
        raise section.fail(key, name, f'lacks the column {missing[0]!r} (a header row '
                           f'{form} is needed; it has {",".join(header) or "none"})')
    unknown = [column for column in header if column not in required + optional]
    if unknown:
        raise section.fail(key, name, f'has an unknown column {unknown[0]!r} ({form})')
    present = tuple(c for c in required + optional if c in header)
    columns = [header.index(c) for c in present]
    values = []
    for number, row in enumerate(rows[1:], start=2):
        try:
            values.append([float(row[k]) for k in columns])
        except (ValueError, IndexError):
            raise section.fail(key, name, f'row {number}: {",".join(row)!r} must hold a number '
                               f'in each column') from None
        if not all(math.isfinite(v) for v in values[-1]):
            raise section.fail(key, name, f'row {number}: values must be finite')
        if len(values) > 1 and values[-1][0] <= values[-2][0]:
            raise section.fail(key, name, f'row {number}: time {values[-1][0]:g} s must be > '
                               f'the previous row\'s ({values[-2][0]:g} s): times strictly '
                               'increasing')
    if len(values) < 2:
        raise section.fail(key, name, f'has {len(values)} rows of data, at least 2 are needed')
    return present, np.array(values)
