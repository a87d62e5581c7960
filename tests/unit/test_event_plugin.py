"""An event kind is a registered part (issue 31): a toy kind defined in this file only,
registered at test time, compiles into the one tick (multilift_sim.physics.events.EVENTS) and flies
in both paths (the engine's `fly`, the per-object `run_headless`), held to an expectation
worked out here, not read from the code: every rotor of a single lift cut, the formation falls
freely, its centre of mass at g. And no shipped kind is named beyond its own two modules."""
from __future__ import annotations

import re
import types
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_control.headless import fly, run_headless
from multilift_sim.formation_params import StateLayout
from multilift_sim import events as event_kinds
from multilift_sim import scenario as scenario_io
from multilift_sim.events.keys import read_uav
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_UAV, EVENT_VALUE

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / 'scenarios'  # (not conftest's: the runs of tests/ros/test_event_part.py
#                                  import this file as their scenario's part)


# -- the toy kind: every rotor of a UAV at `factor` times its effectiveness ----------------
@jit
def apply_rotor_scale(row, tick, effectiveness, taut, released, silent_until, reel):
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


ROTOR_SCALE = types.SimpleNamespace(NAME='rotor_scale', KEYS=('uav', 'factor'), parse=_parse,
                                    pack=_pack, apply=apply_rotor_scale, describe=_describe)


def register_parts() -> None:
    """Called by a scenario's `parts:` naming this file (tests/ros/test_event_part.py's runs),
    not by pytest's import, so this test's process registers the kind only for its block."""
    event_kinds.register(ROTOR_SCALE)


G = 9.81
EVENT_TIME, END = 2.5, 3.0  # [s]


def _single_lift(duration: float, events: list[dict]) -> scenario_io.Scenario:
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['simulation']['duration'] = duration
    data['payload']['drag_coefficient'] = 0.0  # gravity alone once the rotors are cut
    data['events'] = events
    return scenario_io.loads(yaml.safe_dump(data))


def _centre_of_mass(scenario: scenario_io.Scenario, x: np.ndarray) -> tuple[np.ndarray, ...]:
    """(position [m], velocity [m/s]) of a single lift's UAV and payload together."""
    m_uav, m_payload = scenario.uavs[0].vehicle.mass, scenario.payload.mass
    layout = StateLayout(1)
    total = m_uav + m_payload
    return ((m_uav * layout.uav_positions(x)[0] + m_payload * layout.payload_position(x)) / total,
            (m_uav * layout.uav_velocities(x)[0] + m_payload * layout.payload_velocity(x))
            / total)


def test_a_kind_defined_in_a_test_registers_compiles_and_flies():
    cut = [{'time': EVENT_TIME, 'type': 'rotor_scale', 'uav': 1, 'factor': 0.0}]
    with pytest.raises(scenario_io.ScenarioError, match='type.*must be one of'):
        _single_lift(END, cut)  # not a kind before it registers
    before = _single_lift(EVENT_TIME, [])  # nothing differs before the event's tick
    x0 = fly(before).engine.state[0].copy()
    with event_kinds.registered(ROTOR_SCALE):
        with pytest.raises(scenario_io.ScenarioError, match=r'events\[0\]\.factor: -1'):
            _single_lift(END, [dict(cut[0], factor=-1.0)])
        scenario = _single_lift(END, cut)
        engine_run, object_run = fly(scenario), run_headless(scenario)
        states = engine_run.engine.state[0], object_run.simulator.state
        summary = engine_run.summary()['sim']['events']
    with pytest.raises(scenario_io.ScenarioError, match='type.*must be one of'):
        _single_lift(END, cut)  # gone again
    np.testing.assert_array_equal(states[0], states[1])  # both paths, to the bit
    # free fall from the event's tick: the centre of mass moves under gravity alone
    p0, v0 = _centre_of_mass(scenario, x0)
    dt = END - EVENT_TIME
    expected = p0 + v0 * dt + np.array([0.0, 0.0, -0.5 * G * dt * dt])
    p1, v1 = _centre_of_mass(scenario, states[0])
    np.testing.assert_allclose(p1, expected, atol=1e-6)
    np.testing.assert_allclose(v1, v0 + np.array([0.0, 0.0, -G * dt]), atol=1e-6)
    assert summary == [{'type': 'rotor_scale', 'uav': 1, 'rotor': 0, 'value': 0.0,
                        'time': EVENT_TIME, 'description': 'uav1 rotors at 0 times their thrust'}]


def test_no_shipped_kind_is_named_beyond_two_source_files():
    """Its physics module (multilift_sim/events/) and its controllers' reaction, if it has one
    (multilift_control/reactions/): a name as a string or a KIND_ constant."""
    sources = sorted((ROOT / 'ros_ws' / 'src').rglob('*.py'))
    assert sources
    for name in event_kinds.EVENT_KINDS:
        pattern = re.compile(rf"""['"]{name}['"]|\bKIND_{name.upper()}\b""")
        naming = [str(p.relative_to(ROOT)) for p in sources if pattern.search(p.read_text())]
        assert 1 <= len(naming) <= 2, (name, naming)
