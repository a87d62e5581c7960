"""Bad estimation input on the command line (issue 33): one line and exit 2 (the scenario's
checks themselves: tests/unit/test_estimation.py)."""
from __future__ import annotations

import subprocess
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]


def test_the_command_line_refuses_bad_input_in_one_line_with_exit_2(tmp_path):
    data = yaml.safe_load((ROOT / 'scenarios' / 'twin_lift_realistic.yaml').read_text())
    del data['imu']
    path = tmp_path / 'no_imu.yaml'
    path.write_text(yaml.safe_dump(data))
    done = subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', str(path), '--headless'],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "estimator: 'ekf' needs the sensors imu" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
