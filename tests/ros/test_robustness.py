"""Robustness for unattended runs: the scenario loader under random valid and invalid values
(hypothesis), determinism headless and through ROS, isolation of runs on different ROS domains,
a non-finite rotor command, rotor saturation, SIGTERM (`multilift sweep`: test_sweep.py).

The ROS tests use ROS_DOMAIN_ID 12..17 (conftest.ros_env hands out 20..99) with discovery
limited to this machine."""
from __future__ import annotations

import math
import os
import signal
import subprocess
import time

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from conftest import ROOT, SCENARIOS, next_domain, raw_messages, wait_for, wait_until_simulated
from multilift_control.headless import run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.vehicles import SHIPPED as FRAME_TYPES
from multilift_sim.simulation import FormationSimulator, SimulationStopped

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
ROTORS = {'quad': 4, 'hexa': 6, 'octo': 8}
SETTINGS = settings(max_examples=150, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])


def _base(name: str) -> dict:
    return yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())


def _set(data: dict, key: str, value) -> None:
    """data[key] = value for a dotted key with [i] indices ('uavs[0].cable_length')."""
    node = data
    parts = key.replace('[', '.[').split('.')
    steps = [int(p[1:-1]) if p.startswith('[') else p for p in parts]
    for step in steps[:-1]:
        node = node[step]
    node[steps[-1]] = value


def _delete(data: dict, key: str) -> None:
    node = data
    parts = key.replace('[', '.[').split('.')
    steps = [int(p[1:-1]) if p.startswith('[') else p for p in parts]
    for step in steps[:-1]:
        node = node[step]
    del node[steps[-1]]


def _load(data: dict) -> scenario_io.Scenario:
    return scenario_io.loads(yaml.safe_dump(data), 'fuzz.yaml')


# --------------------------------------------------------------------------- value strategies
finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
positive = st.one_of(st.floats(min_value=1e-6, max_value=1e6), st.integers(1, 10 ** 6))
non_negative = st.one_of(st.floats(min_value=0.0, max_value=1e6), st.integers(0, 10 ** 6))
wrong_type = st.one_of(st.text(max_size=8), st.booleans(), st.none(),
                       st.lists(st.integers(), max_size=3), st.dictionaries(
                           st.sampled_from('abc'), st.integers(), max_size=2))
non_finite = st.sampled_from([math.nan, math.inf, -math.inf])

# single-field rules of scenarios/single_lift.yaml: key -> (valid values, invalid values)
NUMBER_RULES = {
    # at least one control period (0.01 s in single_lift.yaml)
    'simulation.duration': (st.floats(min_value=0.01, max_value=1e6),
                            st.floats(max_value=0.004)),
    'simulation.gravity': (st.floats(min_value=0.1, max_value=9.81), st.floats(max_value=0.0)),
    'simulation.baumgarte_alpha': (non_negative, st.floats(max_value=-1e-9)),
    'simulation.baumgarte_beta': (non_negative, st.floats(max_value=-1e-9)),
    'simulation.constraint_tolerance': (positive, st.floats(max_value=0.0)),
    'simulation.constraint_rate_tolerance': (positive, st.floats(max_value=0.0)),
    'simulation.command_timeout': (positive, st.floats(max_value=0.0)),
    'vehicle.arm_length': (positive, st.floats(max_value=0.0)),
    'vehicle.moment_coefficient': (positive, st.floats(max_value=0.0)),
    'uavs[0].cable_length': (positive, st.floats(max_value=0.0)),
    'uavs[0].yaw': (finite, st.nothing()),
    'payload.drag_coefficient': (non_negative, st.floats(max_value=-1e-9)),
    'payload.alpha_deg': (st.floats(min_value=-89.9, max_value=89.9),
                          st.one_of(st.floats(min_value=90.0), st.floats(max_value=-90.0))),
    'payload.beta_deg': (st.floats(min_value=-89.9, max_value=89.9),
                         st.one_of(st.floats(min_value=90.0), st.floats(max_value=-90.0))),
    'control.max_tilt_deg': (st.floats(min_value=0.1, max_value=89.9),
                             st.one_of(st.floats(min_value=90.0), st.floats(max_value=0.0))),
}
VECTOR_RULES = {  # key -> element rule for valid values (None: any finite), invalid element
    'vehicle.inertia': (st.floats(min_value=1e-4, max_value=1e3), st.floats(max_value=0.0)),
    'control.position_gains.kp': (non_negative, st.floats(max_value=-1e-9)),
    'control.position_gains.kd': (non_negative, st.floats(max_value=-1e-9)),
    'control.position_gains.ki': (non_negative, st.floats(max_value=-1e-9)),
    'control.attitude_gains.kp': (non_negative, st.floats(max_value=-1e-9)),
    'control.attitude_gains.kd': (non_negative, st.floats(max_value=-1e-9)),
    'uavs[0].position': (finite, st.nothing()),
    'mission.start': (finite, st.nothing()),
    # a speed of at most 20 m/s (scenario.limits.MAX_MISSION_SPEED): |v| <= sqrt(3) 11 valid,
    # one component beyond 20 m/s not
    'mission.segments[0].velocity': (st.floats(min_value=-11.0, max_value=11.0),
                                     st.one_of(st.floats(min_value=20.01, max_value=1e12),
                                               st.floats(min_value=-1e12, max_value=-20.01))),
}
CHOICE_RULES = {'vehicle.frame_type': FRAME_TYPES,
                'control.mode': tuple(scenario_io.leader_controllers())}
