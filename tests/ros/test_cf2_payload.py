"""`cf2_payload` (issue 34 item 4): two Crazyflie 2.1 (vehicle.preset) carry a 10 g point mass
on 0.5 m cables through the payload's waypoints (mission.tracks: payload). Through ROS as
headless to 1e-9 m; no rotor saturated; the payload follows its waypoints' minimum-snap path
(evaluated here by numpy from the scenario's coefficients, not by the tick) within 6 cm."""
from __future__ import annotations

import json

import numpy as np

from conftest import flown_alike
from multilift_sim import scenario as scenario_io
from multilift_sim.missions.polynomials import evaluate


def test_cf2_payload_flies_through_ros_as_headless_and_the_payload_follows(multilift_run,
                                                                           tmp_path):
    ros, _ = flown_alike(multilift_run, 'cf2_payload', tmp_path)
    summary = json.loads((tmp_path / 'ros' / 'summary.json').read_text())
    assert summary['sim']['saturated_time'] == [0.0, 0.0], summary['sim']
    assert min(summary['sim']['least_thrust_margin']) > 0.3  # room left on every rotor
    mission = scenario_io.load('cf2_payload').mission
    times = ros.payload_time
    path = np.array([evaluate(mission.knots, np.array(mission.coefficients), t)[:3]
                     for t in times])
    error = np.linalg.norm(ros.payload_position() - path, axis=1)
    assert error.max() < 0.06, error.max()
    assert np.ptp(path[:, 1]) > 0.7  # the path moved it: 0.8 m in y and back
