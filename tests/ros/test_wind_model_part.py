"""A wind model is a registered part in one file (issue 31): this file defines `wind.breeze`, a
uniform wind that rises linearly to its speed over `ramp_time` and then holds, registered when
the file is imported. A scenario names this file under `parts:`, so the simulator node imports
it as the test does; no other file knows the model.

The check is worked out here from the statics, not read from the code: a single lift hovering
in a steady wind U holds its payload where the cable balances the payload's weight m_p g
against its drag c_pd U^2 (seed Eq. 2.53 on the air-relative velocity), so the cable leans
downwind by theta with tan(theta) = c_pd U^2 / (m_p g).
"""
from __future__ import annotations

import os
import subprocess
import types
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_sim import wind

ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Breeze:
    speed: float                            # [m/s]
    direction: tuple[float, float, float]   # unit, world
    ramp_time: float                        # [s]


def _parse(section) -> Breeze:
    direction = np.array(section.vector('direction'))
    if not np.linalg.norm(direction) > 0:
        raise section.fail('direction', list(direction), 'must not be zero')
    return Breeze(speed=section.non_negative('speed'),
                  direction=tuple(direction / np.linalg.norm(direction)),
                  ramp_time=section.positive('ramp_time'))


def _series(config: Breeze, scenario, samples: int, dt: float) -> np.ndarray:
    ramp = np.minimum(np.arange(samples) * dt / config.ramp_time, 1.0)
    return np.outer(config.speed * ramp, config.direction)


BREEZE = types.SimpleNamespace(NAME='breeze', parse=_parse, series=_series,
                               UNITS={'speed': 'm/s', 'direction': '', 'ramp_time': 's'})
if BREEZE.NAME not in wind.WIND_MODELS:
    wind.register(BREEZE)

SPEED, DURATION = 4.0, 30.0  # [m/s], [s]


def _scenario_file(folder: Path) -> Path:
    data = yaml.safe_load((ROOT / 'scenarios' / 'single_lift.yaml').read_text())
    data['parts'] = [os.path.relpath(__file__, folder)]
    data['name'] = 'single_lift_breeze'
    data['wind'] = {'breeze': {'speed': SPEED, 'direction': [1.0, 0.0, 0.0], 'ramp_time': 5.0}}
    data['simulation']['duration'] = DURATION
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': DURATION}]
    path = folder / 'breeze.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize('mode', ['ros', 'headless'])
def test_a_wind_model_defined_in_a_test_file_leans_the_cable_as_the_statics_say(
        tmp_path, ros_env, mode):
    from multilift_tools.bagdata import load_run
    path = _scenario_file(tmp_path)
    args = [str(ROOT / 'scripts' / 'multilift'), 'run', str(path), '--bag', str(tmp_path / 'bag')]
    if mode == 'headless':
        args.append('--headless')
    out = subprocess.run(args, capture_output=True, text=True, timeout=600, env=ros_env)
    assert out.returncode == 0, out.stderr[-2000:]
    run = load_run(tmp_path / 'bag')
    cable = run.payload_position()[-1] - run.uav_positions()[0][-1]  # UAV -> payload [m]
    data = yaml.safe_load(path.read_text())
    drag, weight = data['payload']['drag_coefficient'] * SPEED ** 2, \
        data['payload']['mass'] * data['simulation']['gravity']
    assert cable[0] / -cable[2] == pytest.approx(drag / weight, rel=2e-3)  # ~26 deg downwind
    assert abs(cable[1]) < 1e-3


def test_the_model_s_keys_are_validated_and_have_units(tmp_path):
    from multilift_sim import scenario as scenario_io
    from multilift_sim.units import unit_of
    data = yaml.safe_load(_scenario_file(tmp_path).read_text())
    data['parts'] = [str(Path(__file__).resolve())]
    data['wind']['breeze']['ramp_time'] = 0.0
    with pytest.raises(scenario_io.ScenarioError, match=r'wind\.breeze\.ramp_time: 0\.0 must'):
        scenario_io.loads(yaml.safe_dump(data))
    assert unit_of('wind.breeze.speed') == 'm/s' and unit_of('wind.turbulence.airspeed') == 'm/s'
    data['wind'] = {'gale': {'speed': 1.0}}
    with pytest.raises(scenario_io.ScenarioError, match=r'wind\.gale: unknown key'):
        scenario_io.loads(yaml.safe_dump(data))
