"""An elastic twin-lift (`cable_model: elastic`, docs/cables.md) flies through ROS as headless:
the same trajectories and tensions (the one tick), its ropes never pushing."""
from __future__ import annotations

import os
import subprocess

import numpy as np
import yaml

from conftest import ROOT, SCENARIOS, next_domain
from multilift_tools.bagdata import load_run


def test_an_elastic_twin_lift_flies_alike_through_ros_and_headless(tmp_path):
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    data.update(cable_model='elastic', cable={'axial_stiffness': 2.0e4, 'damping': 10.0})
    data['simulation'].update(duration=6.0, substeps=2)
    path = tmp_path / 'twin_lift_elastic.yaml'
    path.write_text(yaml.safe_dump(data))
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    runs = {}
    for mode in ('ros', 'headless'):
        args = [str(ROOT / 'scripts' / 'multilift'), 'run', str(path), '--bag',
                str(tmp_path / mode)] + (['--headless'] if mode == 'headless' else [])
        out = subprocess.run(args, capture_output=True, text=True, timeout=600, env=env)
        assert out.returncode == 0, out.stderr[-2000:]
        runs[mode] = load_run(tmp_path / mode)
    ros, headless = runs['ros'], runs['headless']
    assert np.abs(ros.payload_position() - headless.payload_position()).max() < 1e-9
    assert np.abs(np.array(ros.uav_positions()) - np.array(headless.uav_positions())).max() \
        < 1e-9
    assert np.abs(ros.tensions() - headless.tensions()).max() < 1e-6
    assert ros.tensions().min() >= 0.0 and ros.tensions().max() > 3.0  # ropes pull, never push
