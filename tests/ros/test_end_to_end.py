"""The whole stack as a user runs it: `scripts/multilift run` in separate processes, the bag
read back with rosbags (an independent reader), and the failure paths."""
from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from conftest import ROOT, SCENARIOS, next_domain, wait_for, wait_until_simulated

MULTILIFT = str(ROOT / 'scripts' / 'multilift')


def read_bag(path: Path) -> dict[str, list]:
    """topic -> list of (log_time, message) decoded by rosbags."""
    out: dict[str, list] = {}
    with AnyReader([path]) as reader:
        for conn, stamp, raw in reader.messages():
            out.setdefault(conn.topic, []).append((stamp, reader.deserialize(raw, conn.msgtype)))
        types = {c.topic: c.msgtype for c in reader.connections}
    out['__types__'] = types
    return out


def stamp_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


@pytest.fixture(scope='module')
def single_lift_bag(tmp_path_factory):
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    bag = tmp_path_factory.mktemp('run') / 'single_lift'
    out = subprocess.run([MULTILIFT, 'run', 'single_lift', '--duration', '12', '--bag', str(bag)],
                         capture_output=True, text=True, timeout=300, env=env)
    assert out.returncode == 0, out.stderr + out.stdout
    return bag, out.stdout, read_bag(bag)


def test_bag_has_every_topic_once_per_tick(single_lift_bag):
    bag, _, data = single_lift_bag
    assert (bag / 'metadata.yaml').is_file()
    ticks = 12 * 100 + 1  # t = 0 .. 12 s at 100 Hz
    states = {'/clock': 'rosgraph_msgs/msg/Clock', '/uav1/odom': 'nav_msgs/msg/Odometry',
              '/payload/odom': 'nav_msgs/msg/Odometry',
              '/formation/state': 'multilift_msgs/msg/FormationState'}
    # the controller answers the states before t = 12 s: nothing is asked of it at the end
    answers = {'/formation/snapshot': 'multilift_msgs/msg/FormationSnapshot',
               '/uav1/rotor_cmd': 'multilift_msgs/msg/RotorCommand',
               '/uav1/reference': 'multilift_msgs/msg/TrackingReference',
               '/uav1/attitude_setpoint': 'multilift_msgs/msg/AttitudeSetpoint'}
    for expected, count in ((states, ticks), (answers, ticks - 1)):
        for topic, kind in expected.items():
            assert data['__types__'][topic] == kind
            assert len(data[topic]) == count, topic


def test_lockstep_every_command_answers_its_state(single_lift_bag):
    _, _, data = single_lift_bag
    odom_stamps = [stamp_ns(m) for _, m in data['/uav1/odom']]
    cmd_stamps = [stamp_ns(m) for _, m in data['/uav1/rotor_cmd']]
    assert cmd_stamps == odom_stamps[:-1]  # every state before the last, once
    assert np.all(np.diff(odom_stamps) == 10_000_000)  # 100 Hz simulated time
    clock = [m.clock.sec * 10 ** 9 + m.clock.nanosec for _, m in data['/clock']]
    assert clock == odom_stamps


def test_the_simulator_s_messages_are_logged_at_their_own_tick(single_lift_bag):
    """The recorder reads in rounds, yet stamps each message with the /clock sent before it:
    what the simulator publishes between two /clock messages is logged at its header stamp."""
    _, _, data = single_lift_bag
    for topic in ('/uav1/odom', '/payload/odom', '/formation/state', '/formation/snapshot'):
        logged = [(log_time, stamp_ns(m)) for log_time, m in data[topic]]
        assert all(log_time == stamp for log_time, stamp in logged), \
            (topic, [pair for pair in logged if pair[0] != pair[1]][:5])


def test_rotor_speeds_within_limits_and_frames(single_lift_bag):
    _, _, data = single_lift_bag
    speeds = np.array([m.angular_velocity for _, m in data['/uav1/rotor_cmd']])
    assert speeds.shape[1] == 4
    assert speeds.min() >= 0.0 and speeds.max() <= 2100.0
    odom = data['/uav1/odom'][0][1]
    assert odom.header.frame_id == 'world' and odom.child_frame_id == 'uav1/base_link'
    assert data['/payload/odom'][0][1].header.frame_id == 'world'


def test_flies_the_climb_with_payload_hanging_below(single_lift_bag):
    _, _, data = single_lift_bag
    uav = np.array([[m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z]
                    for _, m in data['/uav1/odom']])
    payload = np.array([[m.pose.pose.position.x, m.pose.pose.position.y,
                         m.pose.pose.position.z] for _, m in data['/payload/odom']])
    # climb 0.3 m/s for 10 s, then +x at 0.5 m/s (world frame, z up)
    assert uav[1000, 2] == pytest.approx(3.0, abs=0.15)
    assert uav[1200, 0] == pytest.approx(1.0, abs=0.3)
    assert np.all(payload[:, 2] < uav[:, 2] - 2.0)
    cable = np.linalg.norm(payload - uav, axis=1)
    assert np.allclose(cable, 2.5, atol=1e-4)


def test_formation_state_and_static_tension(single_lift_bag):
    _, _, data = single_lift_bag
    g = np.array([m.constraint_position[0] for _, m in data['/formation/state']])
    tension = np.array([m.cable_tension[0] for _, m in data['/formation/state']])
    assert np.abs(g).max() < 1e-4
    # at t = 0 the payload hangs at rest under a UAV that starts to climb: T ~ m_p g
    assert tension[0] == pytest.approx(0.4 * 9.81, rel=0.1)
    assert np.all(tension > 0)


def test_summary_printed(single_lift_bag):
    bag, stdout, _ = single_lift_bag
    assert 'max |g|' in stdout and 'max ' in stdout and 'saturated' in stdout
    assert str(bag) in stdout