REQUIRED = ['name', 'simulation', 'simulation.duration', 'simulation.physics_rate',
            'simulation.control_rate', 'simulation.baumgarte_alpha',
            'simulation.baumgarte_beta', 'simulation.constraint_tolerance',
            'simulation.constraint_rate_tolerance', 'vehicle', 'vehicle.mass',
            'vehicle.inertia', 'vehicle.frame_type', 'vehicle.arm_length',
            'vehicle.thrust_coefficient', 'vehicle.moment_coefficient',
            'vehicle.rotor_speed_min', 'vehicle.rotor_speed_max', 'uavs[0].cable_length',
            'payload', 'payload.mass', 'control', 'control.mode', 'control.position_gains',
            'control.position_gains.kp', 'control.attitude_gains.kd', 'mission',
            'mission.segments[0].velocity']
SECTIONS = ['', 'simulation', 'vehicle', 'uavs[0]', 'payload', 'control',
            'control.position_gains', 'control.attitude_gains', 'mission',
            'mission.segments[0]']
MAPPINGS = ['simulation', 'vehicle', 'payload', 'control', 'control.position_gains', 'mission',
            'uavs[0]', 'mission.segments[1]']
LISTS = ['uavs', 'mission.segments', 'gusts']


def _get(data: dict, key: str):
    node = data
    for part in key.replace('[', '.[').split('.'):
        node = node[int(part[1:-1])] if part.startswith('[') else node[part]
    return node


@st.composite
def valid_edits(draw) -> list[tuple[str, object]]:
    keys = draw(st.lists(st.sampled_from(sorted(NUMBER_RULES) + sorted(VECTOR_RULES)
                                         + sorted(CHOICE_RULES)), unique=True, max_size=6))
    edits = []
    for key in keys:
        if key in NUMBER_RULES:
            edits.append((key, draw(NUMBER_RULES[key][0])))
        elif key in VECTOR_RULES:
            edits.append((key, draw(st.lists(VECTOR_RULES[key][0], min_size=3, max_size=3))))
        else:
            edits.append((key, draw(st.sampled_from(CHOICE_RULES[key]))))
    return edits


