"""The reorganising formation (issue 35 item 2, `formation.reorganize: thrust_margin`,
multilift_control.laws.reorganize): its statics against triangles worked out by hand and
against the equilibrium of Eq. 2.73 (analysis.loads), its step within its limits, its laws
compiled against uncompiled, its keys' bad input, and v3_mixed flown both ways."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.controllers.followers import thrust_margin
from multilift_control.controllers import formation_rows
from multilift_control.headless import fly
from multilift_control.laws import cable_forces as allocation
from multilift_control.laws import reorganize as laws
from multilift_control.laws.layout import (REORGANIZE_ACCELERATION, REORGANIZE_MAX_RATE,
                                           REORGANIZE_SHIFT)
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.loads import hover_loads
from multilift_sim.scenario import ScenarioError
from multilift_tools.loads_cli import loads_main
from test_compiled_laws import Checker

G = 9.81
HOVER = 10.0  # v3_mixed hovers this long [s] before multi_lift's mission


def _table_start(name='v3_mixed'):
    """The scenario `name` started at its geometry's places (Table 3.1), start_places left out."""
    s = scenario_io.load(name)
    return dataclasses.replace(s, formation=dataclasses.replace(s.formation, start_places=()))


def _triangle(corners, height=0.0):
    return np.array([[x, y, height] for x, y in corners], dtype=float)


def test_an_equilateral_v_shares_its_payload_evenly():
    side, length, m_p = 4.0, 10.26, 0.8
    radius = side / math.sqrt(3.0)  # circumradius
    places = _triangle([(0.0, 0.0), (-side * math.sqrt(3) / 2, side / 2),
                        (-side * math.sqrt(3) / 2, -side / 2)])
    lengths = np.full(3, length)
    payload, found = laws.hang_point(places, lengths, np.array([0.0, 0.0, -1.0]))
    depth = math.sqrt(length ** 2 - radius ** 2)
    assert found
    np.testing.assert_allclose(payload, places.mean(axis=0) - [0.0, 0.0, depth], atol=1e-9)
    tensions, _ = laws.cable_tensions(places, lengths, payload, np.array([0.0, 0.0, m_p * G]))
    np.testing.assert_allclose(tensions, m_p * G * length / (3.0 * depth), rtol=1e-9)


def test_a_triangle_s_tensions_are_its_circumcentre_s_weights():
    """Level UAVs on equal cables: the payload hangs below the circumcentre, every cable at the
    same angle, so the horizontal balance sum T_i (A_i - O) = 0 makes T_i proportional to
    sin 2 A_i (the circumcentre's barycentric coordinates), A_i the triangle's angle at UAV i;
    a right angle at UAV 3 leaves its cable nothing."""
    for corners in ([(0.0, 0.0), (-3.5, 2.2), (-2.9, -1.2)], [(0.0, 0.0), (-4.0, 0.0),
                                                              (-2.0, -2.0)]):
        places = _triangle(corners, 5.0)
        payload, found = laws.hang_point(places, np.full(3, 10.26), np.array([0.0, 0.0, -1.0]))
        tensions, _ = laws.cable_tensions(places, np.full(3, 10.26), payload,
                                          np.array([0.0, 0.0, 0.8 * G]))
        angles = []
        for i in range(3):
            a, b = places[(i + 1) % 3, :2] - places[i, :2], places[(i + 2) % 3, :2] - places[i, :2]
            angles.append(math.acos(a @ b / np.linalg.norm(a) / np.linalg.norm(b)))
        weights = np.sin(2.0 * np.array(angles))
        assert found
        np.testing.assert_allclose(tensions / tensions.sum(), weights / weights.sum(),
                                   atol=1e-9)
    assert tensions[2] == pytest.approx(0.0, abs=1e-9)  # the right angle's


def test_the_static_margins_are_the_equilibrium_s_of_eq_2_73():
    s = _table_start()
    constants, memory, _, _ = thrust_margin.arrays(s, 1)
    _, constraints = formation_rows(s)
    places = constraints.nominal_positions(np.zeros(3))
    margins = laws.static_margins(constants, places, np.array([0.0, 0.0, G]))
    np.testing.assert_allclose(margins, hover_loads(s).margins, atol=1e-9)


