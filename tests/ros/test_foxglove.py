"""`multilift foxglove` (foxglove_bridge) against a Foxglove WebSocket client, and the shipped
Foxglove layout.

The bridge runs as a separate process (`scripts/multilift foxglove` once cli.py dispatches to it,
else foxglove_main directly) on a free port and a ROS domain of this module's own
(conftest.next_domain), discovery on localhost only; the test process publishes /payload/odom
and is the WebSocket client (the `websockets` package, subprotocol foxglove.sdk.v1, as the
Foxglove app).
"""

from __future__ import annotations

import json
import os
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import pytest
import rclpy
from multilift_msgs.msg import FormationState, RotorCommand
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from websockets.sync.client import connect

from multilift_sim.wire import msgdefs
from multilift_tools.foxglove.bridge import is_bridged
from multilift_tools.foxglove.server import SUBPROTOCOL
from multilift_tools.foxglove.stamps import stamp_ns

from conftest import ROOT, next_domain
DOMAIN = next_domain()
ENV = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
           PYTHONUNBUFFERED='1')
LATCHED = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
MESSAGE_DATA = 0x01  # binary opcode of the server's Message Data
TIMEOUT = 30.0  # [s] discovery, advertisement and first messages, on a loaded machine


def bridge_command(*args: str) -> list[str]:
    cli = (ROOT / 'ros_ws' / 'src' / 'multilift_tools' / 'multilift_tools' / 'cli.py').read_text()
    if 'foxglove.command' in cli:
        return [str(ROOT / 'scripts' / 'multilift'), 'foxglove', *args]
    return [sys.executable, '-c', 'import sys; from multilift_tools.foxglove.command import '
            'foxglove_main; sys.exit(foxglove_main(sys.argv[1:]))', *args]


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


@pytest.fixture
def bridge(tmp_path):
    """The bridge process on a free port: (process, port, log path); killed at teardown."""
    port = free_port()
    log = open(tmp_path / 'bridge.log', 'w+')
    process = subprocess.Popen(bridge_command('--port', str(port)), env=ENV, stdout=log,
                               stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                               start_new_session=True)
    yield process, port, tmp_path / 'bridge.log'
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
    process.wait(timeout=10)
    log.close()


@pytest.fixture
def odometry_publisher():
    """A node of the test process publishing /payload/odom at 50 Hz (and a RotorCommand, latched,
    once) from a thread; message k has position.x = k and a stamp of k * 20 ms."""
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    node = rclpy.create_node('foxglove_test', context=context)
    odom = node.create_publisher(Odometry, '/payload/odom', LATCHED)
    rotor = node.create_publisher(RotorCommand, '/uav1/rotor_cmd', LATCHED)
    rotor.publish(RotorCommand(angular_velocity=[410.0, 420.0, 430.0, 440.0],
                               saturated=[False, True, False, False]))
    stop = threading.Event()
    count = [0]

    def run() -> None:
        while not stop.is_set():
            k = count[0]
            msg = Odometry()
            msg.header.frame_id = 'world'
            stamp = divmod(k * 20_000_000, 1_000_000_000)  # (sec, nanosec)
            msg.header.stamp.sec, msg.header.stamp.nanosec = stamp
            msg.child_frame_id = 'payload'
            msg.pose.pose.position.x = float(k)
            msg.pose.pose.position.z = -10.26
            msg.pose.pose.orientation.w = 1.0
            odom.publish(msg)
            count[0] += 1
            stop.wait(0.02)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    yield count
    stop.set()
    thread.join(timeout=5)
    node.destroy_node()
    context.try_shutdown()