@st.composite
def invalid_edit(draw):
    """(key the message must name, function that breaks the data)."""
    kind = draw(st.sampled_from(['number', 'vector', 'choice', 'unknown', 'missing',
                                 'not_mapping', 'not_list']))
    if kind == 'number':
        key = draw(st.sampled_from(sorted(NUMBER_RULES)))
        value = draw(st.one_of(NUMBER_RULES[key][1], wrong_type, non_finite))
        return key, lambda d: _set(d, key, value)
    if kind == 'vector':
        key = draw(st.sampled_from(sorted(VECTOR_RULES)))
        good, bad = VECTOR_RULES[key]
        value = draw(st.one_of(
            st.lists(good, max_size=6).filter(lambda v: len(v) != 3),   # wrong length
            st.tuples(good, good, st.one_of(bad, wrong_type, non_finite)).map(list),
            wrong_type.filter(lambda v: not isinstance(v, list)), finite))
        return key, lambda d: _set(d, key, value)
    if kind == 'choice':
        key = draw(st.sampled_from(sorted(CHOICE_RULES)))
        value = draw(st.one_of(st.text(max_size=10).filter(lambda v: v not in CHOICE_RULES[key]),
                               st.integers(), st.none(), st.booleans()))
        return key, lambda d: _set(d, key, value)
    if kind == 'unknown':
        section = draw(st.sampled_from(SECTIONS))
        name = draw(st.from_regex(r'[a-z][a-z_]{0,10}', fullmatch=True))
        key = f'{section}.{name}' if section else name
        return key, lambda d: (_get(d, section) if section else d).setdefault(name, 1.0)
    if kind == 'missing':
        key = draw(st.sampled_from(REQUIRED))
        return key, lambda d: _delete(d, key)
    if kind == 'not_mapping':
        key = draw(st.sampled_from(MAPPINGS))
        value = draw(st.one_of(st.integers(), st.text(max_size=5),
                               st.lists(st.integers(), max_size=2)))
        return key, lambda d: _set(d, key, value)
    key = draw(st.sampled_from(LISTS))
    value = draw(st.one_of(st.integers(), st.text(min_size=1, max_size=5), st.floats(),
                           st.dictionaries(st.sampled_from('ab'), st.integers(), min_size=1)))
    return key, lambda d: _set(d, key, value)


# --------------------------------------------------------------------------- loader properties
@SETTINGS
@given(edits=valid_edits())
def test_random_valid_values_load_and_are_kept(edits):
    data = _base('single_lift')
    for key, value in edits:
        _set(data, key, value)
        if key == 'vehicle.inertia':  # no longer the seed's: the file must not claim it is
            data['vehicle'].pop('inertia_source', None)
    s = _load(data)
    for key, value in edits:
        if key.startswith('payload.') and key.endswith('_deg'):
            assert math.degrees(getattr(s.payload, key[8:-4])) == pytest.approx(value)
        elif key == 'control.max_tilt_deg':
            assert math.degrees(s.control.max_tilt) == pytest.approx(value)
        elif key == 'simulation.duration':
            assert s.simulation.duration == value
        elif key == 'vehicle.inertia':
            assert s.uavs[0].vehicle.inertia == tuple(float(v) for v in value)
        elif key == 'vehicle.frame_type':
            assert s.uavs[0].vehicle.frame_type == value
        elif key == 'uavs[0].cable_length':
            assert s.uavs[0].cable_length == value
        elif key == 'control.position_gains.kp':
            assert s.control.position_kp == tuple(float(v) for v in value)


@SETTINGS
@given(mass=st.floats(min_value=0.1, max_value=20.0), payload=st.floats(min_value=1e-3,
                                                                        max_value=20.0),
       k_t=st.floats(min_value=1e-7, max_value=1e-5), w_max=st.floats(min_value=100, max_value=5e3),
       frame=st.sampled_from(FRAME_TYPES), rates=st.tuples(st.floats(min_value=1.0,
                                                                     max_value=500.0),
                                                           st.integers(1, 20)))