def test_a_step_keeps_its_rate_spacing_and_spread_and_evens_the_margins():
    s = _table_start()
    f = s.formation
    masses, constraints = formation_rows(s)
    constants, memory, _, _ = thrust_margin.arrays(s, 2)
    rows, targets, n = constraints.rows, constraints.targets, s.n_uavs
    hover = masses[:, None] * np.array([0.0, 0.0, G])  # the lifts at hover [N]
    m = len(targets)
    start = laws.target_places(rows, targets, np.zeros(m), n)
    before = laws.static_margins(constants, start, np.array([0.0, 0.0, G]))
    places, dt = start, 0.01
    for tick in range(3000):
        laws.reorganize(constants, memory, tick * dt, masses, rows, targets, hover)
        memory[1] = tick * dt  # FOLLOWER_LAST_T, which follower_update advances
        moved = laws.target_places(rows, targets, memory[REORGANIZE_SHIFT:REORGANIZE_SHIFT + m],
                                   n)
        step = np.linalg.norm(moved[:, :2] - places[:, :2], axis=1)
        assert step.max() <= constants[REORGANIZE_MAX_RATE] * dt * (1 + 1e-9)
        gaps = [np.linalg.norm(moved[i, :2] - moved[j, :2]) for i in range(n)
                for j in range(i + 1, n)]
        assert f.min_spacing <= min(gaps) and max(gaps) <= f.max_spread
        places = moved
    np.testing.assert_allclose(memory[REORGANIZE_ACCELERATION:REORGANIZE_ACCELERATION + 3], 0.0,
                               atol=1e-12)
    after = laws.static_margins(constants, places, np.array([0.0, 0.0, G]))
    assert before[2] < 0.01 and after[2] > 0.05  # the weak UAV 3 got thrust back
    assert np.ptp(after) < 0.5 * np.ptp(before)
    assert after.min() >= f.thrust_margin_floor


def test_every_reorganising_law_compiled_equals_its_uncompiled_run():
    check = Checker()
    s = scenario_io.load('v3_mixed')
    masses, constraints = formation_rows(s)
    constants, memory, _, _ = thrust_margin.arrays(s, 1)
    rng = np.random.default_rng(3)
    places = constraints.nominal_positions(np.zeros(3))
    effective = np.array([0.3, -0.2, G])
    check(laws.hang_point, places, np.full(3, 10.26), np.array([0.0, 0.0, -1.0]))
    payload, _ = laws.hang_point(places, np.full(3, 10.26), np.array([0.0, 0.0, -1.0]))
    check(laws.cable_tensions, places, np.full(3, 10.26), payload, np.array([0.1, 0.0, 7.8]))
    check(laws.static_margins, constants, places, effective)
    check(laws.margin_cost, np.array([0.1, 0.12, 0.02]), 0.05)
    check(laws.target_places, constraints.rows, constraints.targets, np.zeros(6), 3)
    check(laws.within_limits, places, 2.0, 8.0)

    def steps(step):  # a few ticks of `step` compiled against uncompiled, its memory advancing
        for tick in range(5):
            lifts = masses[:, None] * (np.array([0.0, 0.0, G])
                                       + rng.normal(scale=0.5, size=(3, 3)))
            check(step, constants, memory, 0.01 * tick, masses, constraints.rows,
                  constraints.targets, lifts)
            step(constants, memory, 0.01 * tick, masses, constraints.rows, constraints.targets,
                 lifts)
            memory[1] = 0.01 * tick

    steps(laws.reorganize)
    check(laws._lowest, np.zeros(3), -math.inf, places[0] - [0, 0, 10.0],
          np.array([0.0, 0.0, -1.0]), places, np.full(3, 10.26))
    check(laws.filtered_gravity, constants, memory, 0.01, masses, masses[:, None] * [0, 0, G])
    check(laws._begin, constants, memory, 0.5, masses, constraints.rows, constraints.targets,
          masses[:, None] * [0, 0, G])
    check(laws._kept, constraints.rows, constraints.targets, np.zeros(6), constants,
          places + 0.01, 2, True)
    check(laws.statics_hold, constants, places, effective)
    statics = laws.hover_statics(constants, places)
    check(laws.hover_mass, constants, *statics, 2)
    check(laws.hover_statics, constants, places)
    check(laws.cable_statics, constants, places, effective)
    check(laws.static_pulls, constants, *statics, masses)
    check(allocation._uav, constants, 2, 1)
    check(allocation.share_bounds, constants, 3)
    check(allocation.load_shares, constants, effective, 3)
    check(allocation.balanced_directions, np.array([0.4, 0.35, 0.25]), np.array([0.0, 2.5, 4.0]))
    check(allocation.line_heights, constants, np.array([0.6, 0.4]), 4.0)
    check(allocation.upright, effective)
    check(allocation.level_places, constants, G, places)
    check(allocation.allocated_places, constants, effective, places)
    check(allocation.allocated_statics, constants, places)
    check(allocation.nearest_tensions, constants, places, effective)
    check(allocation.tensions_hold, constants, places, effective)
    steps(allocation.allocate)
    compiled = {f'{module.__name__}.{name}' for module in (laws, allocation)
                for name, value in vars(module).items()
                if hasattr(value, 'py_func') and value.__module__ == module.__name__}
    assert check.met == compiled


