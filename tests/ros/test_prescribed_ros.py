"""`prescribed_swing` (issue 34 item 3) through ROS as headless: a scenario whose UAVs are all
prescribed runs with no controller node (the bag has no controller topic, not even a rotor
command), its payload on the driven pendulum's steady motion (within 1 % of its amplitude);
bad prescribed input is one line and exit 2 from the command line."""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import yaml

from conftest import SCENARIOS, flown_alike


def swing_copy(folder: Path, **edits) -> Path:
    """prescribed_swing.yaml and its CSV copied into folder, sections updated by `edits`."""
    data = yaml.safe_load((SCENARIOS / 'prescribed_swing.yaml').read_text())
    shutil.copy(SCENARIOS / 'prescribed_swing.csv', folder / 'prescribed_swing.csv')
    for section, values in edits.items():
        data[section].update(values)
    path = folder / 'swing.yaml'
    path.write_text(yaml.safe_dump(data))
    return path


def test_prescribed_swing_runs_with_no_controller_through_ros_as_headless(multilift_run,
                                                                          tmp_path):
    ros, _ = flown_alike(multilift_run, 'prescribed_swing', tmp_path)
    for bag in ('ros', 'headless'):
        metadata = (tmp_path / bag / 'metadata.yaml').read_text()
        assert '/uav1/odom' in metadata
        assert 'rotor_cmd' not in metadata and 'attitude_setpoint' not in metadata, bag
    w0 = math.sqrt(9.81 / 1.0)  # the scenario's pendulum: l = 1 m; driven at w0 / 2, A 0.02 m
    w = w0 / 2
    amplitude = w0 ** 2 / (w0 ** 2 - w ** 2) * 0.02
    t = ros.payload_time
    error = np.abs(ros.payload_position()[:, 0] - amplitude * np.sin(w * t)).max()
    assert error < 0.01 * amplitude, error
    assert t[-1] > 19.9


def test_the_cli_says_it_in_one_line_and_exits_2(tmp_path):
    """A payload start off its cable (headless), and --external for a prescribed UAV."""
    path = swing_copy(tmp_path, payload={'initial_position': [0.0, 0.0, 8.5]})
    for extra in (['--headless'], ['--external', 'uav1']):
        if extra[0] == '--external':  # a valid prescribed scenario: uav1 has no controller
            path = swing_copy(tmp_path)
        run = subprocess.run([sys.executable, '-m', 'multilift_tools.cli', 'run', str(path),
                              *extra], capture_output=True, text=True, timeout=120)
        assert run.returncode == 2, run.stderr
        lines = run.stderr.strip().splitlines()
        assert len(lines) == 1, lines
        assert ('initial_position' if extra[0] == '--headless'
                else "uav1's motion is prescribed") in lines[0]
