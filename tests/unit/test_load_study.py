"""`multilift study load_sharing` (issue 35 item 5): the fixed geometry, the reorganising
formation and the cable-force allocation flown on the same missions; what the study's table
says must hold of what the engine flew: on v3_mixed the reorganising formation carries the weak
UAV without the fixed geometry's saturation, the allocation flies two cables, and the margins
are those of the commanded rotor speeds."""
from __future__ import annotations

import json

import numpy as np
import pytest

from multilift_sim import scenario as scenario_io
from multilift_tools.load_study import least_spacing, load_sharing_study, thrust_margins
from multilift_sim.formation_params import StateLayout


def test_the_study_shows_the_reorganising_formation_carrying_the_weak_uav(tmp_path):
    study = load_sharing_study(tmp_path, missions=('v3_mixed', 'twin_lift'))
    rows = study['rows']
    fixed, moving = rows['v3_mixed']['none'], rows['v3_mixed']['thrust_margin']
    assert fixed['saturated_time'][2] > 60.0                     # UAV 3 saturates for long
    assert moving['saturated_time'][2] == 0.0        # started at its hover places (item 1)
    assert moving['least_thrust_margin_after'][2] > fixed['least_thrust_margin_after'][2] + 0.02
    spacing = scenario_io.load('v3_mixed').formation.min_spacing
    assert moving['least_uav_distance'] >= spacing               # within its horizontal bound
    assert rows['twin_lift']['cable_forces']['error'] is None   # any n allocates (item 3)
    for name in ('load_sharing.md', 'load_sharing.json', 'load_sharing.png'):
        assert (tmp_path / name).stat().st_size > 0
    assert json.loads((tmp_path / 'load_sharing.json').read_text())['v3_mixed']['none'][
        'saturated_time'] == fixed['saturated_time']
    assert '| v3_mixed | thrust_margin |' in study['table']


def test_thrust_margins_and_spacing_are_the_definitions():
    s = scenario_io.load('twin_lift')
    limit = s.uavs[0].vehicle.rotor_speed_max
    speeds = np.zeros((2, 2, 4))
    speeds[0, 0] = limit                        # every rotor at its limit: no margin left
    speeds[1, 1] = limit / np.sqrt(2.0)         # half the largest thrust
    margins = thrust_margins(speeds, s)
    np.testing.assert_allclose(margins, [[0.0, 1.0], [1.0, 0.5]], atol=1e-12)
    x = np.zeros((1, StateLayout(2).size))
    layout = StateLayout(2)
    layout.uav_positions(x)[0, 1] = [3.0, 4.0, 0.0]
    assert least_spacing(x, 2) == pytest.approx(5.0)