def _v3_mixed(tmp_path, **formation) -> str:
    data = yaml.safe_load((SCENARIOS / 'v3_mixed.yaml').read_text())
    if formation.get('reorganize') == 'none':  # a fixed V starts at its geometry's places
        del data['formation']['start_places']
    data['formation'].update(formation)
    path = tmp_path / 'v3_mixed_variant.yaml'
    path.write_text(yaml.safe_dump(data))
    return str(path)


@pytest.mark.parametrize('formation, rule', [
    ({'thrust_margin_floor': 1.5}, 'formation.thrust_margin_floor: 1.5 must be within [0, 1)'),
    ({'min_spacing': -1.0}, 'formation.min_spacing: -1.0 must be >= 0'),
    ({'max_spread': 1.0}, 'formation.max_spread: 1.0 must be >= formation.min_spacing'),
    ({'min_spacing': 5.0, 'max_spread': 9.0}, 'm apart, outside min_spacing 5 .. max_spread 9 m'),
    ({'reorganize': 'sometimes'}, 'formation.reorganize: \'sometimes\''),
])
def test_bad_reorganisation_keys_are_one_line(tmp_path, formation, rule):
    with pytest.raises(ScenarioError) as error:
        scenario_io.load(_v3_mixed(tmp_path, **formation))
    assert rule in str(error.value) and '\n' not in str(error.value)


@pytest.mark.parametrize('name,reorganize,rule', [
    ('circle3', 'thrust_margin', "moves linear or V offsets, not a 'circle'"),
    ('circle3', 'cable_forces', "moves linear or V offsets, not a 'circle'")])
def test_a_reorganisation_the_formation_cannot_take_is_refused(name, reorganize, rule):
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['formation']['reorganize'] = reorganize
    with pytest.raises(ScenarioError, match=rule):
        scenario_io.loads(yaml.safe_dump(data))


def test_a_formation_of_one_cannot_reorganise_and_the_command_says_so(tmp_path, capsys):
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['formation'] = {'geometry': 'v', 'distance': 4.0, 'half_angle_deg': 30.0,
                         'alpha_vc': 2.1, 'beta_vc': 1.3, 'reorganize': 'thrust_margin'}
    path = tmp_path / 'alone.yaml'
    path.write_text(yaml.safe_dump(data))
    assert loads_main([str(path)]) == 2
    err = capsys.readouterr().err
    assert err.strip().count('\n') == 0
    assert 'formation.reorganize: \'thrust_margin\' needs a formation of two UAVs' in err


def _flown(scenario, duration=None):
    if duration is not None:
        scenario = dataclasses.replace(
            scenario, simulation=dataclasses.replace(scenario.simulation, duration=duration))
    return fly(scenario).summary()


