"""`multilift plot-sweep` on tables written as `sweep` writes them: axes with units, no panel for
a statistic that does not vary, a `--set` grid read back from CSV drawn as the mean with its
spread (the campaign's metadata beside the CSV), the CSV's and the Parquet's figures in
folders of their own."""
from __future__ import annotations

import matplotlib.pyplot as plt
import pytest
import yaml

from conftest import SCENARIOS
from multilift_tools import campaign as cp
from multilift_tools.campaign import plot_sweep as ps


def _campaign(sets=(), samples=(), n=None):
    base = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    return cp.build_campaign('twin_lift', base, [cp.parse_set(s) for s in sets],
                             [cp.parse_sample(s) for s in samples], n, 0)


def _rows(campaign) -> list[dict]:
    """Rows as a sweep of 2 s writes them: simulated_time, slack_time and max_gust_speed the
    same in every run, max_tension with the payload's mass."""
    rows = []
    for run in campaign.runs:
        mass = run.params.get('payload.mass', 0.8)
        rows.append(cp.make_row(run, {'status': 'ok', 'message': '',
                                      **dict.fromkeys(cp.STATISTICS),
                                      'simulated_time': 2.0, 'slack_time': 0.0,
                                      'max_gust_speed': 0.0,
                                      'max_tension': 10.0 * mass + 0.01 * run.index,
                                      'max_abs_g': 1e-9 * (1 + run.index), 'wall_time': 0.01}))
    return rows


def _write(path, campaign, rows):
    cp.write_table(path, cp.table_columns(campaign, False), rows, campaign.metadata())


def test_a_grid_read_back_from_csv_is_a_grid_and_drawn_as_mean_and_spread(tmp_path):
    """`--set payload.mass=0.5,0.7,0.9`: every value once, so the values alone look sampled."""
    c = _campaign(['payload.mass=0.5,0.7,0.9'])
    table = tmp_path / 'runs.csv'
    _write(table, c, _rows(c))
    assert cp.metadata_path(table).is_file()
    columns, rows, meta = cp.read_table(table)
    assert meta['grid'] == {'payload.mass': ['0.5', '0.7', '0.9']} and meta['sample'] == {}
    assert ps.is_grid('payload.mass', rows, meta)
    fig = ps.draw_parameter('payload.mass', rows, ['max_tension'], ps.is_grid(
        'payload.mass', rows, meta))
    ax = fig.axes[0]
    assert fig._suptitle.get_text().startswith('payload.mass (grid: mean and min-max')
    assert len(ax.collections) == 1 and ax.collections[0].get_label() == 'min-max'
    assert [line.get_label() for line in ax.lines] == ['mean']
    assert list(ax.lines[0].get_xdata()) == [0.5, 0.7, 0.9]
    plt.close(fig)
    # without its metadata the same CSV is guessed, and a sidecar of another table is not read
    cp.metadata_path(table).write_text('{"grid": {"payload.drag_coefficient": []}}')
    assert cp.read_table(table)[2] == {}
    assert not ps.is_grid('payload.mass', rows, {})


def test_csv_keeps_sampled_keys_sampled_and_a_csv_without_metadata_drops_an_old_one(tmp_path):
    c = _campaign(['payload.mass=0.5,0.7'], ['formation.alpha_vc=uniform(1.5, 2.5)'], n=2)
    table = tmp_path / 'runs.csv'
    _write(table, c, _rows(c))
    _, rows, meta = cp.read_table(table)
    assert ps.is_grid('payload.mass', rows, meta)
    assert not ps.is_grid('formation.alpha_vc', rows, meta)
    cp.write_table(table, cp.table_columns(c, False), _rows(c))   # no metadata now
    assert not cp.metadata_path(table).exists() and cp.read_table(table)[2] == {}


def test_axes_carry_units_and_constant_statistics_take_no_panel(tmp_path, capsys):
    c = _campaign(['payload.mass=0.5,0.7,0.9'])
    table = tmp_path / 'runs.csv'
    _write(table, c, _rows(c))
    _, rows, _ = cp.read_table(table)
    names = ps.metrics(cp.table_columns(c, False), rows)
    assert {'simulated_time', 'slack_time', 'max_gust_speed', 'max_tension'} <= set(names)
    assert ps.varying(names, rows) == ['max_abs_g', 'max_tension']
    fig = ps.draw_parameter('payload.mass', rows, ps.varying(names, rows), True)
    shown = [ax for ax in fig.axes if ax.axison]
    assert [ax.get_ylabel() for ax in shown] == ['max_abs_g [m^2]', 'max_tension [N]']
    assert {ax.get_xlabel() for ax in shown} == {'payload.mass [kg]'}
    plt.close(fig)
    assert ps.plot_sweep_main([str(table)]) == 0
    err = capsys.readouterr().err
    assert 'no panel: simulated_time = 2, max_gust_speed = 0, slack_time = 0' in err


def test_csv_and_parquet_plots_go_to_folders_of_their_own(tmp_path):
    c = _campaign(['payload.mass=0.5,0.7'])
    rows = _rows(c)
    for name in ('runs.csv', 'runs.parquet'):
        _write(tmp_path / name, c, rows)
        assert ps.plot_sweep_main([str(tmp_path / name)]) == 0
    for folder in ('runs.csv_plots', 'runs.parquet_plots'):
        assert (tmp_path / folder / 'payload.mass.png').read_bytes()[:4] == b'\x89PNG'
        assert (tmp_path / folder / 'worst_runs.md').is_file()


@pytest.mark.parametrize('name', ['runs.csv', 'runs.parquet'])
def test_both_formats_round_trip_the_campaign_metadata(tmp_path, name):
    c = _campaign(['payload.mass=0.5,0.7'], ['formation.alpha_vc=uniform(1.5, 2.5)'], n=2)
    _write(tmp_path / name, c, _rows(c))
    assert cp.read_table(tmp_path / name)[2] == c.metadata()
