"""Mission sources (issue 34 item 1): `mission.type` waypoints (minimum snap) and file (a clamped
cubic spline) checked against what they must be, not against the code's own numbers: the
trajectory passes through its points, its derivatives are continuous at the knots (to jerk and
beyond), the two-waypoint case is the textbook rest-to-rest minimum-snap polynomial
p0 + (p1 - p0)(35 s^4 - 84 s^5 + 70 s^6 - 20 s^7), a general case equals the minimum of the QP
solved another way (its KKT system over the snap's Gram matrix), and the compiled reference of
the tick evaluates what the scenario read. Bad input is one line naming the key."""
from __future__ import annotations

from math import factorial

import numpy as np
import pytest
import yaml

from multilift_control import laws
from multilift_control.laws.layout import (REFERENCE_ACCELERATION, REFERENCE_POSITION,
                                           REFERENCE_SIZE, REFERENCE_VELOCITY, REFERENCE_YAW)
from multilift_control.laws.reference import mission_reference
from multilift_control.controllers import LeaderController
from multilift_sim import scenario as scenario_io
from multilift_sim.missions import MISSION_SOURCES
from multilift_sim.missions.polynomials import evaluate, minimum_snap
from multilift_sim.scenario import ScenarioError

WAYPOINTS = [{'time': 0.0, 'position': [0.0, 0.0, 0.0]},
             {'time': 4.0, 'position': [1.0, 0.5, 0.5], 'yaw': 0.3},
             {'time': 8.0, 'position': [2.0, 0.0, 0.5]},
             {'time': 10.0, 'position': [2.0, -0.5, 0.2], 'yaw': -0.2}]


def _scenario_data(mission: dict) -> dict:
    from multilift_sim.scenario.files import scenario_dir
    data = yaml.safe_load((scenario_dir() / 'single_lift.yaml').read_text())
    data['simulation']['duration'] = 12.0
    data['mission'] = mission
    return data


def _load(mission: dict, where: str = '<string>'):
    return scenario_io.loads(yaml.safe_dump(_scenario_data(mission)), where)


def _reference(scenario):
    path = LeaderController(scenario).path  # the leader's path (mission.tracks applied)
    law = laws.runnable(mission_reference)
    return lambda t: law(path.mission, path.segments, path.steps, float(t))


def test_the_shipped_sources_are_registered_and_segments_is_the_default():
    assert list(MISSION_SOURCES)[:3] == ['segments', 'waypoints', 'file']
    assert scenario_io.load('single_lift').mission.type == 'segments'


def test_waypoints_pass_through_their_points_and_yaws_and_hold_at_the_ends():
    scenario = _load({'type': 'waypoints', 'waypoints': WAYPOINTS})
    reference = _reference(scenario)
    yaws = [0.0, 0.3, 0.3, -0.2]  # a waypoint without yaw keeps the previous one's
    for waypoint, yaw in zip(WAYPOINTS, yaws):
        at = reference(waypoint['time'])
        assert np.abs(at[REFERENCE_POSITION:REFERENCE_POSITION + 3]
                      - waypoint['position']).max() < 1e-9
        assert at[REFERENCE_YAW] == pytest.approx(yaw, abs=1e-9)
    for t, end in ((-1.0, WAYPOINTS[0]), (11.0, WAYPOINTS[-1])):  # held, at rest
        at = reference(t)
        assert np.abs(at[REFERENCE_POSITION:REFERENCE_POSITION + 3] - end['position']).max() \
            < 1e-9
        assert not at[REFERENCE_VELOCITY:REFERENCE_ACCELERATION + 3].any()


def test_minimum_snap_is_continuous_to_the_sixth_derivative_at_the_knots():
    times = np.array([w['time'] for w in WAYPOINTS])
    points = np.array([w['position'] for w in WAYPOINTS])
    coefficients = minimum_snap(times, points)
    scale = np.abs(points).max()
    for t in times[1:-1]:
        for order in range(7):  # position .. d^6/dt^6: the optimum's continuity
            before = evaluate(times, coefficients, t - 1e-9, order)
            after = evaluate(times, coefficients, t + 1e-9, order)
            assert np.abs(after - before).max() < 1e-6 * scale * 10 ** order, (t, order)
        jump = evaluate(times, coefficients, t + 1e-9, 7) - evaluate(times, coefficients,
                                                                      t - 1e-9, 7)
        assert np.abs(jump).max() > 1e-3  # the seventh jumps: the test can tell
    for t in (times[0], times[-1]):  # at rest: velocity, acceleration, jerk 0
        inside = t + (1e-12 if t == times[0] else -1e-12)
        for order in (1, 2, 3):
            assert np.abs(evaluate(times, coefficients, inside, order)).max() < 1e-8


