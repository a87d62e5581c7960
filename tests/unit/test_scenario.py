"""Scenario loading: every shipped scenario loads; bad values are one clear error."""
from __future__ import annotations

import math

import pytest
import yaml

from conftest import SCENARIOS
from multilift_sim import scenario as scenario_io


def _edited(name: str, edit) -> str:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    edit(data)
    return yaml.safe_dump(data)


@pytest.mark.parametrize('path', sorted(SCENARIOS.glob('*.yaml')), ids=lambda p: p.stem)
def test_shipped_scenarios_load(path):
    s = scenario_io.load(str(path))
    assert s.name == path.stem
    assert s.n_uavs >= 1
    assert s.simulation.physics_steps_per_tick >= 1


def test_single_lift_is_the_seed_mission():
    s = scenario_io.load('single_lift')
    v = s.uavs[0].vehicle
    assert (v.mass, v.arm_length, v.thrust_coefficient, v.moment_coefficient) == \
        (2.5, 0.2, 1.83e-6, 1.85e-7)
    assert (v.rotor_speed_min, v.rotor_speed_max, v.frame_type) == (0.0, 2100.0, 'quad_x')
    assert (s.payload.mass, s.uavs[0].cable_length) == (0.4, 2.5)
    ends = [seg.end_time for seg in s.mission.segments]
    assert ends == [10.0, 25.0, 40.0, 100.0, 120.0]
    assert s.mission.segments[0].velocity == (0.0, 0.0, 0.3)     # climb, z up
    assert s.mission.segments[2].velocity == (0.0, -0.5, 0.0)    # the seed's +j is -y
    assert s.simulation.duration == 120.0


def test_swing_release_angles():
    s = scenario_io.load('single_lift_swing')
    assert math.degrees(s.payload.alpha) == pytest.approx(15.0)
    assert math.degrees(s.payload.beta) == pytest.approx(25.0)
    assert s.control.mode == 'constant_rotor_speed'


@pytest.mark.parametrize('path', sorted(SCENARIOS.glob('*.yaml')), ids=lambda p: p.stem)
def test_shipped_scenarios_load_without_a_warning(path):
    """The seed's inertia is a documented choice of the shipped files (inertia_source: seed)."""
    assert scenario_io.load(str(path)).warnings == ()


def test_seed_inertia_in_a_users_file_warns_but_loads():
    s = scenario_io.loads(_edited('single_lift', lambda d: d['vehicle'].pop('inertia_source')))
    assert any('triangle inequality' in w for w in s.warnings)
    s = scenario_io.loads(_edited(
        'twin_lift', lambda d: d['uavs'][1].update(inertia=[0.2, 0.9, 0.3])))
    assert [w for w in s.warnings if 'uavs[1].inertia' in w]


def test_inertia_source_seed_must_be_the_seeds_inertia():
    text = _edited('single_lift', lambda d: d['vehicle'].update(inertia=[0.5, 0.5, 0.9]))
    with pytest.raises(scenario_io.ScenarioError, match='vehicle.inertia_source'):
        scenario_io.loads(text)


BAD = [
    (lambda d: d['vehicle'].update(mass=-1.0), 'vehicle.mass: -1.0 must be > 0'),
    (lambda d: d['uavs'][0].update(cable_length=0.0), 'uavs[0].cable_length: 0.0 must be > 0'),
    (lambda d: d['vehicle'].update(frame_type='tri'), "vehicle.frame_type: 'tri' must be one of"),
    (lambda d: d['payload'].pop('mass'), 'payload.mass: missing key'),
    (lambda d: d['payload'].update(mass=4.0), 'payload.mass: 4.0 kg is too heavy'),
    (lambda d: d['vehicle'].update(masss=2.5), 'vehicle.masss: unknown key'),
    (lambda d: d['simulation'].update(control_rate=300.0), 'simulation.control_rate'),
    (lambda d: d['vehicle'].update(inertia=[1, 2]), 'vehicle.inertia'),
    (lambda d: d['vehicle'].update(rotor_speed_max=-5), 'vehicle.rotor_speed_max'),
    (lambda d: d['mission']['segments'][1].update(until=5.0), 'mission.segments[1]'),
    (lambda d: d['vehicle'].update(mass='heavy'), "vehicle.mass: 'heavy' must be a number"),
    (lambda d: d['vehicle'].update(mass=float('nan')), 'vehicle.mass: nan must be finite'),
    (lambda d: d['mission'].update(reference_filter_time=-1.0),
     'mission.reference_filter_time: -1.0 must be >= 0'),
    (lambda d: d['vehicle'].update(inertia_source='cad'), "vehicle.inertia_source: 'cad'"),
    (lambda d: d['simulation'].update(integrator='euler'),
     "simulation.integrator: 'euler' must be one of baumgarte, nullspace"),
]


