"""docs/reproduction.md against a fresh `reproduce.single_lift_table()` (seed §2.8.1, §4.1).

The single-lift numbers of the report are regenerated here (release, modal analysis, simulated
and reduced-model periods, the Baumgarte study, static tension; about 10 s) and every rendered
row must stand in the committed report as it is: a change of the physics that moves a number
fails here until `scripts/multilift reproduce` is rerun and its output committed. The numbers
are also checked against the seed and against each other.
"""
from __future__ import annotations

import math
import re

import pytest

from conftest import ROOT
from multilift_tools.report.seed import SEED_EIGENVALUE, SEED_PERIOD, SEED_RELEASE
from multilift_tools.report.single_lift import (TABLE_HEAD, render_row, render_table,
                                                single_lift_table)

REPORT = ROOT / 'docs' / 'reproduction.md'
SINGLE_LIFT_HEADING = '### Single-lift (§2.8.1, §4.1): `reproduce.single_lift_table()`'


@pytest.fixture(scope='module')
def table(tmp_path_factory) -> dict[str, dict]:
    rows = single_lift_table(tmp_path_factory.mktemp('baumgarte'))
    return {row['key']: row for row in rows}


@pytest.fixture(scope='module')
def report_lines() -> list[str]:
    return REPORT.read_text(encoding='utf-8').splitlines()


def test_every_row_stands_in_the_committed_report(table, report_lines):
    stale = [f'{key}: now\n  {render_row(row)}' for key, row in table.items()
             if render_row(row) not in report_lines]
    assert not stale, ('docs/reproduction.md is stale (rerun `scripts/multilift reproduce`):\n'
                       + '\n'.join(stale))


def test_the_report_table_is_exactly_the_regenerated_one(table, report_lines):
    start = report_lines.index(SINGLE_LIFT_HEADING)
    head = report_lines.index(TABLE_HEAD[0], start)
    expected = render_table(list(table.values()))
    assert report_lines[head:head + len(expected)] == expected
    assert not report_lines[head + len(expected)].startswith('|')  # no extra rows


def test_release_linear_period_and_eigenvalues_match_the_seed(table):
    release = table['release']['value']
    assert release == pytest.approx(SEED_RELEASE, abs=0.01)
    assert table['linear_period']['value'] == pytest.approx(SEED_PERIOD, rel=0.005)
    assert table['eigenvalues']['value'] == pytest.approx([SEED_EIGENVALUE] * 2, abs=0.01)
    assert table['state_matrix']['value'] == 16  # the seed's A: 8 independent coordinates


def test_small_swing_has_the_linear_period_and_the_large_one_the_amplitude_law(table):
    linear = table['linear_period']['value']
    small, large = table['period_small']['value'], table['period_large']['value']
    assert small == pytest.approx(SEED_PERIOD, rel=0.005)
    assert small == pytest.approx(linear, rel=1e-4)
    # the seed's 15/25 deg swing is slower than the linear period: an amplitude effect that the
    # nonlinear reduced model and the plane-pendulum law both give
    assert large > 1.01 * linear
    assert large == pytest.approx(table['period_reduced']['value'], rel=1e-5)
    assert large == pytest.approx(table['period_law']['value'], rel=1e-3)


def test_baumgarte_residuals_within_the_seed_bound_and_tension_balances_weight(table):
    for gain in ('20', '100'):
        assert table[f'baumgarte_{gain}']['value'] < 1e-1  # seed §4.1, Fig. 4.2
    assert max(table['dae_error']['value']) < 1e-2      # "approximately equal" (Fig. 4.3)
    tension, weight = table['static_tension']['value']
    assert tension == pytest.approx(weight, rel=1e-9)
    assert math.isfinite(table['scenario_error']['value'])


def test_every_figure_of_the_report_is_committed_and_modest(report_lines):
    text = '\n'.join(report_lines)
    links = re.findall(r'!\[[^\]]*\]\((figures/[^)]+\.png)\)', text)
    numbers = re.findall(r'^### Fig\. ([0-9.]+)$', text, flags=re.MULTILINE)
    assert numbers == ['2.12'] + [f'4.{k}' for k in range(1, 18)]
    beyond = re.findall(r'\(figures/(swing_feedback_[a-z_]+\.png)\)', text)  # issue 20
    assert beyond == ['swing_feedback_single_lift.png', 'swing_feedback_twin_lift.png']
    shared = re.findall(r'\(figures/(load_sharing\.png)\)', text)  # issue 35
    assert shared == ['load_sharing.png']
    assert len(links) == len(numbers) + len(beyond) + len(shared)
    sizes = [(REPORT.parent / link).stat().st_size for link in links]
    assert sum(sizes) < 8e6
