"""Mission sources through ROS (issue 34 item 1): a waypoints mission and a file mission (its CSV
beside the scenario, named relative to it) fly through the ROS graph as headless, to 1e-9 m;
the leader passes its waypoints and turns to their yaw; a bad mission is one line and exit 2."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest import flown_alike
from multilift_sim import scenario as scenario_io
from multilift_sim.missions.polynomials import evaluate

ROOT = Path(__file__).resolve().parents[2]
WAYPOINTS = [{'time': 0.0, 'position': [0.0, 0.0, 0.0]},
             {'time': 4.0, 'position': [1.0, 0.5, 0.5], 'yaw': 0.3},
             {'time': 8.0, 'position': [2.0, 0.0, 0.5]},
             {'time': 10.0, 'position': [2.0, -0.5, 0.2], 'yaw': 0.0}]


def _scenario(folder: Path, mission: dict) -> Path:
    data = yaml.safe_load((ROOT / 'scenarios' / 'single_lift.yaml').read_text())
    data['name'] = f'single_lift_{mission["type"]}'
    data['simulation']['duration'] = 12.0
    data['mission'] = mission
    path = folder / 'mission.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _headless(path: Path, bag: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'multilift_tools.cli', 'run', str(path),
                           '--headless', '--bag', str(bag)], capture_output=True, text=True,
                          timeout=1200)


@pytest.mark.parametrize('kind', ['waypoints', 'file'])
def test_a_mission_source_flies_through_ros_as_headless(multilift_run, tmp_path, kind):
    if kind == 'file':
        (tmp_path / 'path.csv').write_text('t,x,y,z,yaw\n' + ''.join(
            f'{w["time"]},{",".join(map(str, w["position"]))},{w.get("yaw", 0.0)}\n'
            for w in WAYPOINTS))
        mission = {'type': 'file', 'file': 'path.csv'}
    else:
        mission = {'type': 'waypoints', 'waypoints': WAYPOINTS}
    path = _scenario(tmp_path, mission)
    ros, _ = flown_alike(multilift_run, path, tmp_path)
    # the leader passed its waypoints (the cascade lags a moving reference a little)
    leader, euler = ros.uav_positions()[0], ros.uav_euler()[0]
    for waypoint in WAYPOINTS:
        k = int(np.argmin(np.abs(ros.t - waypoint['time'])))
        assert np.linalg.norm(leader[k] - waypoint['position']) < 0.2, (waypoint, leader[k])
    # the leader is asked the trajectory's heading (its coefficients evaluated by numpy, not
    # by the tick) and follows it, lagging by the attitude loop's PD (no rate feedforward:
    # about kd / kp = 5/9 s times the yaw rate, which peaks near 0.4 rad/s here)
    scenario = scenario_io.load(str(path))
    mission = scenario.mission
    times = ros.setpoint_time(1)
    asked = np.array([evaluate(mission.knots, np.array(mission.coefficients), t)[3]
                      for t in times])
    assert np.abs(ros.attitude_setpoint(1)[:, 2] - asked).max() < 1e-9
    assert asked.max() > 0.29  # it turns
    heading = np.interp(times, ros.t, euler[:, 2])
    assert np.abs(heading - asked).max() < 0.25
    assert abs(euler[-1, 2]) < 0.01  # and back to 0 at the end


def test_a_bad_mission_is_one_line_and_exit_2(tmp_path):
    path = _scenario(tmp_path, {'type': 'waypoints', 'waypoints': [WAYPOINTS[1], WAYPOINTS[0]]})
    result = _headless(path, tmp_path / 'bag')
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and 'mission.waypoints[1].time' in lines[0], result.stderr