def _connect(port: int):
    deadline = time.monotonic() + TIMEOUT
    while True:
        try:
            return connect(f'ws://127.0.0.1:{port}', subprotocols=[SUBPROTOCOL],
                           open_timeout=5, max_size=None)
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def test_client_receives_decodable_odometry(bridge, odometry_publisher):
    process, port, log = bridge
    with _connect(port) as ws:
        assert ws.subprotocol == SUBPROTOCOL
        info = json.loads(ws.recv(timeout=TIMEOUT))
        assert info['op'] == 'serverInfo' and info['name'] == 'multilift'
        assert 'time' in info['capabilities']
        channels: dict[str, dict] = {}
        subscription = None
        received: list[tuple[int, Odometry]] = []
        deadline = time.monotonic() + TIMEOUT
        while len(received) < 25:
            assert time.monotonic() < deadline, (channels.keys(), log.read_text())
            frame = ws.recv(timeout=TIMEOUT)
            if isinstance(frame, str):
                message = json.loads(frame)
                if message['op'] == 'advertise':
                    channels.update({c['topic']: c for c in message['channels']})
                    if subscription is None and '/payload/odom' in channels:
                        subscription = 7
                        ws.send(json.dumps({'op': 'subscribe', 'subscriptions': [
                            {'id': subscription, 'channelId': channels['/payload/odom']['id']}]}))
                continue
            if frame[0] != MESSAGE_DATA:
                continue  # Time (0x02) and others
            sub_id, log_time = struct.unpack_from('<IQ', frame, 1)
            assert sub_id == subscription
            received.append((log_time, deserialize_message(frame[13:], Odometry)))
        odom = channels['/payload/odom']
        assert (odom['encoding'], odom['schemaName'], odom['schemaEncoding']) == (
            'cdr', 'nav_msgs/msg/Odometry', 'ros2msg')
        assert odom['schema'] == msgdefs.message_definition('nav_msgs/msg/Odometry')
        rotor = channels['/uav1/rotor_cmd']  # a custom message: its full definition
        assert rotor['schemaName'] == 'multilift_msgs/msg/RotorCommand'
        assert rotor['schema'] == msgdefs.message_definition('multilift_msgs/msg/RotorCommand')
        assert 'MSG: std_msgs/Header' in rotor['schema']
        assert '/parameter_events' not in channels
    xs = [m.pose.pose.position.x for _, m in received]
    assert xs == sorted(xs) and len(set(xs)) == len(xs)  # in order, no duplicates
    assert all(x.is_integer() for x in xs)
    for _, msg in received:
        k = int(msg.pose.pose.position.x)
        stamp = divmod(k * 20_000_000, 1_000_000_000)
        assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == stamp
        assert (msg.header.frame_id, msg.child_frame_id) == ('world', 'payload')
        assert msg.pose.pose.position.z == -10.26
    # each message's time is its header stamp
    assert all(t == m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec
               for t, m in received)
    assert info['metadata']['ROS_DISTRO'] == 'jazzy'
    process.send_signal(signal.SIGTERM)
    assert process.wait(timeout=15) == 0, log.read_text()
    text = log.read_text()
    assert 'bridging /payload/odom [nav_msgs/msg/Odometry]' in text
    assert 'stopped after forwarding' in text


def test_port_in_use_is_one_line_and_exit_code_1(tmp_path):
    with socket.socket() as busy:
        busy.bind(('127.0.0.1', 0))
        busy.listen()
        port = busy.getsockname()[1]
        result = subprocess.run(bridge_command('--port', str(port)), env=ENV,
                                capture_output=True, text=True, timeout=60)
    assert result.returncode == 1
    assert f'cannot serve on 127.0.0.1:{port}' in result.stderr


def test_which_topics_and_which_time():
    assert is_bridged('/payload/odom') and is_bridged('/rosout')
    assert not is_bridged('/parameter_events')
    assert not is_bridged('/_hidden/topic') and not is_bridged('/uav1/_internal')
    assert stamp_ns(2_500_000_000, True, 99) == 2_500_000_000
    assert stamp_ns(None, True, 99) == 0  # simulated time before the first /clock
    assert stamp_ns(2_500_000_000, False, 99) == 99


