"""`multilift bag info|play|reindex` (bag_tools) and `multilift topic hz` (topic_tools).

Bags to start from are built with BagWriter (deterministic, fast) or recorded by a real
`scripts/multilift run`; the tools run as separate processes (`scripts/multilift bag ...` once
cli.py dispatches to bag_tools, else bag_main directly) on a ROS domain of this module's own
(conftest.next_domain), discovery on localhost only. Every process is started in a session of
its own and killed (its whole group) at teardown, also when a test fails.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import time
from pathlib import Path

import pytest
import yaml
from builtin_interfaces.msg import Time
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from multilift_msgs.msg import FormationState
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosbags.highlevel import AnyReader
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String

from multilift_sim.bag import BagWriter
from multilift_tools.bags.play import (CLOCK_TOPIC, PlayEvent, play_events, playback_qos_policies,
                                      wall_offset)
from multilift_tools.bags.summary import format_file_size, read_summary
from multilift_sim.bag.metadata_yaml import OfferedQos, qos_yaml
from multilift_tools.topic_tools import RateWindow, format_hz
from multilift_sim.topics import run_topics

from conftest import ROOT, next_domain
MULTILIFT = ROOT / 'scripts' / 'multilift'
DOMAIN = next_domain()
ENV = dict(os.environ, ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
           TZ='UTC', PYTHONUNBUFFERED='1')
LATCHED = qos_yaml([OfferedQos()])  # reliable + transient_local, as our nodes offer
PERIOD_NS = 10_000_000  # [ns] the synthetic bag's /clock and odometry period (100 Hz)
DURATION_NS = 3_000_000_000  # [ns] the synthetic bag's length
LABEL = 'hello multilift: a latched label'


def command(tool: str, *args: str) -> list[str]:
    """argv of `multilift bag|topic|foxglove ...`."""
    return [str(MULTILIFT), tool, *args]


@pytest.fixture
def spawn(tmp_path):
    """Start processes in sessions of their own, output to a log file each; at teardown every
    one still running is killed with its process group."""
    started: list[subprocess.Popen] = []

    def start(argv: list[str], name: str) -> subprocess.Popen:
        log = open(tmp_path / f'{name}.log', 'w+')
        process = subprocess.Popen(argv, env=ENV, stdout=log, stderr=subprocess.STDOUT,
                                   stdin=subprocess.DEVNULL, start_new_session=True)
        process.log = log
        started.append(process)
        return process

    yield start
    for process in started:
        if process.poll() is None:
            try:
                os.killpg(process.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        process.wait(timeout=10)
        process.log.close()


def output(process: subprocess.Popen) -> str:
    process.log.flush()
    process.log.seek(0)
    return process.log.read()


def wait_for_text(process: subprocess.Popen, text: str, timeout: float = 30.0) -> str:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        seen = output(process)
        if text in seen:
            return seen
        assert process.poll() is None, f'exited {process.returncode} before {text!r}:\n{seen}'
        time.sleep(0.1)
    raise AssertionError(f'no {text!r} within {timeout} s:\n{output(process)}')


def wait_for_subscriptions(topic: str, count: int, process: subprocess.Popen,
                           timeout: float = 30.0) -> None:
    """Wait until `topic` has `count` subscriptions in the graph (seen by a node of this
    process on the tools' domain)."""
    import rclpy
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    node = rclpy.create_node('bag_tools_test_graph', context=context,
                             start_parameter_services=False)
    try:
        deadline = time.monotonic() + timeout
        while node.count_subscribers(topic) < count:
            assert process.poll() is None, output(process)
            assert time.monotonic() < deadline, f'{topic}: {node.count_subscribers(topic)} ' \
                f'subscriptions after {timeout} s'
            time.sleep(0.05)
    finally:
        node.destroy_node()
        context.try_shutdown()


def run_tool(tool: str, *args: str, timeout: float = 60.0) -> subprocess.CompletedProcess:
    return subprocess.run(command(tool, *args), env=ENV, capture_output=True, text=True,
                          timeout=timeout)


# -- a deterministic bag ------------------------------------------------------------------------
def _odometry(t_ns: int) -> Odometry:
    msg = Odometry()
    msg.header.stamp = Time(sec=t_ns // 1_000_000_000, nanosec=t_ns % 1_000_000_000)
    msg.header.frame_id = 'world'
    msg.child_frame_id = 'payload'
    msg.pose.pose.position.x = 0.5 * t_ns * 1e-9
    msg.pose.pose.position.z = -10.0 + 1e-3 * (t_ns // PERIOD_NS)
    msg.pose.pose.orientation.w = 1.0
    return msg


def _formation(t_ns: int) -> FormationState:
    msg = FormationState(cable_tension=[4.0 + t_ns * 1e-9, 3.5], constraint_position=[1e-6, 0.0],
                         constraint_velocity=[0.0, -1e-5])
    msg.header.stamp = Time(sec=t_ns // 1_000_000_000, nanosec=t_ns % 1_000_000_000)
    msg.header.frame_id = 'world'
    return msg


def make_bag(directory: Path) -> dict[str, list[tuple[int, bytes]]]:
    """A 3 s bag on simulated time: /clock and /payload/odom at 100 Hz, /formation/state at
    50 Hz, one latched std_msgs/String. Returns topic -> [(log time [ns], CDR bytes)]."""
    written: dict[str, list[tuple[int, bytes]]] = {}
    with BagWriter(directory, chunk_size=16 * 1024) as bag:
        bag.add_topic(CLOCK_TOPIC, 'rosgraph_msgs/msg/Clock', LATCHED)
        bag.add_topic('/payload/odom', 'nav_msgs/msg/Odometry', LATCHED)
        bag.add_topic('/formation/state', 'multilift_msgs/msg/FormationState', LATCHED)
        bag.add_topic('/test/label', 'std_msgs/msg/String', LATCHED)

        def write(topic: str, msg, t_ns: int) -> None:
            data = serialize_message(msg)
            # as it comes out of DDS, so as rosbag2 and our recorder store it: Fast DDS pads a
            # serialized payload with zeros to a multiple of 4 bytes, rclpy's serializer does not
            data += bytes(-len(data) % 4)
            bag.write(topic, data, t_ns, 1_700_000_000_000_000_000 + t_ns)
            written.setdefault(topic, []).append((t_ns, data))

        for k in range(DURATION_NS // PERIOD_NS + 1):
            t = k * PERIOD_NS
            write(CLOCK_TOPIC, Clock(clock=Time(sec=t // 1_000_000_000,
                                                nanosec=t % 1_000_000_000)), t)
            if k == 0:
                write('/test/label', String(data=LABEL), t)
            write('/payload/odom', _odometry(t), t)
            if k % 2 == 0:
                write('/formation/state', _formation(t), t)
    return written


@pytest.fixture(scope='module')
def synthetic_bag(tmp_path_factory):
    directory = tmp_path_factory.mktemp('bags') / 'synthetic'
    return directory, make_bag(directory)


# -- info ---------------------------------------------------------------------------------------
def test_info_prints_ros2_bag_info_layout(synthetic_bag):
    directory, written = synthetic_bag
    result = run_tool('bag', 'info', str(directory))
    assert result.returncode == 0, result.stderr
    size = sum(p.stat().st_size for p in directory.iterdir())
    assert 1024 <= size < 1024 ** 2
    total = sum(len(v) for v in written.values())
    assert total == 301 + 301 + 151 + 1
    pad = ' ' * 19
    rows = [('/clock', 'rosgraph_msgs/msg/Clock', 301),
            ('/formation/state', 'multilift_msgs/msg/FormationState', 151),
            ('/payload/odom', 'nav_msgs/msg/Odometry', 301),
            ('/test/label', 'std_msgs/msg/String', 1)]
    topics = [f'Topic: {name} | Type: {kind} | Count: {count} | Serialization Format: cdr'
              for name, kind, count in rows]
    expected = '\n'.join([
        '',
        'Files:             synthetic_0.mcap',
        f'Bag size:          {size / 1024:.1f} KiB',
        'Storage id:        mcap',
        'ROS Distro:        jazzy',
        'Duration:          3.000000000s',
        'Start:             Jan  1 1970 00:00:00.000000000 (0.000000000)',
        'End:               Jan  1 1970 00:00:03.000000000 (3.000000000)',
        'Messages:          754',
        'Topic information: ' + topics[0],
        *[pad + row for row in topics[1:]],
        'Service:           0',
        'Service information: ',
        '']) + '\n'  # format_bag_meta_data's text, then print()'s newline
    assert result.stdout == expected
    assert result.stderr == ''


def test_file_sizes_and_start_times_as_rosbag2_prints_them(tmp_path):
    assert format_file_size(0) == '0 B'
    assert format_file_size(1023) == '1023 B'
    assert format_file_size(1024) == '1.0 KiB'
    assert format_file_size(729_600) == '712.5 KiB'
    assert format_file_size(3 * 1024 ** 3) == '3.0 GiB'
    stamp = 1_700_000_000_123_456_789  # 2023-11-14 22:13:20.123456789 UTC
    with BagWriter(tmp_path / 'wall') as bag:
        bag.add_topic('/test/label', 'std_msgs/msg/String', LATCHED)
        bag.write('/test/label', serialize_message(String(data='a')), stamp)
        bag.write('/test/label', serialize_message(String(data='b')), stamp + 2_500_000_000)
    result = run_tool('bag', 'info', str(tmp_path / 'wall'))
    lines = result.stdout.splitlines()
    assert lines[5] == 'Duration:          2.500000000s'
    assert lines[6] == 'Start:             Nov 14 2023 22:13:20.123456789 (1700000000.123456789)'
    assert lines[7] == 'End:               Nov 14 2023 22:13:22.623456789 (1700000002.623456789)'


# -- reindex ------------------------------------------------------------------------------------
def test_reindex_repairs_a_bag_whose_writer_was_killed(tmp_path):
    """A copy of the MCAP taken while it is being written (what kill -9 leaves): no summary, no
    metadata.yaml, a torn chunk at the end. info scans it; reindex makes a complete bag."""
    source = tmp_path / 'writing'
    bag = BagWriter(source, chunk_size=4 * 1024)
    bag.add_topic('/payload/odom', 'nav_msgs/msg/Odometry', LATCHED)
    bag.add_topic('/formation/state', 'multilift_msgs/msg/FormationState', LATCHED)
    for k in range(400):
        bag.write('/payload/odom', serialize_message(_odometry(k * PERIOD_NS)), k * PERIOD_NS)
        bag.write('/formation/state', serialize_message(_formation(k * PERIOD_NS)),
                  k * PERIOD_NS)
    bag.flush()  # the recorder's periodic flush: 800 messages on disk
    killed = tmp_path / 'killed'
    killed.mkdir()
    data = bag.mcap_path.read_bytes()
    bag.close()
    # what the writer was writing when it died: the head of a 10 kB chunk record (opcode 6)
    torn = bytes([0x06]) + (10_000).to_bytes(8, 'little') + bytes(range(256)) * 2
    (killed / 'writing_0.mcap').write_bytes(data + torn)

    info = run_tool('bag', 'info', str(killed))
    assert info.returncode == 0, info.stderr
    assert 'no metadata.yaml' in info.stderr and 'bag reindex' in info.stderr
    assert 'Messages:          800\n' in info.stdout
    assert 'ROS Distro:        unknown\n' in info.stdout

    result = run_tool('bag', 'reindex', str(killed))
    assert result.returncode == 0, result.stderr
    assert 'reindexed' in result.stdout and '800 messages' in result.stdout
    assert sorted(p.name for p in killed.iterdir()) == ['metadata.yaml', 'writing_0.mcap']
    meta = yaml.safe_load((killed / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert meta['message_count'] == 800
    assert meta['relative_file_paths'] == ['writing_0.mcap']
    assert meta['duration']['nanoseconds'] == 399 * PERIOD_NS
    with open(killed / 'writing_0.mcap', 'rb') as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics.message_count == 800
        assert [m.name for m in reader.iter_metadata()] == ['rosbag2']
    with AnyReader([killed]) as reader:
        odometry = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages()
                    if c.topic == '/payload/odom']
    assert [m.pose.pose.position.z for m in odometry] == [
        _odometry(k * PERIOD_NS).pose.pose.position.z for k in range(400)]
    again = run_tool('bag', 'reindex', str(killed))  # a complete bag: nothing lost
    assert again.returncode == 0 and '800 messages' in again.stdout


def test_reindex_and_info_name_what_is_wrong(tmp_path):
    empty = tmp_path / 'empty'
    empty.mkdir()
    result = run_tool('bag', 'reindex', str(empty))
    assert result.returncode == 1
    assert 'expected one .mcap file' in result.stderr
    result = run_tool('bag', 'info', str(tmp_path / 'missing'))
    assert result.returncode == 1 and 'no such bag directory' in result.stderr
    result = run_tool('bag', 'play', str(tmp_path / 'missing'), '--rate', '0')
    assert result.returncode == 2 and '--rate must be > 0' in result.stderr


# -- play: pure parts ---------------------------------------------------------------------------
def test_play_events_merge_clock_ticks_before_messages():
    messages = [('/a', b'1', 100), ('/b', b'2', 100), ('/a', b'3', 250)]
    events = list(play_events(messages, 100, 100))
    assert [(e.time_ns, e.topic, e.data) for e in events] == [
        (100, CLOCK_TOPIC, None), (100, '/a', b'1'), (100, '/b', b'2'),
        (200, CLOCK_TOPIC, None), (250, '/a', b'3')]
    assert events == sorted(events)
    assert list(play_events(messages, 100, None)) == [
        PlayEvent(100, 0, '/a', b'1'), PlayEvent(100, 1, '/b', b'2'),
        PlayEvent(250, 2, '/a', b'3')]
    assert wall_offset(3_000_000_000, 1_000_000_000, 2.0) == pytest.approx(1.0)
    assert wall_offset(1_000_000_000, 1_000_000_000, 0.5) == 0.0


def test_playback_qos_follows_rosbag2():
    latched = {'reliability': 'reliable', 'durability': 'transient_local'}
    sensor = {'reliability': 'best_effort', 'durability': 'volatile'}
    assert playback_qos_policies([latched]) == ('reliable', 'transient_local')
    assert playback_qos_policies([latched, latched]) == ('reliable', 'transient_local')
    assert playback_qos_policies([sensor]) == ('best_effort', 'volatile')
    assert playback_qos_policies([latched, sensor]) == ('reliable', 'volatile')
    assert playback_qos_policies([]) == ('reliable', 'volatile')
    assert playback_qos_policies([{'reliability': 'system_default'}]) == ('reliable', 'volatile')


def test_rate_window_computes_as_ros2_topic_hz():
    stats = RateWindow(window=10000)
    for k in range(1, 152):  # 151 receipts 10 ms apart, one 30 ms gap
        stats.add(k * 10_000_000 + (20_000_000 if k > 100 else 0))
        if k == 2:
            assert stats.report() is None  # the first report only marks the time
    rate, low, high, std, window = stats.report()
    assert window == 150
    assert rate == pytest.approx(1e9 / ((1510 + 20 - 10) * 1e6 / 150))
    assert (low, high) == pytest.approx((0.01, 0.03))
    assert std > 0
    assert stats.report() is None  # nothing new for a second
    assert format_hz(100.0, 0.0099, 0.0101, 0.00005, 150) == (
        'average rate: 100.000\n\tmin: 0.010s max: 0.010s std dev: 0.00005s window: 150')
    small = RateWindow(window=3)
    for k in range(1, 10):
        small.add(k * 1_000_000_000)
    assert small.report() is None and len(small.intervals) == 3
    small.add(5)  # the clock went back (a new run): the window restarts
    assert small.intervals == []
    for k in range(1, 200):  # and reports come again within a second of the new clock
        small.add(5 + k * 10_000_000)
    assert small.report() is None  # marks the time
    small.add(5 + 3_000_000_000)
    assert small.report() is not None


# -- play, record again, echo, hz: separate processes -------------------------------------------
def _recorded(directory: Path) -> dict[str, list[tuple[int, bytes]]]:
    out: dict[str, list[tuple[int, bytes]]] = {}
    with open(next(directory.glob('*.mcap')), 'rb') as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=True):
            out.setdefault(channel.topic, []).append((message.log_time, message.data))
    return out


def assert_log_times_close(offsets: list[int], period_ns: int) -> None:
    """Re-recorded minus original log times [ns]: within one /clock period, but for stalls.

    The recorder stamps a message with the latest /clock it has received, which its own /clock
    subscription may deliver a tick before or after the message; when the machine stalls, the
    recorder takes the backlog of a topic in one batch, and stamps lead or trail by the stall
    (up to 0.25 s here).
    """
    within = sum(1 for d in offsets if abs(d) <= period_ns) / len(offsets)
    assert within >= 0.9, f'only {within:.0%} of log times within one /clock period'
    assert max(abs(d) for d in offsets) <= 250_000_000, (min(offsets), max(offsets))


def test_record_play_record_gives_the_same_messages(synthetic_bag, spawn, tmp_path):
    """bag play -> recorder_node: every topic's payloads byte-equal, log times within one /clock
    period; meanwhile topic echo --once prints the latched label."""
    directory, written = synthetic_bag
    again = tmp_path / 'again'
    topics = "['/clock|rosgraph_msgs/msg/Clock','/payload/odom|nav_msgs/msg/Odometry'," \
             "'/formation/state|multilift_msgs/msg/FormationState'," \
             "'/test/label|std_msgs/msg/String']"
    recorder = spawn([str(MULTILIFT), 'node', 'multilift_sim', 'recorder_node', '--ros-args',
                      '-p', f'bag:={again}', '-p', f'topics:={topics}', '-p', 'all:=false'],
                     'recorder')
    echo = spawn(command('topic', 'echo', '/test/label', 'std_msgs/msg/String', '--once'),
                 'echo')
    wait_for_text(recorder, 'recording into')
    # the player lives a few seconds: a subscriber that matches after it exited cannot get the
    # latched label from anyone, so the player starts once both readers are in the graph
    wait_for_subscriptions('/test/label', 2, echo)
    player = spawn(command('bag', 'play', str(directory), '--wait-for-subscribers'), 'play')
    assert player.wait(timeout=90) == 0, output(player)
    assert '754 messages published' in output(player)
    assert echo.wait(timeout=20) == 0, output(echo)
    assert output(echo) == f'data: "{LABEL}"\n---\n' or output(echo) == f"data: '{LABEL}'\n---\n"
    os.killpg(recorder.pid, signal.SIGINT)
    assert recorder.wait(timeout=30) == 0, output(recorder)

    recorded = _recorded(again)
    assert sorted(recorded) == sorted(written)
    offsets = []
    for topic, messages in written.items():
        got = recorded[topic]
        assert [data for _, data in got] == [data for _, data in messages], topic
        offsets += [again - first for (again, _), (first, _) in zip(got, messages)]
    assert_log_times_close(offsets, PERIOD_NS)


def test_play_selected_topics_from_an_offset_with_a_generated_clock(
        synthetic_bag, spawn, tmp_path):
    directory, written = synthetic_bag
    again = tmp_path / 'offset'
    topics = "['/clock|rosgraph_msgs/msg/Clock','/payload/odom|nav_msgs/msg/Odometry']"
    recorder = spawn([str(MULTILIFT), 'node', 'multilift_sim', 'recorder_node', '--ros-args',
                      '-p', f'bag:={again}', '-p', f'topics:={topics}', '-p', 'all:=false'],
                     'recorder')
    wait_for_text(recorder, 'recording into')
    player = spawn(command('bag', 'play', str(directory), '--topics', '/payload/odom',
                           '--start-offset', '2', '--rate', '2', '--clock-rate', '50',
                           '--wait-for-subscribers'), 'play')
    start = time.monotonic()
    assert player.wait(timeout=60) == 0, output(player)
    assert '101 messages published' in output(player)  # t = 2.00 .. 3.00 s
    assert time.monotonic() - start > 0.5  # 1 s of bag at rate 2
    os.killpg(recorder.pid, signal.SIGINT)
    assert recorder.wait(timeout=30) == 0, output(recorder)
    recorded = _recorded(again)
    assert [d for _, d in recorded['/payload/odom']] == [
        d for t, d in written['/payload/odom'] if t >= 2_000_000_000]
    clock = [t for t, _ in recorded[CLOCK_TOPIC]]
    assert len(clock) == 51  # the player's /clock: 2.00, 2.02, .. 3.00 s
    odometry = zip(recorded['/payload/odom'], written['/payload/odom'][200:])
    assert_log_times_close([again - first for (again, _), (first, _) in odometry], 20_000_000)


def _hz_reports(text: str) -> list[tuple[float, int]]:
    found = re.findall(r'average rate: ([0-9.]+)\n\tmin: [0-9.]+s max: [0-9.]+s '
                       r'std dev: [0-9.]+s window: (\d+)\n', text)
    return [(float(rate), int(window)) for rate, window in found]


def test_topic_hz_on_a_looping_player_and_play_stops_on_sigint(synthetic_bag, spawn):
    """topic hz (system clock and /clock) sees the bag's 100 Hz; Ctrl-C ends hz (0) and a
    looping player (130)."""
    directory, _ = synthetic_bag
    player = spawn(command('bag', 'play', str(directory), '--loop'), 'loop')
    wall = spawn(command('topic', 'hz', '/payload/odom'), 'hz_wall')
    sim = spawn(command('topic', 'hz', '/payload/odom', '--use-sim-time', '-w', '150'),
                'hz_sim')
    deadline = time.monotonic() + 60
    while not (len(_hz_reports(output(wall))) >= 3 and len(_hz_reports(output(sim))) >= 3):
        assert time.monotonic() < deadline, output(wall) + output(sim)
        assert player.poll() is None, output(player)
        time.sleep(0.2)
    for hz in (wall, sim):
        os.killpg(hz.pid, signal.SIGINT)
        assert hz.wait(timeout=20) == 0, output(hz)
    assert player.poll() is None  # past the end of the 3 s bag: looping
    os.killpg(player.pid, signal.SIGINT)
    assert player.wait(timeout=10) == 130
    assert 'messages published (interrupted)' in output(player)
    rate, window = _hz_reports(output(wall))[-1]
    assert 80.0 < rate < 125.0 and window >= 150, output(wall)  # receipts on a loaded machine
    rate, window = _hz_reports(output(sim))[-1]
    assert 95.0 < rate < 105.0 and 100 <= window <= 150, output(sim)  # /clock: 10 ms steps


# -- a real run: two readers; a run killed with SIGKILL -----------------------------------------
def test_a_real_run_decodes_with_rosbags_and_mcap_ros2(tmp_path):
    bag = tmp_path / 'single'
    run = subprocess.run([str(MULTILIFT), 'run', 'single_lift', '--duration', '2', '--bag',
                          str(bag)], env=ENV, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr + run.stdout
    expected = dict(run_topics(1))
    with AnyReader([bag]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        by_rosbags: dict[str, int] = {}
        for connection, _, raw in reader.messages():
            reader.deserialize(raw, connection.msgtype)
            by_rosbags[connection.topic] = by_rosbags.get(connection.topic, 0) + 1
    assert types == expected
    by_mcap: dict[str, int] = {}
    with open(next(bag.glob('*.mcap')), 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, channel, _, decoded in reader.iter_decoded_messages():
            assert type(decoded).__name__ == expected[channel.topic].split('/')[-1]
            by_mcap[channel.topic] = by_mcap.get(channel.topic, 0) + 1
    assert by_mcap == by_rosbags
    assert all(by_mcap[t] == 201 for t in ('/clock', '/payload/odom', '/formation/state'))
    info = run_tool('bag', 'info', str(bag))
    assert info.returncode == 0
    summary = read_summary(bag)
    assert summary.message_count == sum(by_mcap.values())
    assert f'Messages:          {summary.message_count}\n' in info.stdout
    for topic, kind in expected.items():
        assert f'Topic: {topic} | Type: {kind} | Count: {by_mcap[topic]} |' in info.stdout
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert set(meta) == {'version', 'storage_identifier', 'duration', 'starting_time',
                         'message_count', 'topics_with_message_count', 'compression_format',
                         'compression_mode', 'relative_file_paths', 'files', 'custom_data',
                         'ros_distro'}  # rosbag2 (Jazzy) metadata version 9
    assert set(meta['topics_with_message_count'][0]['topic_metadata']) == {
        'name', 'type', 'serialization_format', 'offered_qos_profiles', 'type_description_hash'}


def _descendants(pid: int) -> list[int]:
    """Every live process below `pid` (from /proc), children before grandchildren."""
    parents: dict[int, list[int]] = {}
    for entry in Path('/proc').iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / 'stat').read_text().rsplit(')', 1)[1].split()
            except OSError:
                continue
            parents.setdefault(int(fields[1]), []).append(int(entry.name))
    found, queue = [], [pid]
    while queue:
        for child in parents.get(queue.pop(0), []):
            found.append(child)
            queue.append(child)
    return found


def test_a_run_killed_with_sigkill_is_repaired_by_reindex(spawn, tmp_path):
    """kill -9 of the whole run: the supervisor and every node (each in a session of its own,
    so killing the supervisor's group alone would let them close the bag on SIGTERM)."""
    bag = tmp_path / 'killed'
    run = spawn([str(MULTILIFT), 'run', 'twin_lift', '--duration', '60', '--bag', str(bag)],
                'run')
    work = Path(re.search(r'logs in (\S+)', wait_for_text(run, 'logs in', 60)).group(1))
    deadline = time.monotonic() + 120
    t_kill = 0.0
    while t_kill < 8.0:
        assert time.monotonic() < deadline and run.poll() is None, output(run)
        time.sleep(0.2)
        try:
            t_kill = float((work / 'progress').read_text().split()[0])
        except (OSError, ValueError, IndexError):
            pass
    victims = _descendants(run.pid)
    for pid in [*victims, run.pid]:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    run.wait(timeout=10)

    def alive(pid: int) -> bool:
        try:
            return Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()[0] != 'Z'
        except OSError:
            return False

    end = time.monotonic() + 10
    while any(alive(pid) for pid in victims) and time.monotonic() < end:
        time.sleep(0.1)
    assert victims and not any(alive(pid) for pid in victims)
    assert not (bag / 'metadata.yaml').exists()

    result = run_tool('bag', 'reindex', str(bag))
    assert result.returncode == 0, result.stderr
    with AnyReader([bag]) as reader:
        clock = [reader.deserialize(raw, c.msgtype).clock for c, _, raw in reader.messages()
                 if c.topic == CLOCK_TOPIC]
        topics = {c.topic for c in reader.connections}
    assert topics == {t for t, _ in run_topics(2)}
    last = clock[-1].sec + clock[-1].nanosec * 1e-9
    assert last >= t_kill - 4.0, f'recovered up to t = {last:.2f} s, killed at {t_kill:.2f} s'
    with open(next(bag.glob('*.mcap')), 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        decoded = sum(1 for _ in reader.iter_decoded_messages())
    assert decoded == read_summary(bag).message_count > 0
    print(f'killed at t = {t_kill:.2f} s; bag decodes to t = {last:.2f} s')
