"""`multilift run SCENARIO --external uav1` with the example leader of examples/ (built with
colcon as a user would), through the `multilift_run` fixture of multilift_tools.testing (the
pytest plugin a user's own tests get): the user's node, written with default QoS, flies the
formation; the bag holds its commands; our own follower node counts as an external controller
(it reads /formation/snapshot, not /uav2/odom); a missing node is named at the startup timeout,
and so is a node that publishes the commands but reads no state. Across hosts:
test_multi_host.py.
"""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from multilift_msgs.msg import RotorCommand
from nav_msgs.msg import Odometry
from rclpy.serialization import deserialize_message

from conftest import raw_messages

ROOT = Path(__file__).resolve().parents[2]
MULTILIFT = str(ROOT / 'scripts' / 'multilift')
EXAMPLE = ROOT / 'examples' / 'multilift_example_leader'


@pytest.fixture(scope='module')
def example_install(tmp_path_factory) -> Path:
    """examples/multilift_example_leader built with `colcon build`: its install prefix."""
    work = tmp_path_factory.mktemp('example_ws')
    result = subprocess.run(
        ['colcon', 'build', '--base-paths', str(EXAMPLE), '--build-base', str(work / 'build'),
         '--install-base', str(work / 'install'), '--event-handlers', 'console_cohesion-'],
        cwd=work, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    return work / 'install' / 'multilift_example_leader'


def start_example_leader(prefix: Path, log: Path) -> subprocess.Popen:
    """The example's `leader` executable, as `ros2 run` would start it from a sourced install."""
    site = prefix / 'lib' / 'python3.11' / 'site-packages'
    env = dict(os.environ, PYTHONPATH=f'{site}{os.pathsep}{os.environ.get("PYTHONPATH", "")}',
               PYTHONUNBUFFERED='1')
    return subprocess.Popen([str(prefix / 'lib' / 'multilift_example_leader' / 'leader'),
                             '--ros-args', '-p', 'scenario:=single_lift'], env=env,
                            stdout=open(log, 'w'), stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL, start_new_session=True)


def test_the_example_leader_flies_single_lift_and_is_recorded(multilift_run, example_install,
                                                               tmp_path):
    bag = tmp_path / 'bag'
    run = multilift_run('single_lift', external='uav1', duration=2.0, bag=bag)
    run.wait_for_output('waiting for external controllers of uav1')
    leader = start_example_leader(example_install, tmp_path / 'leader.log')
    try:
        assert run.wait(timeout=180) == 0, run.output()
    finally:
        os.killpg(leader.pid, signal.SIGINT)
        leader.wait(timeout=30)
    # its last line after Ctrl-C, and no log call into a context the signal shut down
    log = (tmp_path / 'leader.log').read_text()
    assert re.search(r'answered [1-9]\d* states', log), log
    assert 'Failed to publish log message to rosout' not in log, log
    assert 'leader tracking' not in run.output()  # none of our controllers ran
    recorded = raw_messages(bag)
    commands = [deserialize_message(d, RotorCommand) for d in recorded['/uav1/rotor_cmd']]
    states = [deserialize_message(d, Odometry) for d in recorded['/uav1/odom']]
    assert len(states) == 201  # t = 0, 0.01, .. 2 s
    # every state before t = 2 s answered once by the user's node, with the state's stamp;
    # nothing waits for an answer to the last state, which the bag may or may not hold
    assert [c.header.stamp for c in commands[:200]] == [s.header.stamp for s in states[:200]]
    assert len(commands) in (200, 201)
    assert all(len(c.angular_velocity) == 4 and min(c.angular_velocity) > 0 for c in commands)
    metadata = yaml.safe_load((bag / 'metadata.yaml').read_text())
    topics = {t['topic_metadata']['name']: t['topic_metadata']
              for t in metadata['rosbag2_bagfile_information']['topics_with_message_count']}
    offered = topics['/uav1/rotor_cmd']['offered_qos_profiles']
    offered = yaml.safe_load(offered) if isinstance(offered, str) else offered
    assert [q['durability'] for q in offered] == ['volatile']  # the user's default QoS
    assert '/tf' in topics and '/uav1/attitude_setpoint' not in topics


def test_our_follower_node_is_an_external_controller(multilift_run, tmp_path):
    bag = tmp_path / 'bag'
    run = multilift_run('twin_lift', external='uav2', duration=1.0, bag=bag)
    with open(tmp_path / 'follower.log', 'w') as log:
        follower = subprocess.Popen(
            [MULTILIFT, 'node', 'multilift_control', 'follower_node', '--ros-args', '-p',
             'scenario:=twin_lift', '-p', 'uav_index:=2'], stdout=log,
            stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        assert run.wait(timeout=180) == 0, run.output() + (tmp_path / 'follower.log').read_text()
    finally:
        os.killpg(follower.pid, signal.SIGINT)
        follower.wait(timeout=30)
    recorded = raw_messages(bag)
    assert len(recorded['/uav2/rotor_cmd']) == len(recorded['/formation/snapshot']) > 0
    assert len(recorded['/uav2/formation_error']) == len(recorded['/uav2/rotor_cmd'])


def test_the_startup_timeout_names_the_missing_external_controller(multilift_run):
    run = multilift_run('twin_lift', external='uav2', duration=1.0, startup_timeout=3.0)
    assert run.wait(timeout=120) == 1, run.output()
    assert ('waiting for the external controller of uav2 to subscribe to a state topic '
            '(/uav2/odom, /formation/snapshot, /uav1/odom, /payload/odom, /tf); the '
            'external controller of uav2 to publish /uav2/rotor_cmd') in run.output()


# publishes uav2's commands, reads only /clock (not a state: every sim-time node reads it)
NO_STATE_READER = """
import rclpy
from multilift_msgs.msg import RotorCommand
from rosgraph_msgs.msg import Clock
rclpy.init()
node = rclpy.create_node('reads_no_state')
node.create_publisher(RotorCommand, '/uav2/rotor_cmd', 10)
node.create_subscription(Clock, '/clock', lambda msg: None, 10)
print('up', flush=True)
try:
    rclpy.spin(node)
except KeyboardInterrupt:
    pass
"""


def test_a_commanding_node_that_reads_no_state_is_named(multilift_run):
    node = subprocess.Popen([sys.executable, '-c', NO_STATE_READER], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True,
                            start_new_session=True)
    try:
        assert node.stdout.readline() == 'up\n'
        run = multilift_run('twin_lift', external='uav2', duration=1.0, startup_timeout=5.0)
        assert run.wait(timeout=120) == 1, run.output()
    finally:
        os.killpg(node.pid, signal.SIGINT)
        node.wait(timeout=30)
    assert ('waiting for the external controller of uav2 to subscribe to a state topic '
            '(/uav2/odom,') in run.output()
    assert 'to publish /uav2/rotor_cmd' not in run.output()


# answers every /uav1/odom state of a single-lift with hover-ish speeds until it answered the
# state at `last` [ns], then waits for the simulator's acknowledgement and exits
ANSWER_UNTIL = """
import sys
import rclpy
from rclpy.duration import Duration
from multilift_msgs.msg import RotorCommand
from nav_msgs.msg import Odometry
last = int(sys.argv[1])
rclpy.init()
node = rclpy.create_node('answers_until')
commands = node.create_publisher(RotorCommand, '/uav1/rotor_cmd', 10)
done = []

def answer(state):
    command = RotorCommand(header=state.header, angular_velocity=[1800.0] * 4,
                           saturated=[False] * 4)
    commands.publish(command)
    stamp = state.header.stamp.sec * 1_000_000_000 + state.header.stamp.nanosec
    if stamp >= last:
        done.append(stamp)

node.create_subscription(Odometry, '/uav1/odom', answer, 10)
print('up', flush=True)
while not done:
    rclpy.spin_once(node, timeout_sec=0.1)
commands.wait_for_all_acked(Duration(seconds=10))
print('answered up to', done[0], flush=True)
node.destroy_node()
rclpy.shutdown()
"""


def test_a_run_of_duration_t_needs_commands_before_t_only(multilift_run, tmp_path):
    """The user's node answers every state up to t = 0.49 s and exits: a 0.5 s run is done
    (before, the simulator waited for a command for the state at t = 0.5 s and failed)."""
    node = subprocess.Popen([sys.executable, '-c', ANSWER_UNTIL, str(490_000_000)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL, text=True, start_new_session=True)
    try:
        assert node.stdout.readline() == 'up\n'
        run = multilift_run('single_lift', external='uav1', duration=0.5, bag=tmp_path / 'bag')
        assert node.wait(timeout=120) == 0
        assert 'answered up to 490000000' in node.stdout.read()
        assert run.wait(timeout=120) == 0, run.output()
    finally:
        if node.poll() is None:
            os.killpg(node.pid, signal.SIGINT)
            node.wait(timeout=30)
    recorded = raw_messages(tmp_path / 'bag')
    assert len(recorded['/uav1/odom']) == 51          # the states at t = 0, 0.01, .. 0.5 s
    assert len(recorded['/uav1/rotor_cmd']) == 50     # the answers to the states before 0.5 s
    assert len(recorded['/formation/state']) == 51    # the last under the commands held


def test_external_names_a_uav_of_the_scenario(multilift_run):
    run = multilift_run('single_lift', external='uav2')
    assert run.wait(timeout=60) == 2
    assert 'uav2' in run.output() and 'uav1..uav1' in run.output()
