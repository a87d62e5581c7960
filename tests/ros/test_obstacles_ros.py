"""Obstacles through ROS (issue 34 items 5 and 6): `window` flown by `multilift run` equals its
headless run to 1e-9 m (conftest.flown_alike) and both summaries give the same clearances,
the least at least 0.05 m with no contact; a scenario built to collide (cf2_payload straight
through a pillar) exits 1 with one line naming what touched what and when, the same line
through ROS and headless."""
from __future__ import annotations

import json
import subprocess
import sys

import yaml

from conftest import collide_scenario, flown_alike


def test_window_through_ros_as_headless_with_the_same_clearances(multilift_run, tmp_path):
    flown_alike(multilift_run, 'window', tmp_path)
    ros, headless = (json.loads((tmp_path / where / 'summary.json').read_text())['sim']
                     for where in ('ros', 'headless'))
    assert ros['clearance'] == headless['clearance'] and ros['contact'] is None
    assert ros['least_clearance'] >= 0.05


def test_a_contact_stops_ros_and_headless_runs_with_the_same_line(multilift_run, tmp_path):
    path = tmp_path / 'collide.yaml'
    path.write_text(yaml.safe_dump(collide_scenario('stop')))
    headless = subprocess.run([sys.executable, '-m', 'multilift_tools.cli', 'run', str(path),
                               '--headless'], capture_output=True, text=True, timeout=600)
    assert headless.returncode == 1, headless.stderr
    line = headless.stderr.strip().splitlines()[-1]
    assert line.startswith("error: contact: uav1 touched obstacle 'pillar' at t = "), line
    run = multilift_run(str(path), startup_timeout=600)
    assert run.wait(timeout=600) == 1, run.output()[-2000:]
    assert line.removeprefix('error: ') in run.output()
