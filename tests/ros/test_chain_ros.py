"""A twin-lift on heavy cables (`cable_model: chain`, docs/cables.md) flies through ROS as
headless: the same trajectories (1e-9 m) and tensions (the one tick), the cables' weight on
the UAVs (the top links' tension above the rigid cables' share of the payload alone)."""
from __future__ import annotations

import numpy as np
import yaml

from conftest import SCENARIOS, flown_alike


def test_a_chain_twin_lift_flies_alike_through_ros_and_headless(tmp_path, multilift_run):
    data = yaml.safe_load((SCENARIOS / 'twin_lift_chain.yaml').read_text())
    data['simulation'].update(duration=6.0)
    path = tmp_path / 'twin_lift_chain.yaml'
    path.write_text(yaml.safe_dump(data))
    ros, headless = flown_alike(multilift_run, path, tmp_path)
    assert np.abs(ros.tensions() - headless.tensions()).max() < 1e-6
    # each top link holds its half of the payload and of its own cable's weight at least
    # (m_p / 2 + mu l) g = 5.43 N hanging straight; the rigid cables' share is 3.9 N
    assert np.median(ros.tensions(), axis=0).min() > 5.0
