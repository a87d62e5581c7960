"""The estimation on the command line (issue 33): bad input is one line and exit 2 (the
scenario's checks themselves: tests/unit/test_estimation.py); `twin_lift_realistic` flies alike
through the ROS nodes and headless."""
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


def test_a_payload_estimator_without_cable_sensors_is_one_line_and_exit_2(tmp_path):
    data = yaml.safe_load((ROOT / 'scenarios' / 'twin_lift_realistic.yaml').read_text())
    del data['cable_sensor']
    path = tmp_path / 'no_cable_sensor.yaml'
    path.write_text(yaml.safe_dump(data))
    done = subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', str(path), '--headless'],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "payload_estimator: 'cable_geometry' needs the sensors cable_sensor" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_the_estimator_flies_alike_through_ros_and_headless(tmp_path):
    """`twin_lift_realistic` (docs/estimation.md) through the ROS nodes and headless: the
    simulator node's estimator gives the controllers the numbers the engine's does (every
    /uav{i}/measured_odom and /uav{i}/estimate, the states to rounding); the estimate is not the
    state but within a few mm of it; the summary records both sensors' seeds."""
    import json
    import os

    import numpy as np

    from conftest import next_domain
    from multilift_tools.bagdata import load_run

    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    for mode in ('ros', 'headless'):
        args = [str(ROOT / 'scripts' / 'multilift'), 'run', 'twin_lift_realistic', '--duration',
                '2.0', '--bag', str(tmp_path / mode)] + (['--headless'] if mode == 'headless'
                                                          else [])
        out = subprocess.run(args, capture_output=True, text=True, timeout=600, env=env)
        assert out.returncode == 0, out.stderr[-2000:]
        seeds = next(line for line in out.stdout.splitlines() if line.startswith('  seeds'))
        assert sorted(seeds.split(None, 1)[1].split(', ')) == [
            'cable_sensor 1', 'imu 1', 'mocap 1']  # the three sensors' seeds, in some order
        assert 'estimate payload position rms' in out.stdout
    ros_run, headless_run = (load_run(tmp_path / mode) for mode in ('ros', 'headless'))
    assert np.abs(ros_run.uav_positions() - headless_run.uav_positions()).max() < 1e-9
    for i in (1, 2):
        ros, headless = (run.topic(f'/uav{i}/measured_odom') for run in (ros_run, headless_run))
        assert len(ros.t) == len(headless.t) == 201
        assert np.abs(ros['position'] - headless['position']).max() < 1e-9
        error = headless['position'] - headless_run.topic(f'/uav{i}/odom')['position']
        assert 1e-5 < np.abs(error).max() < 0.01
        ros, headless = (run.topic(f'/uav{i}/estimate') for run in (ros_run, headless_run))
        assert len(ros.t) == len(headless.t) == 201  # its estimate, with covariance
        assert np.abs(ros['position'] - headless['position']).max() < 1e-9
        assert np.array_equal(headless['position'],
                              headless_run.topic(f'/uav{i}/measured_odom')['position'])
    # the payload's estimate (/payload/estimate, with covariance), the same through both
    ros, headless = (run.topic('/payload/estimate') for run in (ros_run, headless_run))
    assert len(ros.t) == len(headless.t) == 201
    assert np.abs(ros['position'] - headless['position']).max() < 1e-9
    error = headless['position'] - headless_run.topic('/payload/odom')['position']
    assert 1e-6 < np.abs(error).max() < 0.05
    for mode in ('ros', 'headless'):
        summary = json.loads((tmp_path / mode / 'summary.json').read_text())
        assert summary['sim']['seeds'] == {'imu': 1, 'mocap': 1, 'cable_sensor': 1}
