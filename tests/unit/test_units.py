"""One table of units (multilift_sim.units): every column a sweep row really has and every key
of every scenario file has a unit there, indexed and per-UAV names resolve, the README's table
of sweep columns agrees with it, and `run`'s summary prints the table's units."""
from __future__ import annotations

import re
import types

import pytest
import yaml

from conftest import ROOT, SCENARIOS
from multilift_sim import units
from multilift_sim.units import NO_UNIT, label, unit_of
from multilift_tools import campaign as cp
from multilift_tools.run_summary import print_summary


def test_every_column_of_a_real_sweep_row_has_a_unit():
    """A row flown the way a sweep worker flies it (`run_chunk`: 0.2 s of the twin lift, a grid
    key and a sampled per-UAV key): a statistic added without a unit fails here."""
    source, base = cp.load_base('twin_lift')
    campaign = cp.build_campaign(source, base, [cp.parse_set('payload.mass=0.6')],
                                 [cp.parse_sample('uavs[1].cable_length=uniform(9.5, 10.5)')],
                                 1, 0)
    run = campaign.runs[0]
    result = cp.run_chunk(source, base, [(campaign.edits(run), None)], 0.2)[0]
    assert result['status'] == 'ok', result['message']
    row = cp.make_row(run, result)
    columns = set(row) | set(cp.table_columns(campaign, bags=True))
    assert {'payload.mass', 'uavs[1].cable_length', 'max_abs_g', 'wall_time', 'bag'} <= columns
    missing = []
    for column in sorted(columns):
        try:
            unit_of(column)
        except KeyError:
            missing.append(column)
    assert not missing, f'columns without a unit in multilift_sim.units: {missing}'
    assert unit_of('payload.mass') == 'kg' and unit_of('uavs[1].cable_length') == 'm'
    assert unit_of('max_tension') == 'N' and unit_of('wall_time') == 's'


def _leaf_keys(prefix: str, value):
    """Dotted keys of a YAML mapping's leaves; a list of mappings by index, other lists whole."""
    if isinstance(value, dict):
        for key, inner in value.items():
            yield from _leaf_keys(f'{prefix}.{key}' if prefix else key, inner)
    elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        for i, inner in enumerate(value):
            yield from _leaf_keys(f'{prefix}[{i}]', inner)
    else:
        yield prefix


def test_every_key_of_every_scenario_file_has_a_unit():
    keys = set()
    for path in sorted(SCENARIOS.glob('*.yaml')):
        keys |= {(path.name, k) for k in _leaf_keys('', yaml.safe_load(path.read_text()))}
    assert len({k for _, k in keys}) > 60   # the walk reached the files' keys
    missing = []
    for name, key in sorted(keys):
        try:
            unit_of(key)
        except KeyError:
            missing.append(f'{name}: {key}')
    assert not missing, missing


@pytest.mark.parametrize('name, unit', [
    ('uavs[2].cable_length', 'm'), ('uavs[0].rotor_speed_max', 'rad/s'),
    ('vehicle.mass', 'kg'), ('sensors.position_noise', 'm'), ('sensors.attitude_bias',
                                                              'rad/sqrt(s)'),
    ('mission.segments[3].velocity', 'm/s'), ('mission.start[2]', 'm'),
    ('payload.swing_deg', 'deg'), ('control.attitude_gains.kp[1]', '1/s^2'),
    ('uav2_saturated_time', 's'), ('cable1.slack_time', 's'), ('saturated_time[1]', 's'),
    ('follower3_formation_error_max', 'm or m^2'), ('formation.n', NO_UNIT), ('seed', NO_UNIT)])
def test_indexed_and_per_uav_names(name, unit):
    assert unit_of(name) == unit


def test_an_unknown_name_is_a_key_error_naming_it():
    with pytest.raises(KeyError, match='payload.colour'):
        unit_of('payload.colour')
    with pytest.raises(KeyError):
        unit_of('uav2_nonsense')
    assert label('payload.mass') == 'payload.mass [kg]'
    assert label('formation.n') == 'formation.n' and label('nonsense') == 'nonsense'


def test_every_statistic_has_a_unit_and_the_readme_table_agrees():
    assert set(cp.STATISTICS) <= set(units.STATISTIC_UNITS)
    text = (ROOT / 'README.md').read_text()
    section = text[text.index('### Sweep table columns'):]
    section = section[:section.index('\n\n', section.index('| column'))]
    documented = {}
    for line in section.splitlines()[2:]:
        cells = [c.strip() for c in line.strip('|').split('|')]
        for names, unit in zip(cells[::2], cells[1::2]):
            for name in re.findall(r'`([a-z_]+)`', names):
                documented[name] = unit
    assert set(cp.STATISTICS) | {'wall_time'} <= set(documented)
    assert {name: unit_of(name) for name in documented} == documented


def _scenario(n: int):
    uav = types.SimpleNamespace(vehicle=types.SimpleNamespace(rotor_speed_max=2100.0),
                                trajectory=None)
    return types.SimpleNamespace(
        simulation=types.SimpleNamespace(constraint_tolerance=0.02), uavs=[uav] * n, n_uavs=n,
        gusts=[1], control=types.SimpleNamespace(input_shaping='none', swing_stiffness=0.0,
                                                 swing_damping=0.0))


def test_the_run_summary_prints_the_tables_units(monkeypatch, capsys):
    """Each unit the summary prints comes from the table: mark the table's entries and every
    figure's line shows its mark."""
    marked = {name: f'<{name}>' for name in units.STATISTIC_UNITS}
    monkeypatch.setattr(units, 'UNITS', {**units.UNITS, **marked})
    data = {'sim': {'wall_time': 2.0, 'simulated_time': 4.0, 'max_abs_constraint': 1e-9,
                    'max_abs_constraint_rate': 1e-8, 'max_rotor_speed': [1500.0, 1600.0],
                    'saturated_time': [0.0, 0.5], 'min_tension': 3.0, 'max_tension': 6.0,
                    'slack_time': [0.0, 0.25], 'max_payload_swing': 0.5,
                    'rms_payload_swing': 0.2, 'max_gust_speed': 1.5,
                    'compressed_time': 0.3},
            'leader': {'answered_states': 10, 'max_tracking_error': 0.3,
                       'rms_tracking_error': 0.1},
            'follower2': {'answered_states': 10, 'max_abs_formation_error': 0.2,
                          'mean_formation_error_norm': 0.1}}
    print_summary('twin', data, None, _scenario(2))
    out = capsys.readouterr().out
    for name in ('simulated_time', 'max_abs_g', 'max_abs_g_dot', 'max_rotor_speed',
                 'saturated_time', 'max_tension', 'slack_time', 'payload_swing_max',
                 'payload_swing_rms', 'max_gust_speed', 'compressed_time', 'tracking_error_max',
                 'tracking_error_rms', 'formation_error_mean'):
        assert f'<{name}>' in out, (name, out)
