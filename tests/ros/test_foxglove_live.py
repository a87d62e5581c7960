"""The live view of a whole run: a Foxglove WebSocket client connected to `multilift foxglove`
before `multilift run` starts subscribes to every channel as soon as it is advertised (as the
app does) and decodes every message with the channel's ros2msg schema (mcap_ros2's dynamic
decoder, not our message classes). It must receive every message the run recorded, each with its
header stamp as its time, and never be refused a subscription; the server's time follows /clock.
At full speed and with --realtime, and for runs so short at full speed (a few simulated seconds,
about a second of the nodes' wall time) that only the bridge's graph events let it subscribe
while the publishers live: such a run too is forwarded from its first message.
"""
from __future__ import annotations

import json
import os
import signal
import socket
import struct
import subprocess
import threading
import time
from collections import defaultdict
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2._dynamic import generate_dynamic
from mcap_ros2.decoder import DecoderFactory
from websockets.sync.client import connect

ROOT = Path(__file__).resolve().parents[2]
MULTILIFT = ROOT / 'scripts' / 'multilift'
TIMEOUT = 60.0  # [s] for the bridge, the run and the last messages on a loaded machine


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


class Client:
    """A Foxglove WebSocket client in a thread: subscribes to every advertised channel at once,
    decodes messages with the advertised schema."""

    def __init__(self, port: int) -> None:
        deadline = time.monotonic() + TIMEOUT
        while True:
            try:
                self.ws = connect(f'ws://127.0.0.1:{port}',
                                  subprotocols=['foxglove.websocket.v1'], max_size=None)
                break
            except OSError:
                assert time.monotonic() < deadline, 'the bridge does not accept connections'
                time.sleep(0.2)
        self.info = json.loads(self.ws.recv(timeout=TIMEOUT))
        self.channels: dict[int, dict] = {}
        self.decoders: dict[int, object] = {}
        self.by_sub: dict[int, int] = {}
        self.messages: dict[str, list] = defaultdict(list)  # topic -> [(log_time, message)]
        self.times: list[int] = []
        self.errors: list[str] = []
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            for frame in self.ws:
                if isinstance(frame, str):
                    self._on_json(json.loads(frame))
                elif frame[0] == 0x01:
                    sub_id, log_time = struct.unpack_from('<IQ', frame, 1)
                    channel = self.channels[self.by_sub[sub_id]]
                    decoded = self.decoders[channel['id']](frame[13:])
                    self.messages[channel['topic']].append((log_time, decoded))
                elif frame[0] == 0x02:
                    self.times.append(struct.unpack_from('<Q', frame, 1)[0])
        except Exception:  # noqa: BLE001 - the connection closed at teardown
            pass

    def _on_json(self, message: dict) -> None:
        if message['op'] == 'advertise':
            subscriptions = []
            for channel in message['channels']:
                self.channels[channel['id']] = channel
                self.decoders[channel['id']] = generate_dynamic(
                    channel['schemaName'], channel['schema'])[channel['schemaName']]
                self.by_sub[channel['id']] = channel['id']
                subscriptions.append({'id': channel['id'], 'channelId': channel['id']})
            self.ws.send(json.dumps({'op': 'subscribe', 'subscriptions': subscriptions}))
        elif message['op'] == 'status' and message.get('level', 0) >= 2:
            self.errors.append(message['message'])

    def close(self) -> None:
        self.ws.close()
        self.thread.join(timeout=10)


def recorded_counts(bag: Path) -> dict[str, int]:
    [path] = bag.glob('*.mcap')
    with open(path, 'rb') as stream:
        summary = make_reader(stream).get_summary()
    return {summary.channels[cid].topic: n
            for cid, n in summary.statistics.channel_message_counts.items()}


