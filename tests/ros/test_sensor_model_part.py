"""A sensor model is a registered part (issue 31): a toy model defined in this file only, a
position sensor with a constant offset d, registers at test time, compiles into the one tick
(multilift_sim.sensors.sensing.SENSORS) and flies headless (the engine's `fly`, the per-object
`run_headless`, equal to the bit) and through the ROS nodes (`multilift run` of a scenario
whose `parts:` names this file: its processes import it and register the model), equal to the
headless run to 1e-9 m. pytest's own import leaves the registry alone (`registered` adds the
model for one block).

The expectation is worked out here, not read from the code: a single lift hovering at the
origin whose controller reads its position d off believes it is at p + d, so it flies as the
exact-state controller would towards the reference r - d: the same run as the exact one
started with its mission at -d (to rounding), and it settles at p = -d (its position loop has
integral action)."""
from __future__ import annotations

import os
import subprocess
import types
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_sim import sensors
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import MEASURED_COLUMNS, MEASURED_POSITION

ROOT = Path(__file__).resolve().parents[2]
MULTILIFT = str(ROOT / 'scripts' / 'multilift')


# -- the toy model: the position read `offset` [m] (world) off, every other slot exact --------
OFFSET = 0  # its constants row: the offset d [m], world (3 slots)


@jit
def measure_offset(constants, draws, memory, tick, truth, received):
    for c in range(MEASURED_COLUMNS):
        received[c] = truth[c]
    for j in range(3):
        received[MEASURED_POSITION + j] = truth[MEASURED_POSITION + j] + constants[OFFSET + j]


POSITION_OFFSET = types.SimpleNamespace(
    NAME='position_offset', UNITS={'offset': 'm'},
    parse=lambda d: d.vector('offset', (0.0, 0.0, 0.0)),
    constants=lambda offset, every: np.array(offset),
    memory=lambda offset: np.zeros(0),           # it keeps nothing
    draws=lambda offset, n_uavs, samples, dt, rng: np.zeros((n_uavs, samples, 0)),  # none
    measure=measure_offset)


def register_parts() -> None:
    """Called by a scenario's `parts:` naming this file (the runs' processes), not by pytest's
    import."""
    sensors.register(POSITION_OFFSET)


# -- the flights ------------------------------------------------------------------------------
D = (0.25, -0.5, 0.125)  # [m]
SETTLED = 40.0           # [s] of hover


def _hover(duration: float, sensors: dict | None = None, start=(0.0, 0.0, 0.0),
           parts: list[str] | None = None) -> str:
    """single_lift hovering at the origin for `duration` [s], its mission at `start`."""
    data = yaml.safe_load((ROOT / 'scenarios' / 'single_lift.yaml').read_text())
    data['simulation']['duration'] = duration
    data['mission'] = {'start': [float(v) for v in start],
                       'segments': [{'velocity': [0.0, 0.0, 0.0], 'until': duration}]}
    if sensors is not None:
        data['sensors'] = sensors
    if parts is not None:
        data['parts'] = parts
    return yaml.safe_dump(data)


def test_a_model_defined_in_a_test_registers_compiles_and_flies_headless():
    from multilift_control.headless import fly, run_headless
    from multilift_sim import scenario as scenario_io

    offset = {'model': 'position_offset', 'offset': list(D)}
    with pytest.raises(scenario_io.ScenarioError,
                       match="sensors.model: 'position_offset' must be one of measured_state"):
        scenario_io.loads(_hover(1.0, offset))  # not a model before it registers
    shifted = fly(scenario_io.loads(_hover(SETTLED, start=-np.array(D))))
    with sensors.registered(POSITION_OFFSET):
        with pytest.raises(scenario_io.ScenarioError, match=r'sensors\.offset: \[0\.1, 0\.2\] '
                           'must be a list of 3 numbers'):
            scenario_io.loads(_hover(1.0, dict(offset, offset=[0.1, 0.2])))
        scenario = scenario_io.loads(_hover(SETTLED, offset))
        engine_run = fly(scenario)
        object_run = run_headless(scenario.with_duration(2.0))
        short_run = fly(scenario.with_duration(2.0))
    assert 'position_offset' not in sensors.SENSOR_MODELS  # gone again
    # both paths, to the bit
    np.testing.assert_array_equal(short_run.engine.state[0], object_run.simulator.state)
    # the offset run is the exact run towards r - d, to rounding
    x, x_shifted = engine_run.engine.state[0], shifted.engine.state[0]
    np.testing.assert_allclose(x, x_shifted, rtol=0, atol=1e-9)
    # and it settles d off the reference: the UAV at -d, the payload hanging below it
    np.testing.assert_allclose(x[:3], -np.array(D), rtol=0, atol=2e-3)
    assert engine_run.summary()['sim']['seeds'] == {'sensors': 0}


@pytest.fixture(scope='module')
def runs(tmp_path_factory):
    """The run headless (it compiles the tick with the model into numba's cache), then through
    ROS (whose processes load it from there): their bags."""
    from conftest import next_domain

    folder = tmp_path_factory.mktemp('sensor_part')
    path = folder / 'hover_offset.yaml'
    path.write_text(_hover(2.0, {'model': 'position_offset', 'offset': list(D)},
                           parts=[os.path.relpath(__file__, folder)]))
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    bags = {}
    for mode in ('headless', 'ros'):
        bags[mode] = folder / mode
        args = [MULTILIFT, 'run', str(path), '--bag', str(bags[mode])]
        out = subprocess.run(args + (['--headless'] if mode == 'headless' else []),
                             capture_output=True, text=True, timeout=900, env=env)
        assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    return bags


def test_a_model_defined_in_a_test_flies_through_ros_as_headless(runs):
    """The ROS run's bag is the headless run's to 1e-9 m, and its leader's controller read the
    offset (/uav1/measured_odom = /uav1/odom + d, in both bags)."""
    from rosbags.highlevel import AnyReader

    from multilift_tools.bagdata import load_run

    ros, headless = load_run(runs['ros']), load_run(runs['headless'])
    assert np.array_equal(ros.t, headless.t) and len(ros.t) == 201
    assert np.abs(ros.uav_positions() - headless.uav_positions()).max() < 1e-9
    assert np.abs(ros.payload_position() - headless.payload_position()).max() < 1e-9
    for mode in ('ros', 'headless'):
        positions = {}
        with AnyReader([runs[mode]]) as reader:
            wanted = [c for c in reader.connections
                      if c.topic in ('/uav1/odom', '/uav1/measured_odom')]
            for connection, _, raw in reader.messages(wanted):
                p = reader.deserialize(raw, connection.msgtype).pose.pose.position
                positions.setdefault(connection.topic, []).append((p.x, p.y, p.z))
        read, true = (np.array(positions[t]) for t in ('/uav1/measured_odom', '/uav1/odom'))
        assert read.shape == true.shape == (201, 3)
        np.testing.assert_allclose(read - true, np.tile(D, (201, 1)), rtol=0, atol=1e-12)
        assert np.abs(true[-1] - true[0]).max() > 0.05  # it moved towards -d
    assert 'position_offset' not in sensors.SENSOR_MODELS  # pytest's import registered nothing