def test_payload_feasibility_and_rates_follow_the_rules(mass, payload, k_t, w_max, frame, rates):
    """Cross-field rules: a payload the rotors cannot lift names payload.mass; a control rate
    dividing the physics rate loads."""
    data = _base('single_lift')
    data['vehicle'].update(mass=mass, thrust_coefficient=k_t, rotor_speed_max=w_max,
                           frame_type=frame)
    data['payload']['mass'] = payload
    control, steps = rates
    data['simulation'].update(control_rate=control, physics_rate=control * steps)
    lift = ROTORS[frame.split('_')[0]] * k_t * w_max ** 2
    weight = (mass + payload) * data['simulation']['gravity']
    assume(abs(weight - lift) > 1e-9 * lift)
    ratio = (control * steps) / control
    assume(abs(ratio - round(ratio)) <= 1e-9)
    if weight >= lift:
        with pytest.raises(scenario_io.ScenarioError, match=r'payload\.mass: .* too heavy'):
            _load(data)
    else:
        s = _load(data)
        assert s.simulation.physics_steps_per_tick == steps
        assert s.payload.mass == payload


@SETTINGS
@given(broken=invalid_edit())
def test_random_invalid_values_raise_scenario_error_naming_the_key(broken):
    key, edit = broken
    data = _base('single_lift')
    edit(data)
    try:
        _load(data)
    except scenario_io.ScenarioError as exc:
        message = str(exc)
    except Exception as exc:  # noqa: BLE001 - the property: nothing but ScenarioError
        pytest.fail(f'{key}: {type(exc).__name__}: {exc} (expected a ScenarioError)')
    else:
        pytest.fail(f'{key}: the broken scenario loaded')
    assert message.startswith('fuzz.yaml: ')
    assert '\n' not in message
    assert key in message, message


@SETTINGS
@given(n=st.integers(2, 6), geometry=st.sampled_from(['v', 'distance', 'circle']),
       distance=st.floats(min_value=0.5, max_value=30.0), cable=st.floats(min_value=0.5,
                                                                         max_value=60.0),
       half_angle=st.floats(min_value=1.0, max_value=89.0))
def test_formation_values_load_or_name_the_formation(n, geometry, distance, cable, half_angle):
    """Formation sizes and cable lengths: a formation loads or is one ScenarioError naming the
    formation (wider than its cables) -- never another exception."""
    data = _base('multi_lift')
    data['formation'].update(n=n, geometry=geometry, distance=distance)
    if geometry == 'v':
        data['formation']['half_angle_deg'] = half_angle
    else:
        del data['formation']['half_angle_deg']
    data['cable_length'] = cable
    if geometry == 'circle' and n < 3:
        with pytest.raises(scenario_io.ScenarioError, match='formation.geometry'):
            _load(data)
        return
    try:
        s = _load(data)
    except scenario_io.ScenarioError as exc:
        assert 'formation' in str(exc) and 'cable' in str(exc)
        return
    assert s.n_uavs == n and s.formation.geometry == geometry


# --------------------------------------------------------------------------- determinism
def _trajectory(scenario) -> np.ndarray:
    states = []
    # the ticks before t_max, each with the commands that answer it (none answers the last)
    run_headless(scenario, on_tick=lambda sim, snap, answers: answers and states.append(
        np.concatenate([sim.state, *[a.output.rotor_speeds for a in answers]])))
    return np.array(states)


@pytest.mark.parametrize('name', ['single_lift', 'twin_lift', 'multi_lift', 'circle3'])
def test_headless_runs_are_identical(name):
    text = (SCENARIOS / f'{name}.yaml').read_text()
    first = _trajectory(_short(scenario_io.loads(text), 4.0))
    second = _trajectory(_short(scenario_io.loads(text), 4.0))
    assert first.shape[0] == 400
    assert np.array_equal(first, second)  # bit for bit, rotor commands included


def _short(scenario, duration: float):
    from dataclasses import replace
    return replace(scenario, simulation=replace(scenario.simulation, duration=duration))


def _ros_env(domain: int) -> dict:
    return dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')


STATE_TOPICS = ['/uav1/odom', '/payload/odom', '/formation/state', '/uav1/rotor_cmd']


