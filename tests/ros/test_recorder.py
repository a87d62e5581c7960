"""recorder_node as a separate process: what it records, how it shuts down, what a crash leaves.

The test process publishes known messages; the recorder runs as `scripts/multilift node
multilift_sim recorder_node ...` when that script exists, else as the installed console script.
The module has a ROS domain of its own (conftest.next_domain: no other test or worker has it),
discovery on localhost only.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import time
from pathlib import Path

import pytest
import rclpy
import yaml
from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader
from mcap_ros2.decoder import DecoderFactory
from multilift_msgs.msg import RotorCommand
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosbags.highlevel import AnyReader
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Int64, String

from multilift_sim.bag import recover
from multilift_sim.bag import recording
from multilift_sim.bag.recording import LogTime, is_recordable, parse_topic_spec

from conftest import ROOT, next_domain
DOMAIN = next_domain()
LATCHED = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
DDS_ENV = {'ROS_DOMAIN_ID': str(DOMAIN), 'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST'}
OURS = ('/rec_test/int', '/rec_test/rotor_command', '/rec_test/extra')
MATCH_TIMEOUT = 20.0  # [s] Fast DDS discovery between processes can take a few seconds


def recorder_command(*ros_args: str) -> list[str]:
    wrapper = ROOT / 'scripts' / 'multilift'
    if wrapper.is_file() and os.access(wrapper, os.X_OK):
        command = [str(wrapper), 'node', 'multilift_sim', 'recorder_node']
    else:
        command = [str(ROOT / 'ros_ws' / 'install' / 'multilift_sim' / 'lib' / 'multilift_sim'
                       / 'recorder_node')]
    return ['bash', '-c', f'source "{ROOT}/scripts/env.sh" && exec "$@"', 'bash',
            *command, '--ros-args', *ros_args]


@pytest.fixture
def start_recorder(tmp_path):
    """Start recorder processes (own process group each); kill what is left at teardown."""
    started: list[subprocess.Popen] = []
    env = dict(os.environ, **DDS_ENV)

    def start(*ros_args: str) -> subprocess.Popen:
        log = open(tmp_path / f'recorder{len(started)}.log', 'w+')
        process = subprocess.Popen(recorder_command(*ros_args), env=env, stdout=log,
                                   stderr=subprocess.STDOUT, start_new_session=True)
        process.log = log
        started.append(process)
        return process

    yield start
    for process in started:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
        process.log.close()


def start_wall_recorder(start_recorder, bag_dir: Path, *specs: str) -> subprocess.Popen:
    """A recorder of only the topics `specs` ('/topic|pkg/msg/Type') into bag_dir, logging wall
    time and finishing a chunk every 0.2 s."""
    topics = ', '.join(f"'{spec}'" for spec in specs)
    return start_recorder('-p', f'bag:={bag_dir}', '-p', 'all:=false',
                          '-p', 'time_source:=wall', '-p', 'flush_period:=0.2',
                          '-p', f'topics:=[{topics}]')


def stop(process: subprocess.Popen, signum: int, timeout: float = 15.0) -> int:
    os.killpg(process.pid, signum)
    code = process.wait(timeout=timeout)
    process.log.seek(0)
    print(process.log.read())
    return code


@pytest.fixture(scope='module')
def ros():
    """A node of the test process on domain DOMAIN, and a spin helper."""
    with pytest.MonkeyPatch.context() as patch:
        for key, value in DDS_ENV.items():
            patch.setenv(key, value)
        context = rclpy.Context()
        rclpy.init(context=context, domain_id=DOMAIN)
        node = rclpy.create_node('recorder_test', context=context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)

        def spin_until(condition, timeout: float = MATCH_TIMEOUT) -> bool:
            end = time.monotonic() + timeout
            while time.monotonic() < end:
                if condition():
                    return True
                executor.spin_once(timeout_sec=0.05)
            return condition()

        def spin_for(seconds: float) -> None:
            spin_until(lambda: False, seconds)

        yield node, spin_until, spin_for
        executor.shutdown()
        node.destroy_node()
        context.try_shutdown()


@pytest.fixture
def publish(ros):
    """Create publishers on the test node; they are destroyed after the test (no stale /clock)."""
    node = ros[0]
    created = []

    def make(msg_type, topic: str, qos: QoSProfile = LATCHED):
        created.append(node.create_publisher(msg_type, topic, qos))
        return created[-1]

    yield make
    for publisher in created:
        node.destroy_publisher(publisher)


def _rotor(i: int) -> RotorCommand:
    msg = RotorCommand(angular_velocity=[100.0 + i, 200.0, 300.0 - i, 0.5 * i],
                       saturated=[i % 2 == 0, False, False, i % 5 == 0])
    msg.header.frame_id = 'uav1/base_link'
    msg.header.stamp.sec = i
    return msg


def _on_disk(bag_dir: Path, topic: str) -> list:
    """Decoded messages of `topic` in the (maybe unfinished) MCAP, read front to back."""
    values = []
    try:
        with open(next(bag_dir.glob('*.mcap')), 'rb') as stream:
            reader = NonSeekingReader(stream, decoder_factories=[DecoderFactory()])
            for _, channel, _, msg in reader.iter_decoded_messages(log_time_order=False):
                if channel.topic == topic:
                    values.append(msg)
    except (McapError, StopIteration):
        pass  # no file yet, or it ends without summary and footer: the recorder is running
    return values


def _log_times(bag_dir: Path, topic: str) -> list[int]:
    """Log times [ns] of `topic` in the (maybe unfinished) MCAP, in file order."""
    times = []
    try:
        with open(next(bag_dir.glob('*.mcap')), 'rb') as stream:
            for _, channel, message in NonSeekingReader(stream).iter_messages(
                    log_time_order=False):
                if channel.topic == topic:
                    times.append(message.log_time)
    except (McapError, StopIteration):
        pass  # no file yet, or it ends without summary and footer: the recorder is running
    return times


def _read(bag_dir: Path) -> dict[str, list]:
    """topic -> [(log_time, message)] of a bag, via rosbags."""
    result: dict[str, list] = {}
    with AnyReader([bag_dir]) as reader:
        for connection, log_time, raw in reader.messages():
            result.setdefault(connection.topic, []).append(
                (log_time, reader.deserialize(raw, connection.msgtype)))
    return result


def test_sigint_records_exactly_what_was_published(ros, publish, start_recorder, tmp_path):
    node, spin_until, spin_for = ros
    n = 200
    bag_dir = tmp_path / 'bag'
    recorder = start_recorder(
        '-p', f'bag:={bag_dir}', '-p', 'flush_period:=0.2', '-p', 'time_source:=sim',
        '-p', "topics:=['/rec_test/int|std_msgs/msg/Int64',"
              " '/rec_test/rotor_command|multilift_msgs/msg/RotorCommand']")
    test_pub = publish(Int64, '/rec_test/int')
    rotor_pub = publish(RotorCommand, '/rec_test/rotor_command')
    extra_pub = publish(String, '/rec_test/extra')  # found by `all`
    probe_pub = publish(String, '/rec_test/probe')  # found by `all` too
    clock_pub = publish(Clock, '/clock', QoSProfile(depth=10))
    assert spin_until(lambda: all(pub.get_subscription_count() >= 1 for pub in (
        test_pub, rotor_pub, extra_pub, probe_pub, clock_pub))), 'recorder never matched'
    clock = Clock()
    clock.clock.sec = 5  # simulated time of this whole run [s]
    clock_pub.publish(clock)
    # The recorder uses the clock once a probe published after it is logged at t = 5 s:
    # probes one at a time until one is (the /clock and probe readers are independent).
    probes = 0

    def clock_in_effect() -> bool:
        nonlocal probes
        times = _log_times(bag_dir, '/rec_test/probe')
        if len(times) < probes:
            return False  # the last probe is not on disk yet
        if times and times[-1] == 5_000_000_000:
            return True
        probe_pub.publish(String(data=f'probe {probes}'))
        probes += 1
        return False
    assert spin_until(clock_in_effect), 'the recorder never logged at the /clock time'
    for i in range(n):
        test_pub.publish(Int64(data=1000 + i))
        rotor_pub.publish(_rotor(i))
        extra_pub.publish(String(data=f'extra {i}'))
    # Discovery may still be under way on the recorder's side: wait until it has it all.
    assert spin_until(lambda: all(len(_on_disk(bag_dir, t)) >= n for t in OURS))
    assert stop(recorder, signal.SIGINT) == 0

    info = yaml.safe_load((bag_dir / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    counts = {t['topic_metadata']['name']: t['message_count']
              for t in info['topics_with_message_count']}
    assert {topic: counts[topic] for topic in OURS} == {topic: n for topic in OURS}
    assert '/rosout' not in counts and '/parameter_events' not in counts
    assert info['message_count'] == sum(counts.values())
    topics = {t['topic_metadata']['name']: t['topic_metadata']
              for t in info['topics_with_message_count']}
    offered = topics['/rec_test/rotor_command']['offered_qos_profiles']
    assert [(q['reliability'], q['durability']) for q in offered] == [
        ('reliable', 'transient_local')]
    endpoint = node.get_publishers_info_by_topic('/rec_test/rotor_command')[0]
    assert topics['/rec_test/rotor_command']['type_description_hash'] == str(
        endpoint.topic_type_hash)

    got = _read(bag_dir)
    assert [m.data for _, m in got['/rec_test/int']] == [1000 + i for i in range(n)]
    assert [m.data for _, m in got['/rec_test/extra']] == [f'extra {i}' for i in range(n)]
    for i, (_, msg) in enumerate(got['/rec_test/rotor_command']):
        ref = _rotor(i)
        assert list(msg.angular_velocity) == list(ref.angular_velocity)
        assert list(msg.saturated) == list(ref.saturated)
        assert (msg.header.stamp.sec, msg.header.frame_id) == (i, 'uav1/base_link')
    # Log time is the simulated time of the latest /clock message.
    assert {t for topic in OURS for t, _ in got[topic]} == {5_000_000_000}


def test_sigterm_closes_the_bag_with_wall_times(ros, publish, start_recorder, tmp_path):
    _, spin_until, _ = ros
    bag_dir = tmp_path / 'wall'
    recorder = start_wall_recorder(start_recorder, bag_dir, '/rec_test/wall|std_msgs/msg/Int64')
    pub = publish(Int64, '/rec_test/wall')
    assert spin_until(lambda: pub.get_subscription_count() >= 1), 'recorder never matched'
    before = time.time_ns()
    for i in range(50):
        pub.publish(Int64(data=i))
    assert spin_until(lambda: len(_on_disk(bag_dir, '/rec_test/wall')) >= 50)
    after = time.time_ns()
    assert stop(recorder, signal.SIGTERM) == 0
    got = _read(bag_dir)
    assert [m.data for _, m in got['/rec_test/wall']] == list(range(50))
    assert all(before <= t <= after for t, _ in got['/rec_test/wall'])
    # publish_time: the sender's source timestamp, as rosbag2 stores it.
    with open(next(bag_dir.glob('*.mcap')), 'rb') as stream:
        sent = [m.publish_time for _, _, m in make_reader(stream).iter_messages()]
    assert len(sent) == 50 and all(before <= t <= after for t in sent)


def test_sigkill_keeps_every_finished_chunk(ros, publish, start_recorder, tmp_path):
    """Crash safety: what was on disk (every finished chunk) stays readable after SIGKILL."""
    _, spin_until, _ = ros
    n = 300
    bag_dir = tmp_path / 'killed'
    recorder = start_wall_recorder(start_recorder, bag_dir,
                                   '/rec_test/kill|multilift_msgs/msg/RotorCommand')
    pub = publish(RotorCommand, '/rec_test/kill')
    assert spin_until(lambda: pub.get_subscription_count() >= 1), 'recorder never matched'
    for i in range(n):
        pub.publish(_rotor(i))
    # Everything the recorder received is on disk within flush_period (0.2 s) of receipt.
    assert spin_until(lambda: len(_on_disk(bag_dir, '/rec_test/kill')) >= n)
    stop(recorder, signal.SIGKILL)
    assert not (bag_dir / 'metadata.yaml').exists()
    assert [list(m.angular_velocity) for m in _on_disk(bag_dir, '/rec_test/kill')] == [
        list(_rotor(i).angular_velocity) for i in range(n)]

    assert recover(bag_dir, tmp_path / 'recovered') == n
    got = _read(tmp_path / 'recovered')
    assert [list(m.saturated) for _, m in got['/rec_test/kill']] == [
        list(_rotor(i).saturated) for i in range(n)]


def test_a_burst_waiting_for_a_stalled_recorder_is_recorded_whole(ros, publish, start_recorder,
                                                                   tmp_path):
    """A recorder held up (SIGSTOP: a starved process) while a publisher that keeps its
    history sends a burst, then let go, receives the burst at once: its readers keep
    RECORD_QOS_DEPTH messages per topic until a round takes them, so none is lost (with
    1,000 it kept 2,026 of the 6,001: the likely cause of a CI run's window bag missing 2 of
    its 10,001 /uav1/odom messages)."""
    _, spin_until, _ = ros
    n = 6000
    bag_dir = tmp_path / 'burst'
    recorder = start_wall_recorder(start_recorder, bag_dir, '/rec_test/burst|std_msgs/msg/Int64')
    keeps_all = QoSProfile(depth=n, reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)
    pub = publish(Int64, '/rec_test/burst', keeps_all)
    assert spin_until(lambda: pub.get_subscription_count() >= 1), 'recorder never matched'
    pub.publish(Int64(data=-1))
    assert spin_until(lambda: len(_on_disk(bag_dir, '/rec_test/burst')) == 1)
    os.killpg(recorder.pid, signal.SIGSTOP)
    try:
        for i in range(n):
            pub.publish(Int64(data=i))
    finally:
        os.killpg(recorder.pid, signal.SIGCONT)
    assert spin_until(lambda: len(_on_disk(bag_dir, '/rec_test/burst')) >= n + 1, 60.0), \
        f'{len(_on_disk(bag_dir, "/rec_test/burst"))} of {n + 1} recorded'
    assert stop(recorder, signal.SIGINT) == 0
    assert [m.data for _, m in _read(bag_dir)['/rec_test/burst']] == list(range(-1, n))


def test_a_topic_whose_publisher_sent_nothing_is_named_at_the_close(ros, publish,
                                                                     start_recorder, tmp_path):
    """A topic that had a publisher but no message reached the recorder: the bag has it
    without messages, and the recorder says so (`multilift run` repeats its warnings)."""
    _, spin_until, _ = ros
    bag_dir = tmp_path / 'quiet'
    recorder = start_wall_recorder(start_recorder, bag_dir, '/rec_test/loud|std_msgs/msg/Int64',
                                   '/rec_test/quiet|std_msgs/msg/Int64')
    loud, quiet = publish(Int64, '/rec_test/loud'), publish(Int64, '/rec_test/quiet')
    assert spin_until(lambda: loud.get_subscription_count() >= 1
                      and quiet.get_subscription_count() >= 1), 'recorder never matched'
    loud.publish(Int64(data=7))
    assert spin_until(lambda: len(_on_disk(bag_dir, '/rec_test/loud')) == 1)
    assert stop(recorder, signal.SIGINT) == 0
    recorder.log.seek(0)
    warnings = [line for line in recorder.log.read().splitlines()
                if line.startswith('warning:')]
    assert len(warnings) == 1
    # how many the recorder's reader had matched depends on discovery on its side: 0 or 1
    assert re.fullmatch(r'warning: recorder: /rec_test/quiet had 1 publisher\(s\) \([01] matched '
                        r'by the recorder\) but no message of it arrived; the bag has the topic '
                        r'without messages', warnings[0]), warnings
    info = yaml.safe_load((bag_dir / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    counts = {t['topic_metadata']['name']: t['message_count']
              for t in info['topics_with_message_count']}
    assert counts == {'/rec_test/loud': 1, '/rec_test/quiet': 0}


def test_refuses_an_existing_bag_directory(start_recorder, tmp_path):
    bag_dir = tmp_path / 'taken'
    bag_dir.mkdir()
    (bag_dir / 'metadata.yaml').write_text('not ours')
    recorder = start_recorder('-p', f'bag:={bag_dir}')
    assert recorder.wait(timeout=30) == 2
    recorder.log.seek(0)
    assert 'already exists and is not empty' in recorder.log.read()
    assert (bag_dir / 'metadata.yaml').read_text() == 'not ours'


def test_log_time_base_is_chosen_once():
    wall = iter(range(1000, 2000))
    auto = LogTime('auto', wall_ns=lambda: next(wall))
    assert auto.stamp(lambda: True) == 0  # /clock published, no message yet: ROS time 0
    auto.on_clock(7_000_000_000)
    assert auto.stamp(lambda: False) == 7_000_000_000 and auto.base == 'sim'
    no_clock = LogTime('auto', wall_ns=lambda: next(wall))
    assert no_clock.stamp(lambda: False) == 1000
    no_clock.on_clock(5)  # a /clock that appears later does not switch clocks mid-bag
    assert no_clock.stamp(lambda: True) == 1001 and no_clock.base == 'wall'
    heard = LogTime('auto', wall_ns=lambda: next(wall))
    heard.on_clock(3)
    assert heard.stamp(lambda: False) == 3
    assert LogTime('wall', wall_ns=lambda: 42).stamp(lambda: True) == 42
    with pytest.raises(ValueError, match='time source'):
        LogTime('gps')


def test_sim_log_time_is_the_clock_sent_before_the_message():
    """Messages are stamped by send time, whenever they are read (out-of-order clocks too)."""
    log_time = LogTime('sim')
    assert log_time.stamp(lambda: True, 50) == 0  # no /clock yet: ROS time 0
    for sim_ns, sent_ns in ((0, 100), (10, 200), (20, 300)):
        log_time.on_clock(sim_ns, sent_ns)
    clocks = lambda: True  # noqa: E731
    assert [log_time.stamp(clocks, sent) for sent in (50, 100, 199, 200, 250, 999)] == \
        [0, 0, 0, 10, 10, 20]
    assert log_time.stamp(clocks) == 20  # no send time: the latest clock received
    log_time.on_clock(15, 250)  # a /clock read after a later one
    assert log_time.stamp(clocks, 260) == 15 and log_time.stamp(clocks, 300) == 20


def test_sim_log_time_remembers_the_newest_forgotten_clock():
    log_time = LogTime('sim')
    for k in range(3 * recording.CLOCK_MEMORY):
        log_time.on_clock(10 * k, 1000 + k)
    assert log_time.stamp(lambda: True, 1000 + 3 * recording.CLOCK_MEMORY - 1) == \
        10 * (3 * recording.CLOCK_MEMORY - 1)
    oldest = log_time.stamp(lambda: True, 0)  # sent before every clock still kept
    assert 0 < oldest < 10 * (3 * recording.CLOCK_MEMORY - recording.CLOCK_MEMORY)


def test_topic_specs_and_recordable_topics():
    assert parse_topic_spec(' /uav1/odom | nav_msgs/Odometry ') == (
        '/uav1/odom', 'nav_msgs/msg/Odometry')
    for bad in ('/uav1/odom', 'uav1/odom|nav_msgs/msg/Odometry', '/a|not a type'):
        with pytest.raises(ValueError, match='topic spec'):
            parse_topic_spec(bad)
    assert is_recordable('/clock') and is_recordable('/uav1/odom')
    assert not is_recordable('/rosout') and not is_recordable('/parameter_events')
    assert not is_recordable('/_hidden/x') and not is_recordable('/a/_action/status')