def test_v3_mixed_saturates_fixed_and_carries_its_load_reorganised(tmp_path):
    """After the hover in which it reorganises, the reorganising V saturates no rotor and
    tracks within the seed law's tracking on multi_lift plus 20 %; the fixed V of the same
    file saturates UAV 3 in the climb and the corners."""
    seed = _flown(scenario_io.load('multi_lift'))['leader']['max_tracking_error']
    fixed = scenario_io.load(_v3_mixed(tmp_path, reorganize='none'))
    assert fixed.control.follower == 'virtual_constraints'
    moving = scenario_io.load('v3_mixed')
    assert moving.control.follower == 'thrust_margin'
    for scenario, saturates in ((fixed, True), (moving, False)):
        whole = _flown(scenario)
        after = (whole['sim']['saturated_time'][2]
                 - _flown(scenario, HOVER)['sim']['saturated_time'][2])
        climbed = (_flown(scenario, HOVER + 10.0)['sim']['saturated_time'][2]
                   - _flown(scenario, HOVER)['sim']['saturated_time'][2])
        if saturates:
            assert after > 30.0 and climbed > 1.0
        else:  # started at rest at its hover places, the statics in its law: no rotor
            assert after == 0.0 and sum(whole['sim']['saturated_time']) == 0.0
            assert whole['sim']['least_thrust_margin'][2] > 0.045
            assert whole['leader']['max_tracking_error'] <= 1.2 * seed
            # no cable pushes: each keeps a third of its even share statically
            # (LEAST_TENSION_SHARE), of which the flight's dips take up to 0.7 N
            assert whole['sim']['min_tension'] > 0.1


def test_v3_mixed_flies_with_its_cables_allocated(tmp_path):
    """cable_forces on v3_mixed (issue 35 item 3's bar): the mission flown to its end, no
    rotor saturated (from the file's start places, the shares fed forward), tracking within
    the seed's on multi_lift plus 20 %, every cable pulling, and UAV 3's least thrust margin
    over the run at least the reorganising formation's (the same file flown with
    `thrust_margin`) and at least 4.9 %: the allocation solves the shares directly."""
    seed = _flown(scenario_io.load('multi_lift'))['leader']['max_tracking_error']
    allocated = scenario_io.load(_v3_mixed(tmp_path, reorganize='cable_forces'))
    assert allocated.control.follower == 'cable_forces'
    whole = _flown(allocated)
    gradient = _flown(scenario_io.load('v3_mixed'))['sim']['least_thrust_margin']
    assert sum(whole['sim']['saturated_time']) == 0.0  # no rotor, no UAV
    assert whole['leader']['max_tracking_error'] <= 1.2 * seed
    assert whole['sim']['min_tension'] > 0.1
    least = whole['sim']['least_thrust_margin']
    assert min(least) >= min(gradient) and least[2] >= gradient[2] and least[2] >= 0.049


def test_the_hover_feedforward_is_the_statics_share_of_the_geometry_flown():
    """`hover_mass`: the equilateral V's even share m + m_p / 3; a triangle's m + m_p w_i, w_i
    its circumcentre's barycentric weight (sin 2 A_i / sum sin 2 A_j, the cables' equal slope
    cancelling); the shares sum to the payload."""
    s = _table_start()
    constants, _, _, _ = thrust_margin.arrays(s, 1)
    m, m_p = s.uavs[0].vehicle.mass, s.payload.mass
    v = _triangle([(0.0, 0.0), (-2.0 * math.sqrt(3.0), 2.0), (-2.0 * math.sqrt(3.0), -2.0)])
    for i in range(3):
        assert laws.hover_mass(constants, *laws.hover_statics(constants, v), i) \
            == pytest.approx(m + m_p / 3.0, rel=1e-9)
    corners = [(0.0, 0.0), (-4.187, 1.89), (-3.127, -1.344)]
    places = _triangle(corners)
    angles = []
    for i in range(3):
        a, b = places[(i + 1) % 3, :2] - places[i, :2], places[(i + 2) % 3, :2] - places[i, :2]
        angles.append(math.acos(a @ b / np.linalg.norm(a) / np.linalg.norm(b)))
    weights = np.sin(2.0 * np.array(angles))
    weights /= weights.sum()
    statics = laws.hover_statics(constants, places)
    shares = np.array([laws.hover_mass(constants, *statics, i) - m for i in range(3)])
    np.testing.assert_allclose(shares, m_p * weights, atol=1e-9)
    assert shares[2] < 0.7 * m_p / 3.0  # UAV 3 carries well under the even share


