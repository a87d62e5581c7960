"""`multilift topic ...` and `multilift node ...` (cli_tools), against live publishers.

The tools run as separate processes (`scripts/multilift` when it exists, else cli_tools directly)
on a ROS domain of this module's own (conftest.next_domain), discovery on localhost only.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest
import rclpy
import yaml
from multilift_msgs.msg import RotorCommand
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Byte, ByteMultiArray, Int64

from multilift_sim.ros.introspection import message_to_ordered, message_to_yaml

from conftest import ROOT, next_domain, wait_for
DOMAIN = next_domain()
ENV = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
LATCHED = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def multilift(*args: str, timeout: float = 30.0) -> subprocess.CompletedProcess:
    """Run `multilift topic|node ...` to completion, output captured."""
    wrapper = ROOT / 'scripts' / 'multilift'
    if wrapper.is_file() and os.access(wrapper, os.X_OK):
        command = [str(wrapper), *args]
    else:
        entry = {'topic': 'topic_main', 'node': 'node_main'}[args[0]]
        command = [sys.executable, '-c', 'import sys; from multilift_tools.topic_tools import '
                   f'{entry}; sys.exit({entry}(sys.argv[1:]))', *args[1:]]
    return subprocess.run(command, env=ENV, capture_output=True, text=True, timeout=timeout)


def _rotor() -> RotorCommand:
    msg = RotorCommand(angular_velocity=[410.5, 399.0, 402.25, 401.0],
                       saturated=[False, True, False, False])
    msg.header.stamp.sec, msg.header.stamp.nanosec = 3, 500
    msg.header.frame_id = 'uav2/base_link'
    return msg


def test_yaml_like_ros2_topic_echo():
    assert message_to_yaml(Int64(data=5)) == 'data: 5\n'
    text = message_to_yaml(_rotor())
    assert text.splitlines()[:5] == ['header:', '  stamp:', '    sec: 3', '    nanosec: 500',
                                     "  frame_id: uav2/base_link"]
    assert '\nangular_velocity:\n- 410.5\n- 399.0\n' in text
    assert yaml.safe_load(text) == {
        'header': {'stamp': {'sec': 3, 'nanosec': 500}, 'frame_id': 'uav2/base_link'},
        'angular_velocity': [410.5, 399.0, 402.25, 401.0],
        'saturated': [False, True, False, False]}
    odom = Odometry()
    odom.pose.covariance[0] = 2.0
    as_dict = message_to_ordered(odom)
    assert list(as_dict) == ['header', 'child_frame_id', 'pose', 'twist']
    assert as_dict['pose']['covariance'] == [2.0] + [0.0] * 35
    assert yaml.safe_load(message_to_yaml(odom))['twist']['covariance'] == [0.0] * 36
    assert message_to_ordered(Byte(data=b'\x07')) == {'data': 7}
    blob = yaml.safe_load(message_to_yaml(ByteMultiArray(data=[b'\x01', b'\xff'])))
    assert blob['data'] == [1, 255]


@pytest.fixture(scope='module')
def publishers():
    """Latched publishers of a multilift message and a nav_msgs message, held for the module."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=DOMAIN)
        node = rclpy.create_node('topic_tools_test', context=context)
        rotor = node.create_publisher(RotorCommand, '/tools_test/rotor_command', LATCHED)
        odom = node.create_publisher(Odometry, '/tools_test/odom', LATCHED)
        rotor.publish(_rotor())
        msg = Odometry(child_frame_id='uav1/base_link')
        msg.pose.pose.position.z = 2.5
        msg.pose.covariance[35] = 0.25
        odom.publish(msg)
        yield node
        node.destroy_node()
        context.try_shutdown()