# -- the layout ---------------------------------------------------------------------------------
def _field_type(message_class, path: str) -> object:
    """Follow `a.b[2].c` through a message class's fields; the final field's ROS type name."""
    instance = message_class()
    kind = None
    for part in path.split('.'):
        name, _, index = part.partition('[')
        fields = instance.get_fields_and_field_types()
        assert name in fields, f'{message_class.__name__} has no field {name}'
        kind = fields[name]
        value = getattr(instance, name)
        if index:
            assert kind.startswith('sequence<') or kind.endswith(']'), kind
        elif hasattr(value, 'get_fields_and_field_types'):
            instance = value
    return kind


def _check_layout(layout: dict, scenario) -> set[str]:
    """The layout shows every panel once, the 3D panel follows world with markers and /tf, and
    every plotted series is a real numeric field plotted against its header stamp; the
    plotted topics."""
    from multilift_msgs.msg import AttitudeSetpoint, TrackingReference, VirtualConstraintError
    panels = layout['configById']

    def leaves(node) -> list[str]:
        if isinstance(node, str):
            return [node]
        return leaves(node['first']) + leaves(node['second'])

    assert sorted(leaves(layout['layout'])) == sorted(panels)
    three_d = [p for key, p in panels.items() if key.startswith('3D!')]
    assert len(three_d) == 1
    assert three_d[0]['followTf'] == 'world'
    assert three_d[0]['topics']['/visualization/markers']['visible'] is True
    assert three_d[0]['topics']['/tf']['visible'] is True
    plotted = set()
    for key, plot in panels.items():
        if not key.startswith('Plot!'):
            continue
        for series in plot['paths']:
            assert series['timestampMethod'] == 'headerStamp'
            topic, _, path = series['value'].partition('.')
            leaf = topic.rsplit('/', 1)[1]
            kind = {'state': FormationState, 'rotor_cmd': RotorCommand, 'odom': Odometry,
                    'reference': TrackingReference, 'attitude_setpoint': AttitudeSetpoint,
                    'formation_error': VirtualConstraintError}[leaf]
            assert _field_type(kind, path) in ('double', 'sequence<double>'), series['value']
            plotted.add(topic)
    for i, uav in enumerate(scenario.uavs, start=1):
        rotors = panels[f'Plot!rotors{i}']['paths']
        assert [s['value'] for s in rotors] == [
            f'/uav{i}/rotor_cmd.angular_velocity[{k}]' for k in range(uav.vehicle.n_rotors)]
    tensions = [s['value'] for s in panels['Plot!tensions']['paths']]
    assert tensions == [f'/formation/state.cable_tension[{k}]' for k in range(scenario.n_uavs)]
    return plotted


def test_the_shipped_layout_is_the_twin_lift_layout():
    from multilift_sim import scenario as scenario_io
    from multilift_tools.foxglove.layout import layout
    twin = scenario_io.load('twin_lift')
    shipped = json.loads((ROOT / 'docs' / 'foxglove_layout.json').read_text())
    assert shipped == json.loads(json.dumps(layout(twin)))
    assert _check_layout(shipped, twin) == {
        '/formation/state', '/uav1/rotor_cmd', '/uav2/rotor_cmd', '/uav1/reference',
        '/uav1/odom', '/uav1/attitude_setpoint', '/uav2/attitude_setpoint',
        '/uav2/formation_error'}


def test_layout_of_any_scenario_from_the_command_line(tmp_path):
    from multilift_sim import scenario as scenario_io
    path = tmp_path / 'v5.json'
    result = subprocess.run(bridge_command('--layout', str(path), 'v5'), env=ENV,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    v5 = scenario_io.load('v5')
    plotted = _check_layout(json.loads(path.read_text()), v5)
    assert {f'/uav{i}/formation_error' for i in range(2, 6)} <= plotted
    errors = json.loads(path.read_text())['configById']['Plot!formation']['paths']
    assert len(errors) == 4 * 3  # four followers, three rows each in the V