def test_v3_mixed_starts_at_the_hover_places_its_formation_moves_to():
    """start_places are the fixed point of the gradient's step at hover (to the file's 1 mm:
    rounded to 1 cm UAV 3's cable would carry less than the step keeps, and it would hold);
    the payload starts where it hangs at rest: every cable at its length, the least-norm
    tensions positive and carrying m_p g (Eq. 2.73's payload rows)."""
    s = scenario_io.load('v3_mixed')
    np.testing.assert_allclose(thrust_margin.hover_places(s), s.formation.start_places,
                               atol=0.001)
    from multilift_sim.start import formation_start
    uavs, payload = formation_start(s)
    np.testing.assert_allclose(uavs[1:, :2] - uavs[0, :2], s.formation.start_places)
    assert np.ptp(uavs[:, 2]) == 0.0
    spans = uavs - payload
    np.testing.assert_allclose(np.linalg.norm(spans, axis=1), 10.26, rtol=1e-9)
    units = spans / np.linalg.norm(spans, axis=1)[:, None]
    tensions = np.linalg.lstsq(units.T, [0.0, 0.0, s.payload.mass * G], rcond=None)[0]
    np.testing.assert_allclose(units.T @ tensions, [0.0, 0.0, s.payload.mass * G], atol=1e-9)
    assert tensions.min() > 0.0


@pytest.mark.parametrize('change, rule', [
    ({'formation': {'start_places': [[-4.0, 2.0]]}}, 'must list one [x, y] per follower (2)'),
    ({'formation': {'start_places': [[-4.0, 2.0, 0.0], [-3.0, -1.0, 0.0]]}},
     'must be a list of 2 numbers'),
    ({'formation': {'start_places': [[-1.0, 0.5], [-3.0, -1.0]]}}, 'outside min_spacing'),
    ({'formation': {'reorganize': 'none'}}, 'starts a reorganising formation'),
    ({'uavs': [{'attach_point': [0.0, 0.0, -0.1]}, {}, {'rotor_speed_max': 1930.0}]},
     'not cables held off the UAVs\' centres'),
])
def test_bad_start_places_are_one_line(change, rule):
    data = yaml.safe_load((SCENARIOS / 'v3_mixed.yaml').read_text())
    for key, value in change.items():
        if isinstance(value, dict):
            data[key].update(value)
        else:
            data[key] = value
    with pytest.raises(ScenarioError) as error:
        scenario_io.loads(yaml.safe_dump(data))
    assert rule in str(error.value) and '\n' not in str(error.value)


def test_cable_forces_refuses_a_rigid_body_in_one_line():
    data = yaml.safe_load((SCENARIOS / 'v3_mixed.yaml').read_text())
    data['formation']['reorganize'] = 'cable_forces'
    del data['formation']['start_places']
    data['uavs'][0]['attach_point'] = [0.0, 0.0, -0.1]  # a rigid body's it allocates: not so
    data['payload'] = {'type': 'rigid_body', 'mass': 0.8, 'shape': 'box',
                       'size': [1.0, 0.6, 0.4], 'drag_coefficient': 0.12,
                       'attach_points': [[0.5, 0.0, 0.2], [-0.5, 0.3, 0.2], [-0.5, -0.3, 0.2]]}
    with pytest.raises(ScenarioError) as error:
        scenario_io.loads(yaml.safe_dump(data))
    assert "allocates a point payload's cables or a rigid body's" in str(error.value)
    assert '\n' not in str(error.value)


def test_a_formation_started_at_its_places_starts_at_rest():
    """With start_places the formation starts at the static equilibrium of Eq. 2.73 and its
    controllers hold it (issue 35 item 1): each UAV tilted to carry its weight and its cable's
    pull (`start.start_equilibrium`), the leader's integral at the pull
    (`leaders.cascade.start_integral`), the followers' law counting the statics' pulls
    (`static_pulls`) and weights (`hover_mass`). Through 2 s of v3_mixed's hover no UAV moves
    0.1 mm nor turns 0.01 degree, and the rotors turn at the equilibrium's speeds (solved apart
    by `analysis.equilibrium`) but for the followers' first tick (their thrust book's even-share
    guess, 11 rad/s) and never saturate; the cables carry the equilibrium's tensions."""
    from multilift_control.headless import run_headless
    from multilift_sim.analysis.equilibrium import scenario_equilibrium
    s = scenario_io.load('v3_mixed')
    s = dataclasses.replace(s, simulation=dataclasses.replace(s.simulation, duration=2.0))
    equilibrium = scenario_equilibrium(s)
    speeds, positions, angles = [], [], []

    def on_tick(sim, snapshot, answers):
        positions.append([u.position.copy() for u in snapshot.uavs])
        angles.append([u.euler.copy() for u in snapshot.uavs])
        if answers:
            speeds.append([a.output.rotor_speeds.copy() for a in answers])
            assert not any(a.output.saturated.any() for a in answers)

    summary = run_headless(s, on_tick).summary()
    off = np.abs(np.array(speeds) - np.array(equilibrium.rotor_speeds)[None]).max(axis=2)
    assert off[:, 0].max() < 0.01 and off[1:].max() < 2.5 and off[20:].max() < 0.1
    assert np.abs(np.array(positions) - positions[0]).max() < 1e-4
    assert np.degrees(np.abs(np.array(angles) - angles[0]).max()) < 0.01
    assert np.degrees(np.abs(np.array(angles[0])[:, :2]).max()) > 0.5  # tilted, not level
    assert summary['sim']['min_tension'] == pytest.approx(equilibrium.tensions.min(), abs=1e-3)
    assert summary['sim']['max_tension'] == pytest.approx(equilibrium.tensions.max(), abs=1e-3)