def test_ros_runs_give_byte_identical_state_messages(tmp_path):
    bags = []
    for k in range(2):
        bag = tmp_path / f'run{k}'
        out = subprocess.run([MULTILIFT, 'run', 'single_lift', '--duration', '3', '--bag',
                              str(bag)], capture_output=True, text=True, timeout=300,
                             env=_ros_env(12))
        assert out.returncode == 0, out.stderr
        bags.append(raw_messages(bag))
    for topic in STATE_TOPICS:
        # the states at the 301 ticks of [0, 3] s; commands for the 300 before t = 3 s
        assert len(bags[0][topic]) == (300 if topic.endswith('rotor_cmd') else 301), topic
        assert bags[0][topic] == bags[1][topic], topic  # CDR payloads, byte for byte


def test_two_runs_on_different_domains_do_not_see_each_other(tmp_path):
    runs = []
    domains = (next_domain(), next_domain())
    for domain, (name, n) in zip(domains, (('single_lift', 1), ('twin_lift', 2))):
        bag = tmp_path / name
        proc = subprocess.Popen([MULTILIFT, 'run', name, '--duration', '3', '--bag', str(bag)],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                env=_ros_env(domain))
        runs.append((proc, bag, n))
    for proc, bag, n in runs:
        _, err = proc.communicate(timeout=300)
        assert proc.returncode == 0, err
    for proc, bag, n in runs:
        data = raw_messages(bag)
        topics = ['/clock', '/payload/odom', '/formation/state'] + \
            [f'/uav{i}/{leaf}' for i in range(1, n + 1) for leaf in ('odom', 'rotor_cmd')]
        for topic in topics:
            expected = 300 if topic.endswith('rotor_cmd') else 301  # no command answers t_max
            assert len(data[topic]) == expected, (bag.name, topic, len(data[topic]))
        # a twin-lift's second UAV must not appear in the single-lift's bag
        assert ('/uav2/odom' in data) == (n == 2)


# --------------------------------------------------------------------------- failures
@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf])
def test_non_finite_rotor_command_stops_the_simulator_naming_the_uav(bad):
    sim = FormationSimulator(scenario_io.load('twin_lift'))
    speeds = [np.full(4, 1500.0), np.full(4, 1500.0)]
    flags = [np.zeros(4, bool)] * 2
    sim.advance(speeds, flags)
    before = sim.state.copy()
    speeds[1][2] = bad
    with pytest.raises(SimulationStopped) as err:
        sim.advance(speeds, flags)
    message = str(err.value)
    assert message.startswith('uav2: rotor command is not finite') and 't = 0.010 s' in message
    assert np.array_equal(sim.state, before) and sim.tick == 1  # nothing integrated


def test_nan_from_a_controller_stops_a_headless_run(monkeypatch):
    from multilift_control import controllers
    original = controllers.LeaderController.update

    def broken(self, t, state):
        out, ref = original(self, t, state)
        if t >= 0.5:
            out.rotor_speeds[0] = math.nan
        return out, ref
    monkeypatch.setattr(controllers.LeaderController, 'update', broken)
    with pytest.raises(SimulationStopped, match=r'uav1: rotor command is not finite .* '
                                                r'at t = 0\.500 s'):
        run_headless(scenario_io.load('single_lift'))


FAKE_LEADER = """
import sys, time
import rclpy
from multilift_msgs.msg import RotorCommand
from nav_msgs.msg import Odometry
from multilift_sim.ros.common import PUBLISHER_QOS, SUBSCRIBER_QOS
rclpy.init()
node = rclpy.create_node('fake_leader')
pub = node.create_publisher(RotorCommand, '/uav1/rotor_cmd', PUBLISHER_QOS)
def answer(msg):
    t = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
    cmd = RotorCommand()
    cmd.header.stamp = msg.header.stamp
    cmd.header.frame_id = 'uav1/base_link'
    cmd.angular_velocity = [float('nan') if t >= 0.5 else 1700.0, 1700.0, 1700.0, 1700.0]
    cmd.saturated = [False] * 4
    pub.publish(cmd)
node.create_subscription(Odometry, '/uav1/odom', answer, SUBSCRIBER_QOS)
end = time.monotonic() + float(sys.argv[1])
while rclpy.ok() and time.monotonic() < end:
    rclpy.spin_once(node, timeout_sec=0.05)
rclpy.try_shutdown()
"""


