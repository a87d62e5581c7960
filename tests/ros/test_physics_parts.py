"""A payload type, a cable model and a formulation are registered parts, each declared in one
file (issue 31): this test file defines three toys and registers them in `register_parts()`,
which a scenario's `parts:` calls in every process that reads it (the simulator node too); no
other file knows them.

- payload type `sphere`: a point mass whose drag comes from its `radius` [m] and `drag_area`
  is not given: c_pd = rho C_D pi r^2 / 2 (air at sea level, a sphere's C_D = 0.47);
- cable model `rated`: the seed's rigid cables with a `cable: {rated_tension: N}` key, refusing
  a payload whose hanging weight share exceeds it;
- formulation `calm`: the Baumgarte DAE that declares it models no wind.

The checks are worked out here, not read from the code: a single lift hovering in a steady wind
U holds the payload where its cable balances m_p g against the drag c_pd U^2 (seed Eq. 2.53 on
the air-relative velocity), tan(theta) = c_pd U^2 / (m_p g), with c_pd from the radius.
"""
from __future__ import annotations

import math
import os
import types
from pathlib import Path

import numpy as np
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
AIR_DENSITY, SPHERE_DRAG = 1.225, 0.47  # [kg/m^3], C_D [-]
RADIUS, WIND, DURATION = 0.15, 3.0, 30.0  # [m], [m/s], [s]


def _sphere_parse(p, payload, n):
    radius = p.positive('radius')
    drag = 0.5 * AIR_DENSITY * SPHERE_DRAG * math.pi * radius * radius
    return payload.__class__(**{**payload.__dict__, 'drag_coefficient': drag})


def _rated_cable(top):
    section = top.section('cable')
    rated = section.positive('rated_tension')
    section.done()
    return rated


def _rated_uav_cable(u, length, base):
    return 0.0, 0.0


def _rated_check(scenario):
    from multilift_sim.cables import CABLE_MODELS
    share = scenario.payload.mass * scenario.simulation.gravity / scenario.n_uavs
    if share > scenario.cable:  # what _rated_cable read: the rated tension [N]
        return (f'cable_model: rated: each cable carries {share:.1f} N hanging, beyond its '
                f'rated_tension {scenario.cable:g} N')
    return CABLE_MODELS['rigid'].check(scenario)


def register_parts():
    from multilift_sim.cables import CABLE_MODELS
    from multilift_sim.formulations import FORMULATIONS
    from multilift_sim.payloads import PAYLOAD_TYPES
    PAYLOAD_TYPES.register(types.SimpleNamespace(
        NAME='sphere', NEEDS=frozenset(), MIN_UAVS=1, parse=_sphere_parse))
    CABLE_MODELS.register(types.SimpleNamespace(
        NAME='rated', NEEDS=frozenset(), RELEASE_LIMIT_DEG=90.0, KEEPS_LENGTH=True,
        SLACKENS=False, REELS=False, parse_cable=_rated_cable, parse_uav_cable=_rated_uav_cable,
        check=_rated_check))
    baumgarte = FORMULATIONS['baumgarte']
    FORMULATIONS.register(types.SimpleNamespace(
        NAME='calm', SUPPORTS=baumgarte.SUPPORTS - {'wind'}, make=baumgarte.make))


def _scenario_file(folder: Path, **edits) -> Path:
    data = yaml.safe_load((ROOT / 'scenarios' / 'single_lift.yaml').read_text())
    data['parts'] = [os.path.relpath(__file__, folder)]
    data['name'] = 'single_lift_sphere'
    data['payload'] = {**data['payload'], 'type': 'sphere', 'radius': RADIUS}
    data['payload'].pop('drag_coefficient', None)
    data.update(cable_model='rated', cable={'rated_tension': 50.0},
                wind={'velocity': [WIND, 0.0, 0.0]})
    data['simulation']['duration'] = DURATION
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': DURATION}]
    for key, value in edits.items():
        data[key] = value
    path = folder / 'sphere.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_a_payload_type_and_a_cable_model_from_a_test_file_fly_as_the_statics_say(
        tmp_path, multilift_run):
    from conftest import flown_alike  # (here: a scenario's `parts:` imports this file too)
    path = _scenario_file(tmp_path)
    ros, _ = flown_alike(multilift_run, path, tmp_path)
    cable = ros.payload_position()[-1] - ros.uav_positions()[0][-1]  # UAV -> payload [m]
    data = yaml.safe_load(path.read_text())
    drag = 0.5 * AIR_DENSITY * SPHERE_DRAG * math.pi * RADIUS ** 2 * WIND ** 2
    weight = data['payload']['mass'] * data['simulation']['gravity']
    assert cable[0] / -cable[2] == pytest.approx(drag / weight, rel=2e-3)
    assert abs(cable[1]) < 1e-3


def test_each_part_s_declarations_are_what_validation_reads(tmp_path):
    from multilift_control.headless import fly
    from multilift_sim import scenario as scenario_io
    path = _scenario_file(tmp_path)
    data = yaml.safe_load(path.read_text())
    data['parts'] = [str(Path(__file__).resolve())]
    scenario_io.loads(yaml.safe_dump(data))  # the parts register
    # the cable model's own check, in one line
    heavy = {**data, 'cable': {'rated_tension': 1.0}}
    with pytest.raises(scenario_io.ScenarioError, match=r'beyond its rated_tension 1 N'):
        scenario_io.loads(yaml.safe_dump(heavy), str(path))
    # the formulation's declaration: no wind, named in one line with who models it
    calm = {**data, 'simulation': {**data['simulation'], 'integrator': 'calm'}}
    with pytest.raises(scenario_io.ScenarioError,
                       match=r"wind and vehicle.drag_coefficient need simulation.integrator: "
                             r"baumgarte, got 'calm'"):
        scenario_io.loads(yaml.safe_dump(calm))
    # without wind, `calm` is the Baumgarte DAE: the same run to the bit
    still = {**calm, 'wind': {'velocity': [0.0, 0.0, 0.0]}}
    still['simulation'] = {**still['simulation'], 'duration': 2.0}
    states = [fly(scenario_io.loads(yaml.safe_dump({**still, 'simulation': {
        **still['simulation'], 'integrator': name}}))).engine.state[0]
        for name in ('calm', 'baumgarte')]
    np.testing.assert_array_equal(states[0], states[1])
    # the payload type's key
    bad = {**data, 'payload': {**data['payload'], 'radius': -1.0}}
    with pytest.raises(scenario_io.ScenarioError, match=r'payload\.radius: -1\.0 must'):
        scenario_io.loads(yaml.safe_dump(bad))
