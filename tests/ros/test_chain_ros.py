"""A twin-lift on heavy cables (`cable_model: chain`, docs/cables.md) flies through ROS as
headless: the same trajectories (1e-9 m) and tensions (the one tick), the cables' weight on
the UAVs (the top links' tensions above what rigid cables carry)."""
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
    # the top links hold the payload and the cables (their vertical parts sum to (m_p + 2 mu
    # l) g = 10.9 N on average): above m_p g plus half the cables' weight, 9.4 N, which rigid
    # cables at their 11 deg from vertical (m_p g / cos 11 deg = 8.0 N) do not reach
    assert np.median(ros.tensions(), axis=0).sum() > 9.4