def test_list_and_info(publishers):
    wanted = {'/tools_test/rotor_command [multilift_msgs/msg/RotorCommand]',
              '/tools_test/odom [nav_msgs/msg/Odometry]'}

    def listed() -> list[str] | None:
        # `topic list` ends once the graph settles (as ros2cli's does); on a loaded machine the
        # publishers' node may be seen a moment before its topics: ask again until they are
        out = multilift('topic', 'list', '-t')
        assert out.returncode == 0, out.stderr
        lines = out.stdout.splitlines()
        return lines if wanted <= set(lines) else None
    wait_for(listed, 60, 'the publishers\' topics in `topic list -t`')
    names = multilift('topic', 'list').stdout.splitlines()
    assert '/tools_test/odom' in names and names == sorted(names)

    info = multilift('topic', 'info', '/tools_test/rotor_command')
    assert info.returncode == 0, info.stderr
    assert info.stdout.splitlines() == ['Type: multilift_msgs/msg/RotorCommand',
                                        'Publisher count: 1', 'Subscription count: 0']
    missing = multilift('topic', 'info', '/tools_test/nothing')
    assert missing.returncode == 1 and 'Unknown topic' in missing.stderr


def test_echo_once_prints_the_latched_message(publishers):
    out = multilift('topic', 'echo', '/tools_test/rotor_command', '--once')
    assert out.returncode == 0, out.stderr
    assert out.stdout.endswith('---\n')
    assert yaml.safe_load(out.stdout.split('---\n')[0]) == yaml.safe_load(
        message_to_yaml(_rotor()))

    odom = multilift('topic', 'echo', '/tools_test/odom', 'nav_msgs/msg/Odometry', '--once')
    assert odom.returncode == 0, odom.stderr
    data = yaml.safe_load(odom.stdout.split('---\n')[0])
    assert data['child_frame_id'] == 'uav1/base_link'
    assert data['pose']['pose']['position']['z'] == 2.5
    assert data['pose']['covariance'] == [0.0] * 35 + [0.25]


def _echo_process(topic: str, type_name: str) -> subprocess.Popen:
    return subprocess.Popen([str(ROOT / 'scripts' / 'multilift'), 'topic', 'echo', topic,
                             type_name, '--once'], env=ENV, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


@pytest.mark.parametrize('qos, leaf', [(LATCHED, 'latched'), (10, 'volatile')])
def test_echo_started_first_prints_what_a_later_publisher_sends(publishers, qos, leaf):
    """The subscription comes first (no publisher known: reliable, transient_local); then a
    latched publisher sends once, or a publisher with the defaults (volatile: it does not
    match that request, so echo subscribes again) keeps sending: echo prints it either way."""
    topic = f'/tools_test/late_{leaf}'
    echo = _echo_process(topic, 'std_msgs/msg/Int64')
    try:
        deadline = time.monotonic() + 30
        while publishers.count_subscribers(topic) < 1:  # echo has subscribed
            assert echo.poll() is None, echo.communicate()
            assert time.monotonic() < deadline, 'echo never subscribed'
            time.sleep(0.05)
        publisher = publishers.create_publisher(Int64, topic, qos)
        publisher.publish(Int64(data=7))
        while echo.poll() is None:
            assert time.monotonic() < deadline, 'echo printed nothing'
            if qos == 10:  # a volatile message reaches only readers matched when it is sent
                publisher.publish(Int64(data=7))
            time.sleep(0.1)
        out, err = echo.communicate()
        assert echo.returncode == 0, err
        assert out == 'data: 7\n---\n'
    finally:
        if echo.poll() is None:
            os.killpg(echo.pid, 9)
            echo.wait()


def test_echo_of_an_unknown_topic_says_so():
    out = multilift('topic', 'echo', '/tools_test/never_published', '--once')
    assert out.returncode == 1
    assert 'Could not determine the type' in out.stderr


def test_node_runs_the_console_script_like_ros2_run(tmp_path):
    missing = multilift('node', 'multilift_sim', 'no_such_node')
    assert missing.returncode == 1
    assert "No executable 'no_such_node'" in missing.stderr and 'recorder_node' in missing.stderr
    unknown = multilift('node', 'no_such_package', 'x')
    assert unknown.returncode == 1 and "Package 'no_such_package' not found" in unknown.stderr
    # The executable runs with the remaining arguments: the recorder refuses a used directory.
    taken = tmp_path / 'taken'
    taken.mkdir()
    (taken / 'file').write_text('x')
    out = multilift('node', 'multilift_sim', 'recorder_node', '--ros-args', '-p', f'bag:={taken}')
    assert out.returncode == 2
    assert f"bag directory '{taken}' already exists" in out.stderr
