"""A vehicle frame is a registered part in one file (issue 31): this file defines an H-frame
quadrotor with a long nose (front arms FRONT, rear arms REAR times the arm length), registered
when the file is imported. A scenario names this file under `parts:`, so the simulator and
controller nodes import it as the test does; no other file knows the frame.

The check is worked out here from the statics, not read from the code: hovering with the
payload hanging below its centre, the UAV's rotors carry the weight W = (m + m_p) g with no
moment, so each front rotor pulls W REAR / (2 (FRONT + REAR)) and each rear one
W FRONT / (2 (FRONT + REAR)) (moments about the body y axis), and each rotor's speed is
sqrt(f / k_T). A frame the allocation did not read would hover on four equal speeds.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import types
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_sim import vehicles

ROOT = Path(__file__).resolve().parents[2]
FRONT, REAR, HALF_WIDTH = 1.0, 0.6, 0.8  # arm lengths along x and y [arm lengths]


def _h_frame_rotors(arm_length: float) -> np.ndarray:
    """Front-right, rear-right, rear-left, front-left hubs [m], body FLU."""
    x_front, x_rear, y = FRONT * arm_length, -REAR * arm_length, HALF_WIDTH * arm_length
    return np.array([[x_front, -y, 0.0], [x_rear, -y, 0.0], [x_rear, y, 0.0],
                     [x_front, y, 0.0]])


H_FRAME = types.SimpleNamespace(NAME='quad_h_long_nose', SPINS=(1, -1, 1, -1),
                                rotor_positions=_h_frame_rotors)
if H_FRAME.NAME not in vehicles.VEHICLE_FRAMES:
    vehicles.register(H_FRAME)

HOVER_TIME = 20.0  # [s]: the leader has settled on its integral action by then


def _scenario_file(folder: Path) -> Path:
    data = yaml.safe_load((ROOT / 'scenarios' / 'single_lift.yaml').read_text())
    data['parts'] = [os.path.relpath(__file__, folder)]  # relative to the scenario's folder
    data['name'] = 'single_lift_h_frame'
    data['vehicle'].update(frame_type=H_FRAME.NAME, rotor_speed_max=2600.0)
    data['simulation']['duration'] = HOVER_TIME
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': HOVER_TIME}]
    path = folder / 'h_frame.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _hover_speeds(data: dict) -> np.ndarray:
    """Front and rear rotor speeds [rad/s] of the statics above."""
    vehicle = data['vehicle']
    weight = (vehicle['mass'] + data['payload']['mass']) * data['simulation']['gravity']
    front = weight * REAR / (2.0 * (FRONT + REAR))
    rear = weight * FRONT / (2.0 * (FRONT + REAR))
    k_t = vehicle['thrust_coefficient']
    return np.sqrt(np.array([front, rear, rear, front]) / k_t)


@pytest.mark.parametrize('mode', ['ros', 'headless'])
def test_a_frame_defined_in_a_test_file_hovers_on_its_statics(tmp_path, ros_env, mode):
    from multilift_tools.bagdata import load_run
    path = _scenario_file(tmp_path)
    args = [str(ROOT / 'scripts' / 'multilift'), 'run', str(path), '--bag', str(tmp_path / 'bag')]
    if mode == 'headless':
        args.append('--headless')
    out = subprocess.run(args, capture_output=True, text=True, timeout=600, env=ros_env)
    assert out.returncode == 0, out.stderr[-2000:]
    speeds = load_run(tmp_path / 'bag').rotor_speeds(1)
    expected = _hover_speeds(yaml.safe_load(path.read_text()))
    assert not np.allclose(expected[0], expected[1], rtol=0.05)  # the frame matters
    np.testing.assert_allclose(speeds[-1], expected, rtol=2e-3)
    summary = json.loads((tmp_path / 'bag' / 'summary.json').read_text())
    assert math.isclose(summary['sim']['max_rotor_speed'][0], speeds.max(), rel_tol=1e-6)


def test_a_scenario_without_the_part_does_not_know_the_frame(tmp_path):
    from multilift_sim import scenario as scenario_io
    data = yaml.safe_load(_scenario_file(tmp_path).read_text())
    del data['parts']
    data['vehicle']['frame_type'] = 'quad_h_unknown'
    with pytest.raises(scenario_io.ScenarioError, match='frame_type.*must be one of'):
        scenario_io.loads(yaml.safe_dump(data))
    data['parts'] = ['no_such_part.py']
    with pytest.raises(scenario_io.ScenarioError, match=r"parts: 'no_such_part.py' is no "):
        scenario_io.loads(yaml.safe_dump(data))
