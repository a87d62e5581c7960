"""An estimator is a registered part (issue 33 item 2): a toy estimator defined in this file
only, one that believes every UAV's position is d off, registers at test time
(`estimators.ESTIMATORS.registered`), compiles into the one tick through the dispatcher
generated from the registry (estimators.estimation.ESTIMATORS_DISPATCH) and flies headless,
the engine's `fly` and the per-object `run_headless` equal to the bit.

The expectation is worked out here, not read from the code: a single lift hovering at the
origin whose controller reads its position d off flies as the exact-state controller would
towards the reference r - d: the same run as the exact one started with its mission at -d (to
rounding), settled at p = -d."""
from __future__ import annotations

import types
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_sim import estimators
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import MEASURED_POSITION

ROOT = Path(__file__).resolve().parents[2]
OFFSET = 0  # the toy's constants row: the offset d [m], world (3 slots)


@jit
def estimate_offset(constants, sensors, memory, tick, received):
    for j in range(3):
        received[MEASURED_POSITION + j] += constants[OFFSET + j]


POSITION_OFFSET = types.SimpleNamespace(
    NAME='offset_estimate', UNITS={'offset': 'm'},
    parse=lambda d: d.vector('offset', (0.0, 0.0, 0.0)),
    needs=lambda sensor_names: '',              # it reads no sensor
    constants=lambda offset, scenario, rows: np.array(offset),
    memory=lambda offset, scenario: np.zeros(0),
    estimate=estimate_offset)

D = (0.25, -0.5, 0.125)  # [m]
SETTLED = 40.0           # [s] of hover


def _hover(duration: float, estimator: dict | None = None, start=(0.0, 0.0, 0.0)) -> str:
    data = yaml.safe_load((ROOT / 'scenarios' / 'single_lift.yaml').read_text())
    data['simulation']['duration'] = duration
    data['mission'] = {'start': [float(v) for v in start],
                       'segments': [{'velocity': [0.0, 0.0, 0.0], 'until': duration}]}
    if estimator is not None:
        data['estimator'] = estimator
    return yaml.safe_dump(data)


def test_an_estimator_defined_in_a_test_registers_compiles_and_flies_headless():
    from multilift_control.headless import fly, run_headless
    from multilift_sim import scenario as scenario_io

    toy = {'model': 'offset_estimate', 'offset': list(D)}
    with pytest.raises(scenario_io.ScenarioError,
                       match="estimator.model: 'offset_estimate' must be one of none, ekf"):
        scenario_io.loads(_hover(1.0, toy))  # not an estimator before it registers
    shifted = fly(scenario_io.loads(_hover(SETTLED, start=-np.array(D))))
    with estimators.ESTIMATORS.registered(POSITION_OFFSET):
        scenario = scenario_io.loads(_hover(SETTLED, toy))
        engine_run = fly(scenario)
        object_run = run_headless(scenario.with_duration(2.0))
        short_run = fly(scenario.with_duration(2.0))
    assert 'offset_estimate' not in estimators.ESTIMATORS  # gone again
    np.testing.assert_array_equal(short_run.engine.state[0], object_run.simulator.state)
    x, x_shifted = engine_run.engine.state[0], shifted.engine.state[0]
    np.testing.assert_allclose(x, x_shifted, rtol=0, atol=1e-9)
    np.testing.assert_allclose(x[:3], -np.array(D), rtol=0, atol=2e-3)