def test_two_waypoints_give_the_rest_to_rest_minimum_snap_polynomial():
    p0, p1, duration = np.array([0.5, -1.0, 2.0]), np.array([2.5, 1.0, 1.0]), 3.0
    scenario = _load({'type': 'waypoints', 'waypoints': [
        {'time': 1.0, 'position': p0.tolist()},
        {'time': 1.0 + duration, 'position': p1.tolist()}]})
    reference = _reference(scenario)
    for s in np.linspace(0.0, 1.0, 23):
        shape = 35 * s ** 4 - 84 * s ** 5 + 70 * s ** 6 - 20 * s ** 7
        rate = (140 * s ** 3 - 420 * s ** 4 + 420 * s ** 5 - 140 * s ** 6) / duration
        bend = (420 * s ** 2 - 1680 * s ** 3 + 2100 * s ** 4 - 840 * s ** 5) / duration ** 2
        at = reference(1.0 + s * duration)
        assert np.abs(at[REFERENCE_POSITION:REFERENCE_POSITION + 3]
                      - (p0 + (p1 - p0) * shape)).max() < 1e-12 * 10
        assert np.abs(at[REFERENCE_VELOCITY:REFERENCE_VELOCITY + 3]
                      - (p1 - p0) * rate).max() < 1e-10
        assert np.abs(at[REFERENCE_ACCELERATION:REFERENCE_ACCELERATION + 3]
                      - (p1 - p0) * bend).max() < 1e-9


def _snap_gram(duration: float) -> np.ndarray:
    """Q with c^T Q c = integral_0^T (d^4 p / dt^4)^2 dt, p = sum_j c_j t^j, j < 8."""
    gram = np.zeros((8, 8))
    for i in range(4, 8):
        for j in range(4, 8):
            a = factorial(i) / factorial(i - 4) * factorial(j) / factorial(j - 4)
            gram[i, j] = a * duration ** (i + j - 7) / (i + j - 7)
    return gram


def test_minimum_snap_equals_the_qp_solved_through_its_kkt_system():
    """The QP of Mellinger & Kumar: minimise the sum of the pieces' snap integrals subject to
    the waypoints, rest at the ends and continuity of velocity .. jerk at interior points only,
    solved by its KKT system: the closed form (continuity to d^6 imposed) is its optimum."""
    times = np.array([0.0, 1.5, 4.0, 5.0, 7.5])
    values = np.array([0.0, 1.0, -0.5, 0.2, 2.0])
    m = len(times) - 1
    durations = np.diff(times)

    def row(order, t):
        out = np.zeros(8)
        for j in range(order, 8):
            out[j] = factorial(j) / factorial(j - order) * t ** (j - order)
        return out

    hessian = np.zeros((8 * m, 8 * m))
    constraints, right = [], []
    for k in range(m):
        block = slice(8 * k, 8 * k + 8)
        hessian[block, block] = _snap_gram(durations[k])
        for t, value in ((0.0, values[k]), (durations[k], values[k + 1])):
            a = np.zeros(8 * m)
            a[block] = row(0, t)
            constraints.append(a)
            right.append(value)
    for order in (1, 2, 3):
        a = np.zeros(8 * m)
        a[:8] = row(order, 0.0)
        constraints.append(a)
        right.append(0.0)
        a = np.zeros(8 * m)
        a[8 * (m - 1):] = row(order, durations[-1])
        constraints.append(a)
        right.append(0.0)
        for k in range(m - 1):
            a = np.zeros(8 * m)
            a[8 * k:8 * k + 8] = row(order, durations[k])
            a[8 * k + 8:8 * k + 16] = -row(order, 0.0)
            constraints.append(a)
            right.append(0.0)
    a = np.array(constraints)
    kkt = np.block([[2 * hessian, a.T], [a, np.zeros((len(a), len(a)))]])
    solution = np.linalg.lstsq(kkt, np.r_[np.zeros(8 * m), right], rcond=None)[0][:8 * m]
    ours = minimum_snap(times, values[:, None])[:, 0, :].ravel()
    assert np.abs(ours - solution).max() < 1e-6 * np.abs(solution).max()
    cost = lambda c: c @ hessian @ c  # noqa: E731
    assert cost(ours) == pytest.approx(cost(solution), rel=1e-9)


