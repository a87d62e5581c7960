"""What a scenario asks beyond its bodies or vehicles is refused at load (scenario/limits.py):
a rigid body's attach points outside its shape, a mission faster than MAX_MISSION_SPEED or a
filtered corner beyond the formation's thrust-to-weight margin; each one line naming the file,
the key, the value and the rule, and `multilift run` exits 2. Every shipped scenario loads."""
from __future__ import annotations

import math

import pytest
import yaml

from conftest import SCENARIOS
from multilift_sim import scenario as scenario_io
from multilift_sim.payloads.rigid_body import attach_margin, distance_outside
from multilift_sim.scenario.limits import MAX_MISSION_SPEED, max_mission_acceleration
from multilift_tools import cli


def _edited(name: str, edit) -> str:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    edit(data)
    return yaml.safe_dump(data)


def _error(text: str) -> str:
    with pytest.raises(scenario_io.ScenarioError) as info:
        scenario_io.loads(text)
    message = str(info.value)
    assert '\n' not in message
    return message


@pytest.mark.parametrize('path', sorted(SCENARIOS.glob('*.yaml')), ids=lambda p: p.stem)
def test_every_shipped_scenario_is_within_the_limits(path):
    s = scenario_io.load(str(path))
    assert s.name == path.stem


def test_distance_outside_box_and_cylinder():
    box = (1.0, 0.6, 0.4)
    assert distance_outside('box', box, (0.5, 0.3, 0.2)) == 0.0      # a corner
    assert distance_outside('box', box, (0.0, 0.0, 0.0)) == 0.0
    assert distance_outside('box', box, (2.5, 0.3, 0.2)) == pytest.approx(2.0)
    assert distance_outside('box', box, (0.8, 0.7, 0.2)) == pytest.approx(0.5)  # 0.3, 0.4
    beam = (3.0, 0.03)
    assert distance_outside('cylinder', beam, (1.5, 0.0, 0.0)) == 0.0
    assert distance_outside('cylinder', beam, (0.0, 0.0, 0.03)) == 0.0
    assert distance_outside('cylinder', beam, (0.0, 0.03, 0.04)) == pytest.approx(0.02)
    assert distance_outside('cylinder', beam, (1.8, 0.0, 0.0)) == pytest.approx(0.3)
    assert attach_margin('box', box) == pytest.approx(0.01)
    assert attach_margin('cylinder', (0.05, 0.01)) == 1e-3        # 1 mm for a small body


def test_box_attach_point_outside_is_refused_with_its_rule():
    message = _error(_edited('box_lift', lambda d: d['payload']['attach_points'].__setitem__(
        0, [2.5, 0.3, 0.2])))
    assert 'payload.attach_points[0]: [2.5, 0.3, 0.2] must lie on or inside the box' in message
    assert '|x| <= 0.5' in message and '2 m outside' in message


def test_attach_point_within_the_margin_loads_and_beyond_it_does_not():
    inside = _edited('box_lift', lambda d: d['payload']['attach_points'].__setitem__(
        0, [0.509, 0.3, 0.2]))     # 9 mm beyond the 1.0 m box's end: within 1 %
    assert scenario_io.loads(inside).payload.attach_points[0][0] == 0.509
    message = _error(_edited('box_lift', lambda d: d['payload']['attach_points'].__setitem__(
        0, [0.52, 0.3, 0.2])))
    assert 'attach_points[0]' in message and 'within 0.01 m' in message


def test_cylinder_attach_point_off_its_surface_is_refused():
    message = _error(_edited('beam_lift', lambda d: d['payload']['attach_points'].__setitem__(
        1, [-1.5, 0.0, 0.5])))
    assert 'payload.attach_points[1]: [-1.5, 0.0, 0.5]' in message
    assert 'the cylinder |x| <= 1.5, sqrt(y^2 + z^2) <= 0.03' in message


def test_a_mission_segment_faster_than_the_cap_is_refused():
    message = _error(_edited('twin_lift', lambda d: d['mission']['segments'][1].update(
        velocity=[1e12, 0.0, 0.0])))
    assert 'mission.segments[1].velocity: [1000000000000.0, 0.0, 0.0]' in message
    assert f'at most {MAX_MISSION_SPEED:g} m/s' in message
    # raw steps (no filter) are checked for speed too
    message = _error(_edited('single_lift', lambda d: d['mission']['segments'][0].update(
        velocity=[0.0, 0.0, 25.0])))
    assert 'mission.segments[0].velocity' in message and 'got 25 m/s' in message


def test_the_acceleration_bound_is_the_tilt_limit_or_the_thrust_margin():
    s = scenario_io.load('twin_lift')
    g = s.simulation.gravity
    # the twin-lift's 25 deg tilt limit binds: g tan 25 deg = 4.57 < 5.27 m/s^2 of thrust margin
    thrust_margin = g * math.sqrt(((2 * 4 * 1.83e-6 * 2100.0 ** 2) / ((2 * 2.5 + 0.8) * g)) ** 2
                                  - 1)
    assert thrust_margin == pytest.approx(5.27, abs=0.01)
    assert max_mission_acceleration(s) == pytest.approx(g * math.tan(math.radians(25.0)),
                                                        rel=1e-12)
    # a payload of 1.5 kg leaves T/W = 64.6 / 63.8 N: the thrust margin binds (1.52 m/s^2)
    heavy = scenario_io.loads(_edited('twin_lift', lambda d: d['payload'].update(mass=1.5)))
    ratio = (2 * 4 * 1.83e-6 * 2100.0 ** 2) / ((2 * 2.5 + 1.5) * g)
    assert max_mission_acceleration(heavy) == pytest.approx(g * math.sqrt(ratio ** 2 - 1),
                                                            rel=1e-12)
    assert max_mission_acceleration(heavy) < g * math.tan(math.radians(25.0))


def _quick(v):
    def edit(d):
        d['mission']['reference_filter_time'] = 0.1
        d['mission']['segments'][1]['velocity'] = [v, 0.0, 0.0]
    return edit


def test_a_corner_beyond_the_formation_s_margin_is_refused():
    s = scenario_io.load('twin_lift')
    limit = max_mission_acceleration(s)
    tau = 0.1
    fast = limit * math.e * tau * 1.05  # the step from rest asks 5 % too much
    message = _error(_edited('twin_lift', _quick(fast)))
    assert 'mission.segments[1].velocity' in message
    assert 'more than the formation can fly: 4.57 m/s^2' in message
    assert 'sqrt((T/W)^2 - 1)' in message
    slow = limit * math.e * tau * 0.95 / 2  # its corners (from -0.5 in z, to -0.5 in y) pass
    assert scenario_io.loads(_edited('twin_lift', _quick(slow))).mission.segments[1] \
        .velocity[0] == slow


def test_multilift_run_exits_2_with_one_line(tmp_path, capsys):
    path = tmp_path / 'bad_box.yaml'
    path.write_text(_edited('box_lift', lambda d: d['payload']['attach_points'].__setitem__(
        0, [2.5, 0.3, 0.2])))
    assert cli.main(['run', str(path), '--headless']) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f'error: {path}: payload.attach_points[0]: [2.5, 0.3, 0.2]')