def _run(args, env, **kw):
    return subprocess.Popen([MULTILIFT, 'run', *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, **kw)


def _children_of(marker: str) -> list[int]:
    out = subprocess.run(['pgrep', '-f', marker], capture_output=True, text=True)
    return [int(p) for p in out.stdout.split()]


@pytest.fixture
def private_scenario(tmp_path):
    """single_lift under a unique path, so the test can find its own processes."""
    path = tmp_path / f'single_lift_{os.getpid()}_{time.monotonic_ns()}.yaml'
    path.write_text((SCENARIOS / 'single_lift.yaml').read_text())
    return path


def _wait_for_processes(marker: str, count: int, timeout: float = 60.0) -> list[int]:
    def enough() -> list[int]:
        pids = _children_of(marker)
        return pids if len(pids) >= count else []
    return wait_for(enough, timeout, f'{count} processes matching {marker!r} running')


def test_ctrl_c_leaves_closed_readable_bag_and_no_processes(tmp_path, ros_env,
                                                             private_scenario):
    bag = tmp_path / 'bag'
    proc = _run([str(private_scenario), '--bag', str(bag)], ros_env)
    _wait_for_processes(private_scenario.name, 3)
    wait_until_simulated(proc, 1.0)  # 100 ticks and more in the bag
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert _children_of(private_scenario.name) == []
    data = read_bag(bag)
    assert len(data['/uav1/odom']) > 50
    assert abs(len(data['/uav1/odom']) - len(data['/uav1/rotor_cmd'])) <= 1


@pytest.mark.parametrize('scenario,victim,named', [
    ('single_lift', 'leader_node', 'leader_node'),
    ('twin_lift', 'follower_node', 'follower_node (uav2)')])
def test_a_dead_controller_stops_the_run_and_is_named(tmp_path, ros_env, scenario, victim,
                                                      named):
    private = tmp_path / f'{scenario}_{os.getpid()}_{time.monotonic_ns()}.yaml'
    private.write_text((SCENARIOS / f'{scenario}.yaml').read_text())
    bag = tmp_path / 'bag'
    proc = _run([str(private), '--bag', str(bag)], ros_env)
    pids = _wait_for_processes(f'{victim}.*{private.name}', 1)
    wait_until_simulated(proc, 0.5)  # the run is under way
    os.kill(pids[0], signal.SIGKILL)
    killed = time.monotonic()
    _, err = proc.communicate(timeout=60)
    print(f'{victim} killed: the run stopped {time.monotonic() - killed:.2f} s later')
    assert proc.returncode == 1
    assert f'error: {named} stopped' in err
    assert _children_of(private.name) == []
    assert len(read_bag(bag)['/uav1/odom']) > 10


def test_a_killed_recorder_stops_the_run_and_its_bag_is_rebuilt(tmp_path, ros_env,
                                                               private_scenario):
    """The recorder dies without closing the bag (here SIGKILL, as a crash in the DDS library
    would): the run stops, names it, and rebuilds the bag from its complete chunks."""
    bag = tmp_path / 'bag'
    proc = _run([str(private_scenario), '--bag', str(bag)], ros_env)
    pids = _wait_for_processes(f'recorder_node.*{bag}', 1)
    wait_until_simulated(proc, 1.0)
    size = sum(f.stat().st_size for f in bag.glob('*.mcap'))
    # a flush after t = 1 s: the file grew by a chunk of messages
    wait_for(lambda: sum(f.stat().st_size for f in bag.glob('*.mcap')) > size, 60,
             'a chunk written after t = 1 s')
    os.kill(pids[0], signal.SIGKILL)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1, err
    assert 'error: recorder_node stopped (killed by SIGKILL)' in err
    assert 'warning: recorder_node ended (killed by SIGKILL) without closing the bag' in err
    assert f'bag rebuilt at {bag} from its complete chunks' in err
    assert _children_of(private_scenario.name) == []
    assert (bag / 'metadata.yaml').is_file()
    odom = read_bag(bag)['/uav1/odom']
    assert len(odom) > 0
    assert [stamp_ns(m) for _, m in odom] == sorted(stamp_ns(m) for _, m in odom)


def test_a_silent_controller_hits_the_lockstep_timeout(tmp_path, ros_env, private_scenario):
    text = private_scenario.read_text().replace('command_timeout: 5.0', 'command_timeout: 1.0')
    private_scenario.write_text(text)
    proc = _run([str(private_scenario)], ros_env)
    pids = _wait_for_processes(f'leader_node.*{private_scenario.name}', 1)
    wait_until_simulated(proc, 0.5)  # the leader has answered: the lockstep is running
    os.kill(pids[0], signal.SIGSTOP)
    try:
        _, err = proc.communicate(timeout=60)
    finally:
        for pid in _children_of(private_scenario.name):
            os.kill(pid, signal.SIGKILL)
    assert proc.returncode == 1
    assert 'no rotor command from uav1' in err and 'sim_node' in err


def test_constraint_violation_names_cable_time_and_residual(tmp_path, ros_env):
    text = (SCENARIOS / 'single_lift_swing.yaml').read_text()
    text = text.replace('baumgarte_alpha: 20.0', 'baumgarte_alpha: 0.0')
    text = text.replace('baumgarte_beta: 20.0', 'baumgarte_beta: 0.0')
    text = text.replace('physics_rate: 1000.0', 'physics_rate: 100.0')
    text = text.replace('constraint_tolerance: 0.1', 'constraint_tolerance: 1.0e-9')
    path = tmp_path / 'drift.yaml'
    path.write_text(text)
    proc = _run([str(path), '--duration', '5'], ros_env)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 1
    assert 'cable 1: constraint residual |g| =' in err and 'at t = ' in err