def recorded_stamps(bag: Path) -> dict[str, list[int]]:
    """topic -> the sorted stamps (`stamp`) of the bag's messages that have one."""
    [path] = bag.glob('*.mcap')
    stamps: dict[str, list[int]] = defaultdict(list)
    with open(path, 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, channel, _, message in reader.iter_decoded_messages():
            own = stamp(message)
            if own is not None:
                stamps[channel.topic].append(own)
    return {topic: sorted(values) for topic, values in stamps.items()}


def stamp(message) -> int | None:
    """The stamp the bridge should use: header, Clock, first element of an array."""
    if hasattr(message, 'header'):
        s = message.header.stamp
    elif hasattr(message, 'clock'):
        s = message.clock
    elif getattr(message, 'transforms', None):
        s = message.transforms[0].header.stamp
    elif getattr(message, 'markers', None):
        s = message.markers[0].header.stamp
    else:
        return None
    return s.sec * 1_000_000_000 + s.nanosec


@pytest.fixture
def ros_env(multilift_domain) -> dict:
    """The test's own domain (multilift_domain: conftest's, next_domain), so no
    other run on this machine shows up in the bridge."""
    return dict(os.environ)


@pytest.fixture
def bridge(tmp_path, ros_env):
    port = free_port()
    log = open(tmp_path / 'bridge.log', 'w+')
    process = subprocess.Popen([str(MULTILIFT), 'foxglove', '--port', str(port)], env=ros_env,
                               stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                               start_new_session=True)
    client = Client(port)
    yield client, tmp_path / 'bridge.log', process
    client.close()
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
        process.wait(timeout=30)
    log.close()


def run_and_check(client, log: Path, process, ros_env: dict, bag: Path, scenario: str,
                  duration: float, pace: list[str], record: bool = True) -> None:
    """`multilift run` with `bag` (else without a recorder, and `bag` is the run's reference:
    the same run headless); the client must get every message the bag has, each with its own
    stamp, and the server's time must follow /clock."""
    assert client.info['metadata']['ROS_DISTRO'] == 'jazzy'
    assert 'time' in client.info['capabilities']
    if not record:
        reference = subprocess.run([str(MULTILIFT), 'run', scenario, '--headless', '--duration',
                                    str(duration), '--bag', str(bag)], env=ros_env,
                                   capture_output=True, text=True, timeout=300)
        assert reference.returncode == 0, reference.stdout + reference.stderr
    run = subprocess.run([str(MULTILIFT), 'run', scenario, '--duration', str(duration),
                          *(['--bag', str(bag)] if record else []), *pace], env=ros_env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    expected = recorded_counts(bag)
    assert '/tf' in expected
    deadline = time.monotonic() + TIMEOUT
    while any(len(client.messages[t]) < n for t, n in expected.items()):
        assert time.monotonic() < deadline, (
            {t: (len(client.messages[t]), n) for t, n in expected.items()
             if len(client.messages[t]) != n}, log.read_text()[-3000:])
        assert process.poll() is None, log.read_text()
        time.sleep(0.1)
    assert client.errors == []
    for topic, n in expected.items():
        got = client.messages[topic]
        assert len(got) == n, topic
        for log_time, message in got:
            own = stamp(message)
            if own is not None:
                assert log_time == own, topic
    clock = [log_time for log_time, _ in client.messages['/clock']]
    assert clock == sorted(clock) and clock[-1] == int(duration * 1e9)
    simulated = [t for t in client.times if t <= int(duration * 1e9)]  # else wall time
    assert simulated and simulated == sorted(simulated)
    assert 'dropped' not in log.read_text()


# Long enough that discovery by polling, as the bridge once did, mostly saw the nodes while they
# lived, and short enough that the publishers' kept history (1000 messages) covers the run.
@pytest.mark.parametrize('scenario, duration, pace', [('twin_lift', 9.5, []),
                                                      ('single_lift', 5.0, ['--realtime'])])
def test_a_client_gets_every_message_of_a_run_with_its_stamp(bridge, ros_env, tmp_path,
                                                             scenario, duration, pace):
    client, log, process = bridge
    run_and_check(client, log, process, ros_env, tmp_path / 'bag', scenario, duration, pace)


# Full speed, a few simulated seconds: the nodes publish for a fraction of a second to a second of
# wall time, the shortest without a recorder (nothing waits for one before t = 0): less than the
# bridge's old 0.5 s poll needed to see every node. Without a recorder the reference is the same
# run headless (tests/ros/test_headless.py: the same topics and counts).
@pytest.mark.parametrize('scenario, duration, record', [('single_lift', 3.0, False),
                                                        ('twin_lift', 2.0, True)])
def test_a_short_full_speed_run_is_forwarded_from_its_first_message(bridge, ros_env, tmp_path,
                                                                    scenario, duration, record):
    client, log, process = bridge
    bag = tmp_path / 'bag'
    run_and_check(client, log, process, ros_env, bag, scenario, duration, [], record)
    # the same messages as the bag from the first on: every stamp, the first /clock at 0
    for topic, stamps in recorded_stamps(bag).items():
        got = sorted(stamp(message) for _, message in client.messages[topic])
        assert got == stamps, (topic, got[:3], stamps[:3])
    assert client.messages['/clock'][0][0] == 0


def test_a_client_s_goal_is_published_and_a_live_run_flies_it(bridge, ros_env, tmp_path):
    """Capability clientPublish (issue 34: live goals through `multilift foxglove`): a client
    advertises /formation/goal (cdr, geometry_msgs/msg/PoseStamped) and sends one; the leader of
    a `run --live` flies it and the bag has it."""
    from geometry_msgs.msg import PoseStamped
    from rclpy.serialization import serialize_message

    from conftest import started_run, wait_for
    from multilift_tools.bagdata import load_run
    client, _, _ = bridge
    assert 'clientPublish' in client.info['capabilities']
    assert client.info['supportedEncodings'] == ['cdr']
    bag = tmp_path / 'bag'
    with started_run(['single_lift', '--live', '--realtime', '--duration', '20', '--bag',
                      str(bag)], ros_env) as (run, work):
        client.ws.send(json.dumps({'op': 'advertise', 'channels': [{
            'id': 7, 'topic': '/formation/goal', 'encoding': 'cdr',
            'schemaName': 'geometry_msgs/msg/PoseStamped'}]}))
        goal = PoseStamped()
        goal.header.frame_id = 'world'
        goal.header.stamp.sec = 3
        goal.pose.position.x, goal.pose.position.y, goal.pose.position.z = 0.3, 0.2, 0.4
        frame = struct.pack('<BI', 0x01, 7) + serialize_message(goal)
        log = work / 'leader_node.log'

        def taken() -> bool:  # sent again until the leader has it (the same goal, taken once)
            client.ws.send(frame)
            return log.exists() and 'goal flown from t = ' in log.read_text()
        wait_for(taken, TIMEOUT, 'the leader flying the client\'s goal', poll=0.5)
        _, err = run.communicate(timeout=300)
    assert run.returncode == 0, err[-2000:]
    assert not client.errors
    flown = load_run(bag)
    assert abs(flown.reference_position()[-1] - [0.3, 0.2, 0.4]).max() < 1e-9
    assert recorded_counts(bag)['/formation/goal'] >= 1
