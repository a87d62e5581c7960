"""Bad prescribed-motion input (issue 34 item 3) is one line and exit 2: a trajectory file with a
missing column, times not increasing, a column group given in part, a file that does not cover
the run, a payload start that does not fit the cables, and what the prescribed DAE does not
model (another formulation, slack cables, a formation of prescribed and flown UAVs). A payload
start that fits is where the run starts. The command line's one line and exit 2:
tests/ros/test_prescribed_ros.py."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.start import initial_state

SCENARIOS = Path(__file__).resolve().parents[2] / 'scenarios'


def swing_copy(folder: Path, csv_text: str | None = None, **edits) -> Path:
    """prescribed_swing.yaml and its CSV (or `csv_text`) copied into folder, the YAML's
    mapping updated by `edits` (section -> {key: value}, or a top-level key -> value)."""
    data = yaml.safe_load((SCENARIOS / 'prescribed_swing.yaml').read_text())
    if csv_text is None:
        shutil.copy(SCENARIOS / 'prescribed_swing.csv', folder / 'prescribed_swing.csv')
    else:
        (folder / 'prescribed_swing.csv').write_text(csv_text)
    for key, value in edits.items():
        if isinstance(value, dict) and isinstance(data.get(key), dict):
            data[key].update(value)
        else:
            data[key] = value
    path = folder / 'swing.yaml'
    path.write_text(yaml.safe_dump(data))
    return path


BAD_FILES = [
    ('t,x,y\n0,0,0\n30,0,0\n', "lacks the column 'z'"),
    ('t,x,y,z\n0,0,0,10\n20,0,0,10\n10,0,0,10\n30,0,0,10\n',
     r'row 4: time 10 s must be > the previous row\'s \(20 s\)'),
    ('t,x,y,z,vx\n0,0,0,10,0\n30,0,0,10,0\n', r"lacks the column 'vy' \(vx,vy,vz go together\)"),
    ('t,x,y,z,ax,ay,az\n0,0,0,10,0,0,0\n30,0,0,10,0,0,0\n', r'ax,ay,az need vx,vy,vz'),
    ('t,x,y,z,speed\n0,0,0,10,0\n30,0,0,10,0\n', "has an unknown column 'speed'"),
    ('t,x,y,z\n0,0,0,10\n5,0,0,10\n', r"covers 0 \.\. 5 s, must cover the run, 0 \.\. 20 s"),
    ('t,x,y,z\n1,0,0,10\n30,0,0,10\n', r"covers 1 \.\. 30 s, must cover the run"),
]


@pytest.mark.parametrize('text,message', BAD_FILES)
def test_a_bad_trajectory_file_is_one_line(tmp_path, text, message):
    with pytest.raises(scenario_io.ScenarioError, match=message) as caught:
        scenario_io.load(str(swing_copy(tmp_path, text)))
    assert '\n' not in str(caught.value)
    assert 'uavs[0].trajectory' in str(caught.value)


@pytest.mark.parametrize('edits,message', [
    ({'payload': {'initial_position': [0.0, 0.0, 8.5]}},
     r"payload\.initial_position: \[0\.0, 0\.0, 8\.5\] is 1\.5 m from uav1's cable end .*"
     r"cable 1 must span its length 1 m within 0\.001 m"),
    ({'simulation': {'integrator': 'nullspace'}},
     r"uavs\[0\]\.trajectory needs simulation\.integrator: baumgarte.*, got 'nullspace'"),
    ({'cable_model': 'slack'}, r'prescribed motion needs cable_model: rigid'),
])
def test_what_does_not_fit_is_one_line(tmp_path, edits, message):
    with pytest.raises(scenario_io.ScenarioError, match=message) as caught:
        scenario_io.load(str(swing_copy(tmp_path, **edits)))
    assert '\n' not in str(caught.value)


def test_a_formation_of_prescribed_and_flown_uavs_is_refused(tmp_path):
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    shutil.copy(SCENARIOS / 'prescribed_swing.csv', tmp_path / 'move.csv')
    data['uavs'][1]['trajectory'] = 'move.csv'
    data['simulation']['duration'] = 20.0
    path = tmp_path / 'mixed.yaml'
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(scenario_io.ScenarioError,
                       match=r"uavs\[0\]: has no trajectory while uavs\[1\] has one"):
        scenario_io.load(str(path))


def test_a_payload_start_that_fits_is_the_runs_start(tmp_path):
    """payload.initial_position and _velocity on a scenario of flown UAVs: the state at t = 0
    has them (the single-lift, its cable 2.5 m: a start 2.5 m under the UAV, swinging)."""
    data = yaml.safe_load((SCENARIOS / 'single_lift_swing.yaml').read_text())
    data['payload'].update(initial_position=[1.5, 0.0, -2.0], initial_velocity=[0.0, 0.3, 0.0])
    path = tmp_path / 'start.yaml'
    path.write_text(yaml.safe_dump(data))
    scenario = scenario_io.load(str(path))
    state = initial_state(scenario)
    layout = StateLayout(1)
    assert np.array_equal(layout.payload_position(state), [1.5, 0.0, -2.0])
    assert np.array_equal(layout.payload_velocity(state), [0.0, 0.3, 0.0])
    assert np.array_equal(layout.uav_positions(state)[0], [0.0, 0.0, 0.0])
    data['payload']['initial_position'] = [1.5, 0.0, -2.1]  # 2.58 m from the UAV
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(scenario_io.ScenarioError, match='cable 1 must span its length 2.5 m'):
        scenario_io.load(str(path))


def test_a_copy_of_the_mapping_reads_the_trajectory_beside_its_scenario(tmp_path, monkeypatch):
    """A sweep's run validates an edited copy of the mapping elsewhere (`anchored`): the
    trajectory file is still the one beside the scenario file."""
    data = yaml.safe_load((SCENARIOS / 'prescribed_swing.yaml').read_text())
    monkeypatch.chdir(tmp_path)
    copy = scenario_io.anchored(data, SCENARIOS)
    assert copy['uavs'][0]['trajectory'] == str(SCENARIOS / 'prescribed_swing.csv')
    assert data['uavs'][0]['trajectory'] == 'prescribed_swing.csv'  # the original untouched
    scenario = scenario_io.from_mapping(copy)
    assert scenario.uavs[0].trajectory.end == 20.0


def test_a_payload_velocity_along_a_rigid_cable_is_one_line(tmp_path):
    """Straight down along the hanging cable: g_dot = 2 l v = 2 m^2/s, beyond the scenario's
    constraint_rate_tolerance 1: refused before the run (it would stop at t = 0)."""
    path = swing_copy(tmp_path, payload={'initial_velocity': [0.0, 0.0, -1.0]})
    with pytest.raises(scenario_io.ScenarioError,
                       match=r'moves along cable 1: its rate g_dot = 2 m\^2/s must be within'):
        scenario_io.load(str(path))


def test_more_than_three_prescribed_uavs_are_refused(tmp_path):
    """Four or more driven rigid cables on a point payload: more constraints than coordinates."""
    data = yaml.safe_load((SCENARIOS / 'v5.yaml').read_text())
    duration = data['simulation']['duration']
    (tmp_path / 'still.csv').write_text(f't,x,y,z\n0,0,0,0\n{duration},0,0,0\n')
    data['uavs'] = [{'trajectory': 'still.csv'} for _ in range(data['formation']['n'])]
    path = tmp_path / 'v5.yaml'
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(scenario_io.ScenarioError, match='at most 3 prescribed UAVs'):
        scenario_io.load(str(path))