def test_a_file_mission_is_a_clamped_cubic_spline_through_its_rows(tmp_path):
    rows = [(0.0, 0.0, 0.0, 1.0), (2.0, 1.0, 0.0, 1.0), (3.5, 1.0, 1.0, 1.5), (6.0, 0.0, 1.0, 1.0)]
    (tmp_path / 'path.csv').write_text(
        't,x,y,z\n' + ''.join(','.join(f'{v:g}' for v in r) + '\n' for r in rows))
    where = tmp_path / 'scenario.yaml'
    where.write_text('')
    scenario = _load({'type': 'file', 'file': 'path.csv'}, str(where))
    reference = _reference(scenario)
    for t, *position in rows:
        assert np.abs(reference(t)[REFERENCE_POSITION:REFERENCE_POSITION + 3]
                      - position).max() < 1e-12
    for t, *_ in rows[1:-1]:  # position, velocity, acceleration continuous at the rows
        before, after = reference(t - 1e-9), reference(t + 1e-9)
        assert np.abs(after[:REFERENCE_ACCELERATION + 3]
                      - before[:REFERENCE_ACCELERATION + 3]).max() < 1e-6
    start = reference(1e-12)  # clamped: at rest at both ends
    assert np.abs(start[REFERENCE_VELOCITY:REFERENCE_VELOCITY + 3]).max() < 1e-9
    assert reference(3.0)[REFERENCE_YAW] == 0.0  # no yaw column: heading 0


@pytest.mark.parametrize('text, rule', [
    ('t,x,y\n0,0,0\n1,1,1\n', "lacks the column 'z'"),
    ('t,x,y,z\n0,0,0,0\n2,1,1,1\n1,2,2,2\n', r'row 4: time 1 s must be > the previous'),
    ('t,x,y,z\n0,0,0,0\n', 'has 1 rows of data, at least 2'),
    ('t,x,y,z\n0,0,0,0\n1,a,1,1\n', 'row 3'),
])
def test_a_bad_mission_file_is_one_line_naming_the_key(tmp_path, text, rule):
    (tmp_path / 'bad.csv').write_text(text)
    where = tmp_path / 'scenario.yaml'
    where.write_text('')
    with pytest.raises(ScenarioError, match=rf'mission\.file: .*{rule}') as error:
        _load({'type': 'file', 'file': 'bad.csv'}, str(where))
    assert '\n' not in str(error.value)


@pytest.mark.parametrize('waypoints, rule', [
    (WAYPOINTS[:1], r'mission\.waypoints: .* must list at least 2 waypoints'),
    ([WAYPOINTS[0], WAYPOINTS[2], WAYPOINTS[1]],
     r"mission\.waypoints\[2\]\.time: 4\.0 must be > the previous waypoint's time \(8 s\)"),
    ([WAYPOINTS[0], {'time': 3.0}], r'mission\.waypoints\[1\]\.position: missing key'),
])
def test_bad_waypoints_are_one_line_naming_the_key(waypoints, rule):
    with pytest.raises(ScenarioError, match=rule) as error:
        _load({'type': 'waypoints', 'waypoints': waypoints})
    assert '\n' not in str(error.value)


def test_an_unknown_type_names_the_registered_ones():
    with pytest.raises(ScenarioError, match=r'mission\.type: .* must be one of segments, '
                                            r'waypoints, file'):
        _load({'type': 'spline'})


def test_the_reference_before_its_size_grew_is_the_same_for_segments():
    """The seed's segments leave REFERENCE_YAW 0 (the leader's heading as before)."""
    reference = _reference(scenario_io.load('single_lift'))
    assert all(reference(t)[REFERENCE_YAW] == 0.0 for t in (0.0, 12.0, 50.0, 130.0))
    assert reference(0.0).shape == (REFERENCE_SIZE,)


def test_tracks_payload_brings_the_payload_to_the_waypoints():
    """`mission.tracks: payload`: the waypoints are the payload's; the leader flies them moved
    up by its cable (one UAV: the payload hangs straight below at rest), so once the swing has
    died down the payload rests on the last waypoint, as the statics says."""
    from multilift_control.headless import run_headless
    waypoints = [{'time': 0.0, 'position': [0.0, 0.0, -2.5]},
                 {'time': 5.0, 'position': [1.0, 0.5, -2.0]},
                 {'time': 10.0, 'position': [2.0, 0.0, -2.0]}]
    data = _scenario_data({'type': 'waypoints', 'tracks': 'payload', 'waypoints': waypoints})
    data['simulation']['duration'] = 25.0
    scenario = scenario_io.loads(yaml.safe_dump(data))
    reference = _reference(scenario)
    assert np.abs(reference(0.0)[:3] - (0.0, 0.0, 0.0)).max() < 1e-12  # the leader's start
    payload, times = [], []
    run_headless(scenario, on_tick=lambda sim, snapshot, _: (
        payload.append(np.array(snapshot.payload_position)), times.append(sim.t_ns * 1e-9)))
    payload, times = np.array(payload), np.array(times)
    for waypoint in waypoints:
        k = int(np.argmin(np.abs(times - waypoint['time'])))
        assert np.linalg.norm(payload[k] - waypoint['position']) < 0.15
    assert np.linalg.norm(payload[-1] - waypoints[-1]['position']) < 0.005