def test_nan_command_over_ros_stops_sim_node_with_one_line(tmp_path):
    """sim_node in lockstep with a controller that answers t >= 0.5 s with a NaN speed."""
    env = _ros_env(16)
    summary = tmp_path / 'summary'
    leader = subprocess.Popen([str(ROOT / '.venv' / 'bin' / 'python'), '-c', FAKE_LEADER, '90'],
                              env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        sim = subprocess.run([MULTILIFT, 'node', 'multilift_sim', 'sim_node', '--ros-args', '-p',
                              'scenario:=single_lift', '-p', f'summary_dir:={summary}'],
                             env=env, capture_output=True, text=True, timeout=120)
    finally:
        leader.kill()
        leader.wait()
    assert sim.returncode == 1, sim.stderr
    lines = [line for line in sim.stderr.splitlines() if line.startswith('error:')]
    assert lines == ['error: uav1: rotor command is not finite ([nan, 1700.0, 1700.0, 1700.0]) '
                     'at t = 0.500 s']
    stats = yaml.safe_load((summary / 'sim.json').read_text())
    assert stats['simulated_time'] == pytest.approx(0.5)
    assert 'not finite' in stats['error']


def test_rotor_command_of_the_wrong_size_is_named():
    sim = FormationSimulator(scenario_io.load('single_lift'))
    with pytest.raises(SimulationStopped, match='uav1: rotor command has 3 speeds, the vehicle '
                                                'has 4 rotors'):
        sim.advance([np.full(3, 1000.0)], [np.zeros(3, bool)])


def test_saturating_payload_runs_and_stays_within_rotor_limits():
    """The seed's 0.79 kg payload on the single-lift: hover needs ~2100 rad/s, the limit."""
    data = _base('single_lift')
    data['payload']['mass'] = 0.79
    scenario = _load(data)
    hover = math.sqrt((2.5 + 0.79) * 9.81 / (4 * 1.83e-6))
    assert 2090 < hover < 2100
    low, high = [math.inf], [-math.inf]

    def watch(sim, snap, answers):
        if not answers:  # the state at t_max: nothing answers it
            return
        low[0] = min(low[0], float(answers[0].output.rotor_speeds.min()))
        high[0] = max(high[0], float(answers[0].output.rotor_speeds.max()))
    sim = run_headless(_short(scenario, 30.0), on_tick=watch).simulator
    assert sim.t == pytest.approx(30.0)
    assert sim.stats.saturated_time[0] > 0
    assert 0.0 <= low[0] and high[0] <= 2100.0
    assert sim.stats.max_rotor_speed[0] == pytest.approx(2100.0)


def _pids_with(marker: str) -> list[int]:
    out = subprocess.run(['pgrep', '-f', marker], capture_output=True, text=True)
    return [int(p) for p in out.stdout.split()]


def test_sigterm_leaves_no_process_and_a_closed_bag(tmp_path):
    scenario = tmp_path / f'sigterm_{os.getpid()}_{time.monotonic_ns()}.yaml'
    scenario.write_text((SCENARIOS / 'twin_lift.yaml').read_text())
    bag = tmp_path / 'bag'
    proc = subprocess.Popen([MULTILIFT, 'run', str(scenario), '--bag', str(bag)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=_ros_env(15))
    # the command (cli), sim, leader, follower name the scenario file
    wait_for(lambda: len(_pids_with(scenario.name)) == 4, 60, 'the run\'s 4 processes')
    wait_until_simulated(proc, 1.0)  # 100 ticks and more in the bag
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert 'interrupted' in err
    assert _pids_with(scenario.name) == []
    assert _pids_with(str(bag)) == []            # the recorder (its argv names the bag)
    assert (bag / 'metadata.yaml').is_file()
    mcap = next(bag.glob('*.mcap'))
    assert mcap.read_bytes()[-8:] == b'\x89MCAP0\r\n'   # footer magic: the file was closed
    data = raw_messages(bag)
    assert len(data['/uav1/odom']) > 50
    assert abs(len(data['/uav1/odom']) - len(data['/uav2/rotor_cmd'])) <= 1


# -- a node's teardown is bounded (run_node's TeardownGuard) -------------------------------------
# Seen in CI: a follower whose run had finished never returned from the DDS teardown and ignored
# SIGINT and SIGTERM until SIGKILL. The guard ends such a process itself; here the hang is made
# on purpose, once with the GIL released (the Python watchdog: the node's own exit code and a
# warning with the stacks) and once with the GIL held (faulthandler's C watchdog: exit code 1).
GUARDED_HANG = '''
import re, sys, time
from multilift_sim.ros.common import TeardownGuard
guard = TeardownGuard('probe_node')
guard.arm(int(sys.argv[1]), 0.5)
if sys.argv[2] == 'released':
    time.sleep(60)                      # blocked in C with the GIL released
else:
    re.match(r'(a+)+$', 'a' * 64 + 'b')  # blocked in C holding the GIL
'''


@pytest.mark.parametrize('code', [0, 1])
def test_a_teardown_that_hangs_ends_with_the_node_s_code_and_says_where(code):
    out = subprocess.run(['python', '-c', GUARDED_HANG, str(code), 'released'],
                         capture_output=True, text=True, timeout=30)
    assert out.returncode == code, out.stderr
    assert 'warning: probe_node: teardown still running after 0.5 s' in out.stderr
    assert 'time.sleep' in out.stderr or 'line 7' in out.stderr, out.stderr


def test_a_teardown_that_hangs_holding_the_gil_still_ends():
    start = time.monotonic()
    out = subprocess.run(['python', '-c', GUARDED_HANG, '0', 'held'],
                         capture_output=True, text=True, timeout=30)
    assert out.returncode == 1, out.stderr
    assert 'Timeout' in out.stderr and 'line 9' in out.stderr, out.stderr
    assert time.monotonic() - start < 20


def test_a_teardown_that_ends_leaves_no_warning():
    script = ('from multilift_sim.ros.common import TeardownGuard\n'
              "guard = TeardownGuard('probe_node'); guard.arm(0, 0.5); guard.disarm()\n"
              'import time; time.sleep(1.5)\n')
    out = subprocess.run(['python', '-c', script], capture_output=True, text=True, timeout=30)
    assert out.returncode == 0 and 'warning' not in out.stderr and not out.stderr, out.stderr


# -- our processes' Fast DDS profile (multilift_sim.ros.fastdds) ----------------------------------
# what the probe process itself maps of /dev/shm (its own: a listing of /dev/shm would count
# another test's participant that opened its files in between)
SHM_PROBE = ('import os, rclpy; from std_msgs.msg import String\n'
             'def shm(): return {line.split("/dev/shm/")[1].strip() for line in '
             'open("/proc/self/maps") if "/dev/shm/" in line and "fastrtps" in line}\n'
             'before = shm()\n'
             'rclpy.init(); node = rclpy.create_node("profile_probe")\n'
             'pub = node.create_publisher(String, "/profile_probe", 10)\n'
             'pub.publish(String(data="x")); opened = shm() - before\n'
             'node.destroy_node(); rclpy.shutdown()\n'
             'print("ok", sorted(opened))\n')


@pytest.mark.parametrize('discovery,file', [('SUBNET', 'fastdds_profiles.xml'),
                                            ('LOCALHOST', 'fastdds_profiles_localhost.xml')])
def test_the_fastdds_profile_is_written_and_parsed_and_a_users_own_wins(tmp_path, monkeypatch,
                                                                        discovery, file):
    from multilift_sim.ros.fastdds import (FASTDDS_LOCALHOST_PROFILE, FASTDDS_PROFILE,
                                           use_fastdds_profile)
    for name in ('FASTRTPS_DEFAULT_PROFILES_FILE', 'FASTDDS_DEFAULT_PROFILES_FILE'):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path / 'cache'))
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', discovery)
    monkeypatch.setenv('ROS_DOMAIN_ID', str(next_domain()))
    default_env = dict(os.environ)
    path = use_fastdds_profile()
    assert path == tmp_path / 'cache' / 'multilift' / file
    assert path.read_text() == (FASTDDS_PROFILE if discovery == 'SUBNET'
                                else FASTDDS_LOCALHOST_PROFILE)
    assert os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'] == str(path)
    # LOCALHOST is kept by the profile itself (rmw's LOCALHOST would add shared memory)
    assert os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'SUBNET'
    # Fast DDS reads it without complaint: a node with a publisher, under the profile, and
    # on UDP alone: its participant opens nothing in /dev/shm
    out = subprocess.run(['python', '-c', SHM_PROBE], capture_output=True, text=True,
                         timeout=60, env=dict(os.environ))
    assert out.returncode == 0 and out.stdout.strip() == 'ok []', (out.stdout, out.stderr)
    assert 'error' not in out.stderr.lower(), out.stderr
    # without it, Fast DDS's defaults open shared memory (what the lines above rule out)
    out = subprocess.run(['python', '-c', SHM_PROBE], capture_output=True, text=True,
                         timeout=60, env=default_env)
    assert out.returncode == 0 and 'fastrtps_port' in out.stdout, (out.stdout, out.stderr)
    # a profile the user names is left alone, and so is the discovery range
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', discovery)
    monkeypatch.setenv('FASTDDS_DEFAULT_PROFILES_FILE', str(tmp_path / 'theirs.xml'))
    monkeypatch.delenv('FASTRTPS_DEFAULT_PROFILES_FILE')
    assert use_fastdds_profile() is None
    assert 'FASTRTPS_DEFAULT_PROFILES_FILE' not in os.environ
    assert os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == discovery


