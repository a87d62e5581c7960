"""An event kind defined in one test file flies through ROS (issue 31; the headless half and the
compiled dispatcher: tests/unit/test_event_plugin.py). This file defines `rotors_scaled`: every
rotor of a UAV at `factor` times its thrust from the event's tick. A scenario names this file
under `parts:`; the processes of its runs import it and register the kind (the simulator node
regenerates the tick's dispatcher with it). pytest's own import leaves the registry alone (the
runs are other processes), so no other test of this worker sees the kind.

The check is worked out here, not read from the code: with every rotor of a single lift cut at
EVENT_TIME, the centre of mass of UAV and payload falls freely, p0 + v0 t - g t^2 / 2.
"""
from __future__ import annotations

import os
import subprocess
import types
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_sim import events
from multilift_sim.events.keys import read_uav
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_UAV, EVENT_VALUE

ROOT = Path(__file__).resolve().parents[2]


@jit
def apply_rotors_scaled(row, tick, effectiveness, taut, released, silent_until):
    uav = int(row[EVENT_UAV])
    for r in range(effectiveness.shape[1]):
        effectiveness[uav, r] *= row[EVENT_VALUE]


def _parse(e, uavs, earlier):
    return dict(uav=read_uav(e, uavs), values=(('factor', e.number(
        'factor', ..., lambda v: v >= 0, 'must be >= 0')),))


def _pack(event, row, rate):
    row[EVENT_VALUE] = event.value('factor')


def _describe(row):
    uav, value = int(row[EVENT_UAV]) + 1, float(row[EVENT_VALUE])
    return uav, 0, value, f'uav{uav} rotors at {value:g} times their thrust'


ROTORS_SCALED = types.SimpleNamespace(NAME='rotors_scaled', KEYS=('uav', 'factor'),
                                      parse=_parse, pack=_pack, apply=apply_rotors_scaled,
                                      describe=_describe)
if __name__.startswith('multilift_parts_'):  # imported by a scenario's `parts:`
    events.register(ROTORS_SCALED)

EVENT_TIME, END, G = 2.5, 3.0, 9.81  # [s], [s], [m/s^2]


def _scenario_file(folder: Path) -> Path:
    data = yaml.safe_load((ROOT / 'scenarios' / 'single_lift.yaml').read_text())
    data['parts'] = [os.path.relpath(__file__, folder)]
    data['name'] = 'single_lift_rotors_cut'
    data['simulation']['duration'] = END
    data['payload']['drag_coefficient'] = 0.0  # gravity alone once the rotors are cut
    data['events'] = [{'time': EVENT_TIME, 'type': 'rotors_scaled', 'uav': 1, 'factor': 0.0}]
    path = folder / 'rotors_cut.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope='module')
def runs(tmp_path_factory):
    """The run headless (it compiles the tick with the kind into numba's cache), then through
    ROS (whose simulator node loads it from there): their bags."""
    folder = tmp_path_factory.mktemp('event_part')
    path = _scenario_file(folder)
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    bags = {}
    for mode in ('headless', 'ros'):
        bags[mode] = folder / mode
        args = [str(ROOT / 'scripts' / 'multilift'), 'run', str(path), '--bag', str(bags[mode])]
        out = subprocess.run(args + (['--headless'] if mode == 'headless' else []),
                             capture_output=True, text=True, timeout=900, env=env)
        assert out.returncode == 0, out.stderr[-2000:]
    return path, bags


@pytest.mark.parametrize('mode', ['headless', 'ros'])
def test_an_event_kind_defined_in_a_test_file_cuts_the_rotors_through_ros(runs, mode):
    from multilift_tools.bagdata import load_run
    path, bags = runs
    data = yaml.safe_load(path.read_text())
    m_uav, m_payload = data['vehicle']['mass'], data['payload']['mass']
    run = load_run(bags[mode])
    t = run.t
    uav, payload = run.uav_positions()[0], run.payload_position()
    centre = (m_uav * uav + m_payload * payload) / (m_uav + m_payload)  # [m], world
    start = int(np.argmin(np.abs(t - EVENT_TIME)))  # the event's tick: the cut from there
    falling = t[start:] - t[start]
    # ballistic: centre + g t^2 / 2 (up) is a straight line in t on every axis
    lifted = centre[start:] + np.outer(0.5 * G * falling ** 2, [0.0, 0.0, 1.0])
    for axis in range(3):
        line = np.polyval(np.polyfit(falling, lifted[:, axis], 1), falling)
        assert np.abs(lifted[:, axis] - line).max() < 1e-6, axis
    assert t[-1] == pytest.approx(END)
    fall = centre[start, 2] - centre[-1, 2]
    assert fall > 1.0  # it fell: 1.23 m less 0.15 m of the climb at 0.3 m/s it was cut in


def test_the_runs_record_the_event(runs):
    from multilift_tools.bagdata import load_run
    path, bags = runs
    for mode in ('headless', 'ros'):
        summary = yaml.safe_load((bags[mode] / 'summary.json').read_text())
        assert [e['type'] for e in summary['sim']['events']] == ['rotors_scaled'], mode
    assert 'rotors_scaled' not in events.EVENT_KINDS  # pytest's import registered nothing
    assert np.abs(load_run(bags['ros']).payload_position()
                  - load_run(bags['headless']).payload_position()).max() < 1e-9