def test_tracks_payload_with_segments_needs_the_payload_s_start():
    with pytest.raises(ScenarioError, match=r'mission\.start: missing key \(with mission\.'
                                            r'tracks: payload'):
        _load({'tracks': 'payload', 'segments': [{'velocity': [0.1, 0, 0], 'duration': 5.0}]})


def test_a_vehicle_preset_fills_the_keys_not_given_and_a_key_given_overrides():
    import math
    data = _scenario_data({'type': 'waypoints', 'waypoints': WAYPOINTS})
    data['vehicle'] = {'preset': 'crazyflie_2_1'}
    data['payload']['mass'] = 0.01
    data['uavs'][0]['cable_length'] = 0.5
    vehicle = scenario_io.loads(yaml.safe_dump(data)).uavs[0].vehicle
    # Förster 2015's C_T = 3.1582e-10 N/rpm^2 per (rad/s)^2, the datasheet's 27 g and 46 mm
    assert vehicle.mass == 0.027 and vehicle.arm_length == 0.046
    assert vehicle.thrust_coefficient == pytest.approx(3.1582e-10 * (60 / (2 * math.pi)) ** 2)
    assert vehicle.rotor_speed_max == pytest.approx(21666.4475 * 2 * math.pi / 60, rel=1e-9)
    data['vehicle']['mass'] = 0.030
    assert scenario_io.loads(yaml.safe_dump(data)).uavs[0].vehicle.mass == 0.030
    data['vehicle'] = {'preset': 'table_4_2'}  # the seed's, as the shipped scenarios write it
    data['payload']['mass'] = 0.4
    data['uavs'][0]['cable_length'] = 2.5
    assert scenario_io.loads(yaml.safe_dump(data)).uavs[0].vehicle == \
        scenario_io.load('single_lift').uavs[0].vehicle
    data['vehicle'] = {'preset': 'crazyflie_3'}
    with pytest.raises(ScenarioError, match=r'vehicle\.preset: .* must be one of table_4_2, '
                                            r'crazyflie_2_1'):
        scenario_io.loads(yaml.safe_dump(data))


def test_a_learning_hover_of_a_waypoints_scenario_hovers_at_the_leader_s_start():
    """The hover task replaces the mission by one held segment at the leader's start, whatever
    the scenario's source (a waypoints mission would otherwise still be flown)."""
    from multilift_learning.tasks import task_scenario, task_scenario_yaml
    scenario = _load({'type': 'waypoints', 'waypoints': WAYPOINTS[1:]})
    hover = task_scenario(scenario, 'hover')
    assert hover.mission.type == 'segments' and hover.mission.knots == ()
    reference = _reference(hover)
    for t in (0.0, 5.0, 11.0):
        assert np.array_equal(reference(t)[:3], scenario.uavs[0].position)
    assert task_scenario(scenario_io.load('single_lift'), 'hover').mission.start == \
        scenario_io.load('single_lift').mission.start
    assert 'segments' in yaml.safe_load(task_scenario_yaml('cf2_payload', 'hover'))['mission']


def test_a_copy_validated_elsewhere_reads_the_file_beside_its_scenario(tmp_path):
    """A sweep validates each run's copy of the scenario's mapping from elsewhere
    (`scenario.anchored`): `mission.file` is made absolute against the scenario's folder."""
    (tmp_path / 'path.csv').write_text('t,x,y,z\n0,0,0,0\n2,1,0,0\n')
    data = scenario_io.anchored(_scenario_data({'type': 'file', 'file': 'path.csv'}), tmp_path)
    assert data['mission']['file'] == str((tmp_path / 'path.csv').resolve())
    scenario = scenario_io.loads(yaml.safe_dump(data))  # validated from the working directory
    assert scenario.mission.knots == (0.0, 2.0)
