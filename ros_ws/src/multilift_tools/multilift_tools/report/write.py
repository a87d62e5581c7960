"""`write_reproduction`: the cases' results of `multilift reproduce` -> the measurements, the
figures (DIR/figures/*.png) and DIR/reproduction.md.
"""
from __future__ import annotations

import time
from pathlib import Path

from multilift_sim.scenario import load
from multilift_tools.report.cases import CASES
from multilift_tools.report.figures import make_figures
from multilift_tools.report.measure import measure
from multilift_tools.report.numbers import Report
from multilift_tools.report.seed import MULTI, SWING, TWIN


def write_reproduction(out: Path, results: dict[str, dict], work: Path, jobs: int,
                       started: float) -> Path:
    """Figures and reproduction.md in `out` from the cases' results; returns the report."""
    from multilift_tools.bagdata import load_run
    from multilift_tools.compare import comparison_numbers
    from multilift_tools.report.template import render_report

    scenarios = {name: load(name) for name in (SWING, TWIN, MULTI)}
    runs = {name: load_run(results[name]['bag']) for name in (SWING, TWIN, MULTI)}
    numbers = measure(results, work, runs, scenarios)
    files = make_figures(runs, scenarios, out / 'figures', work / 'baumgarte',
                         numbers['twin'].climb_excess.start, numbers['multi'].gusts)
    wall = {case: results[case]['wall_time'] for case in CASES}
    wall['total'] = time.monotonic() - started
    report = Report(**numbers, files=files, comparison=tuple(comparison_numbers(
        [runs[TWIN], runs[MULTI]], ['A: TL', 'B: ML'], [scenarios[TWIN], scenarios[MULTI]])),
        wall=wall, jobs=jobs)
    path = out / 'reproduction.md'
    path.write_text(render_report(report))
    return path