def test_nullspace_integrator_is_selectable_and_holds_the_cable():
    from multilift_control.headless import run_headless
    text = _edited('single_lift_swing', lambda d: d['simulation'].update(integrator='nullspace',
                                                                          duration=2.0))
    s = scenario_io.loads(text)
    assert s.simulation.integrator == 'nullspace'
    sim = run_headless(s).simulator
    assert type(sim.model).__name__ == 'NullSpaceModel'
    assert sim.stats.max_abs_constraint < 1e-10


FORMATION_BAD = [
    (lambda d: d.update(cable_length=1.0), 'formation: cable 1 (1 m) is shorter than'),
    (lambda d: d['payload'].update(mass=8.0), 'payload.mass: 8.0 kg is too heavy'),
    (lambda d: d['formation'].update(geometry='star'), "formation.geometry: 'star' must be one"),
    (lambda d: d['formation'].update(offsets=[]), 'formation.offsets'),
    (lambda d: d['formation'].update(n=3), 'uavs: 2 entries but formation.n is 3'),
    (lambda d: d['uavs'][1].update(position=[1, 2, 3]), 'uavs[1].position'),
]


@pytest.mark.parametrize('edit,message', FORMATION_BAD, ids=[m for _, m in FORMATION_BAD])
def test_formations_that_cannot_fly_fail_at_load(edit, message):
    with pytest.raises(scenario_io.ScenarioError) as err:
        scenario_io.loads(_edited('twin_lift', edit), 'x.yaml')
    assert message in str(err.value)


@pytest.mark.parametrize('edit,message', BAD, ids=[m for _, m in BAD])
def test_bad_values_name_key_and_rule(edit, message):
    with pytest.raises(scenario_io.ScenarioError) as err:
        scenario_io.loads(_edited('single_lift', edit), 'x.yaml')
    assert message in str(err.value)
    assert str(err.value).startswith('x.yaml: ')


def test_a_run_flies_at_least_one_control_period():
    with pytest.raises(scenario_io.ScenarioError, match=r'x.yaml: simulation.duration: 0.004 '
                       r'must be at least one control period \(1/control_rate = 0.01 s\)'):
        scenario_io.loads(_edited('single_lift', lambda d: d['simulation'].update(
            duration=0.004)), 'x.yaml')
    scenario = scenario_io.load('single_lift')
    assert scenario.with_duration(0.006).simulation.tick_count == 1
    assert scenario.with_duration(3).simulation.duration == 3.0
    for short in (0.004, 0.0, -1.0, math.nan, math.inf):
        with pytest.raises(scenario_io.ScenarioError, match='at least one control period'):
            scenario.with_duration(short)


def test_exponent_numbers_without_a_dot_or_a_signed_exponent_are_numbers(tmp_path):
    """YAML 1.1 (PyYAML) reads `1.5e5` as text; a scenario reads it as the number a user wrote
    (as YAML 1.2 and JSON do), in a file and in a sweep's base."""
    import yaml as _yaml

    from multilift_sim import scenario as _scenario
    assert _yaml.safe_load('k: 1.5e5')['k'] == '1.5e5'  # what PyYAML alone gives
    text = _scenario.resolve('twin_lift').read_text()
    data = _scenario.read_yaml(text)
    data['cable_model'] = 'elastic'
    data['cable'] = {'axial_stiffness': 'PLACEHOLDER', 'damping': 8.0}
    data['simulation']['substeps'] = 4
    path = tmp_path / 'rope.yaml'
    path.write_text(_yaml.safe_dump(data, sort_keys=False).replace('PLACEHOLDER', '1.5e5'))
    assert '1.5e5' in path.read_text()
    loaded = _scenario.load(str(path))
    assert loaded.cable_model == 'elastic'
    assert _scenario.read_yaml('[1e5, 2.5E-3, -3e+2, 1.0, 7, 1e, e5]') == [
        1e5, 2.5e-3, -300.0, 1.0, 7, '1e', 'e5']