def test_the_static_pulls_balance_the_payload():
    """`static_pulls`: T_j e_j - m_p g / n e_z. Even V: every vertical part zero and the
    horizontal ones T sin(theta) towards the UAVs (T = m_p g l / (3 sqrt(l^2 - R^2)), R the
    circumradius); any triangle: the payload's horizontal balance makes the pulls sum to zero,
    the vertical parts too (sum T_j e_j,z = m_p g)."""
    s = _table_start()
    masses, _ = formation_rows(s)
    constants, _, _, _ = thrust_margin.arrays(s, 1)
    side, length, m_p = 4.0, 10.26, s.payload.mass
    radius = side / math.sqrt(3.0)
    v = _triangle([(0.0, 0.0), (-2.0 * math.sqrt(3.0), 2.0), (-2.0 * math.sqrt(3.0), -2.0)])
    pulls = laws.static_pulls(constants, *laws.hover_statics(constants, v), masses)
    tension = m_p * G * length / (3.0 * math.sqrt(length ** 2 - radius ** 2))
    centre = v.mean(axis=0)
    for j in range(3):
        outward = (v[j, :2] - centre[:2]) / radius
        np.testing.assert_allclose(pulls[j, :2], tension * radius / length * outward, atol=1e-9)
    np.testing.assert_allclose(pulls[:, 2], 0.0, atol=1e-9)
    skewed = _triangle([(0.0, 0.0), (-4.143, 1.904), (-3.147, -1.389)])
    pulls = laws.static_pulls(constants, *laws.hover_statics(constants, skewed), masses)
    np.testing.assert_allclose(pulls.sum(axis=0), 0.0, atol=1e-9)
    assert abs(pulls[2, 2]) > 0.5  # UAV 3 carries well under its even share there


def test_a_reorganising_run_records_each_uav_s_thrust_margin(tmp_path):
    """Issue 35 item 6: /uav{i}/thrust_margin (a reorganising formation only): each UAV's
    1 - sum omega^2 / (N omega_max^2) of the rotor commands it sent (/uav{i}/rotor_cmd,
    recomputed here), whose least is the summary's least_thrust_margin; the Foxglove layout
    plots it; a fixed formation's bag and layout have none (its bag keeps its bits)."""
    from multilift_sim.topics import margin_topics, scenario_topics
    from multilift_tools.bagdata import load_run
    from multilift_tools.foxglove.layout import layout
    from multilift_tools.headless_bag import record_headless
    s = scenario_io.load('v3_mixed')
    s = dataclasses.replace(s, simulation=dataclasses.replace(s.simulation, duration=12.0))
    flown = record_headless(s, tmp_path / 'bag').summary()
    run = load_run(tmp_path / 'bag')
    for i, uav in enumerate(s.uavs, start=1):
        margin = run.topic(f'/uav{i}/thrust_margin')
        speeds = run.rotor_speeds(i)
        expected = 1.0 - (speeds ** 2).sum(axis=1) / (4 * uav.vehicle.rotor_speed_max ** 2)
        np.testing.assert_allclose(margin['data'][:len(expected)], expected, atol=1e-12)
        assert margin['data'].min() == pytest.approx(flown['sim']['least_thrust_margin'][i - 1],
                                                     abs=1e-12)
    assert 'Plot!margins' in layout(s)['configById']
    twin = scenario_io.load('twin_lift')
    assert not margin_topics(twin) and 'Plot!margins' not in layout(twin)['configById']
    assert not any(topic.endswith('thrust_margin') for topic, _ in scenario_topics(twin))
