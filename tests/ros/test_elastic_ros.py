"""An elastic twin-lift (`cable_model: elastic`, docs/cables.md) flies through ROS as headless:
the same trajectories and tensions (the one tick), its ropes never pushing, and the same
rope figures in summary.json (each rope's max stretch and peak tension)."""
from __future__ import annotations

import numpy as np
import yaml

from conftest import SCENARIOS, flown_alike


def test_an_elastic_twin_lift_flies_alike_through_ros_and_headless(tmp_path, multilift_run):
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    data.update(cable_model='elastic', cable={'axial_stiffness': 2.0e4, 'damping': 10.0})
    data['simulation'].update(duration=6.0, substeps=2)
    path = tmp_path / 'twin_lift_elastic.yaml'
    path.write_text(yaml.safe_dump(data))
    ros, headless = flown_alike(multilift_run, path, tmp_path)
    assert np.abs(ros.tensions() - headless.tensions()).max() < 1e-6
    assert ros.tensions().min() >= 0.0 and ros.tensions().max() > 3.0  # ropes pull, never push
    for key in ('max_stretch', 'peak_tension'):
        np.testing.assert_allclose(ros.summary['sim'][key], headless.summary['sim'][key],
                                   rtol=1e-9)
    np.testing.assert_allclose(ros.summary['sim']['peak_tension'], ros.tensions().max(axis=0),
                               rtol=1e-9)