def test_our_localhost_participants_and_anyone_elses_hear_each_other(monkeypatch, tmp_path):
    """A node of a user's under rmw's own LOCALHOST (shared memory and UDP) and one under our
    LOCALHOST profile (UDP on 127.0.0.1) exchange messages both ways."""
    from multilift_sim.ros.fastdds import use_fastdds_profile
    for name in ('FASTRTPS_DEFAULT_PROFILES_FILE', 'FASTDDS_DEFAULT_PROFILES_FILE'):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path / 'cache'))
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    monkeypatch.setenv('ROS_DOMAIN_ID', str(next_domain()))
    theirs = dict(os.environ)
    use_fastdds_profile()
    ours = dict(os.environ)
    for publisher, subscriber in ((ours, theirs), (theirs, ours)):
        listener = subprocess.Popen(['python', '-c', ECHO_ONE], env=subscriber, text=True,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        talker = subprocess.Popen(['python', '-c', TALK_UNTIL_HEARD], env=publisher, text=True,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        out, err = listener.communicate(timeout=60)
        talker.communicate(timeout=60)
        assert listener.returncode == 0 and out.strip() == 'heard hello', err


# a subscriber that prints the first message it hears; a publisher that publishes until a
# subscriber matched and then acknowledged a message (reliable, transient_local history)
ECHO_ONE = ('import rclpy; from std_msgs.msg import String\n'
            'from rclpy.qos import QoSProfile, DurabilityPolicy\n'
            'rclpy.init(); node = rclpy.create_node("echo_one"); heard = []\n'
            'qos = QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL)\n'
            'node.create_subscription(String, "/interop", lambda m: heard.append(m.data), qos)\n'
            'while not heard: rclpy.spin_once(node, timeout_sec=0.1)\n'
            'print("heard", heard[0])\n')
TALK_UNTIL_HEARD = ('import rclpy; from std_msgs.msg import String\n'
                    'from rclpy.duration import Duration\n'
                    'from rclpy.qos import QoSProfile, DurabilityPolicy\n'
                    'rclpy.init(); node = rclpy.create_node("talker")\n'
                    'qos = QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL)\n'
                    'pub = node.create_publisher(String, "/interop", qos)\n'
                    'while pub.get_subscription_count() < 1: rclpy.spin_once(node, '
                    'timeout_sec=0.1)\n'
                    'pub.publish(String(data="hello"))\n'
                    'pub.wait_for_all_acked(Duration(seconds=30))\n')
