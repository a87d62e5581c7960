"""BagWriter: rosbag2 (Jazzy, MCAP) bag directories, read back by rosbags and the mcap reader."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader
from multilift_msgs.msg import RotorCommand
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosbags.highlevel import AnyReader
from rosbags.interfaces import QosDurability, QosHistory, QosReliability
from std_msgs.msg import String

from multilift_sim.bag import metadata_yaml
from multilift_sim.bag import BagError, BagWriter, recover

# A profile exactly as `ros2 bag record` (Jazzy) stores it in an MCAP channel.
ROSBAG2_QOS = """- history: unknown
  depth: 0
  reliability: reliable
  durability: transient_local
  deadline:
    sec: 9223372036
    nsec: 854775807
  lifespan:
    sec: 9223372036
    nsec: 854775807
  liveliness: automatic
  liveliness_lease_duration:
    sec: 9223372036
    nsec: 854775807
  avoid_ros_namespace_conventions: false"""


def _odometry(i: int) -> Odometry:
    msg = Odometry(child_frame_id='uav1/base_link')
    msg.header.stamp.sec, msg.header.stamp.nanosec = i, 1000 * i
    msg.header.frame_id = 'world'
    msg.pose.pose.position.x, msg.pose.pose.position.z = 0.5 * i, -2.0
    msg.pose.covariance[35] = float(i)
    msg.twist.twist.linear.y = 1.0 / (i + 1)
    return msg


def _rotor(i: int) -> RotorCommand:
    msg = RotorCommand(angular_velocity=[float(i), 2.0 * i, 3.0, 4.5],
                       saturated=[i % 2 == 0, False, True, i % 3 == 0])
    msg.header.frame_id = f'uav{i % 3 + 1}/base_link'
    return msg


def _mcap(bag_dir: Path) -> Path:
    return bag_dir / f'{bag_dir.name}_0.mcap'


def test_qos_yaml_is_rosbag2_text():
    assert metadata_yaml.qos_yaml([metadata_yaml.OfferedQos()]) == ROSBAG2_QOS
    assert metadata_yaml.dump([]) == '[]'
    assert metadata_yaml.parse_qos_yaml(ROSBAG2_QOS)[0]['durability'] == 'transient_local'


@pytest.mark.parametrize('compression', ['zstd', 'lz4', 'none'])
def test_round_trip_field_by_field(tmp_path, compression):
    n = 300
    bag_dir = tmp_path / 'run'
    with BagWriter(bag_dir, compression=compression, chunk_size=16 * 1024,
                   custom_data={'scenario': 'two uavs'}) as bag:
        bag.add_topic('/odom', 'nav_msgs/msg/Odometry', ROSBAG2_QOS)
        bag.add_topic('/uav1/rotor_command', 'multilift_msgs/msg/RotorCommand', ROSBAG2_QOS)
        bag.add_topic('/note', 'std_msgs/msg/String')
        for i in range(n):
            bag.write('/odom', serialize_message(_odometry(i)), 1_000_000 + 10 * i)
            bag.write('/uav1/rotor_command', serialize_message(_rotor(i)), 1_000_005 + 10 * i)
        bag.write('/note', serialize_message(String(data='done: "ok" #1')), 5_000_000)
    assert sorted(p.name for p in bag_dir.iterdir()) == ['metadata.yaml', 'run_0.mcap']

    info = yaml.safe_load((bag_dir / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert info['version'] == 9 and info['storage_identifier'] == 'mcap'
    assert info['ros_distro'] == 'jazzy'
    assert info['message_count'] == 2 * n + 1
    assert info['starting_time'] == {'nanoseconds_since_epoch': 1_000_000}
    assert info['duration'] == {'nanoseconds': 4_000_000}
    assert info['relative_file_paths'] == ['run_0.mcap']
    assert info['files'] == [{'path': 'run_0.mcap',
                              'starting_time': {'nanoseconds_since_epoch': 1_000_000},
                              'duration': {'nanoseconds': 4_000_000},
                              'message_count': 2 * n + 1}]
    assert info['compression_format'] == '' and info['compression_mode'] == ''
    assert info['custom_data'] == {'scenario': 'two uavs'}
    counts = {t['topic_metadata']['name']: t['message_count']
              for t in info['topics_with_message_count']}
    assert counts == {'/odom': n, '/uav1/rotor_command': n, '/note': 1}
    odom_meta = info['topics_with_message_count'][0]['topic_metadata']
    assert odom_meta['type'] == 'nav_msgs/msg/Odometry'
    assert odom_meta['serialization_format'] == 'cdr'
    assert odom_meta['offered_qos_profiles'] == yaml.safe_load(ROSBAG2_QOS)
    assert odom_meta['type_description_hash'].startswith('RIHS01_')

    with AnyReader([bag_dir]) as reader:
        assert {c.topic: c.msgcount for c in reader.connections} == counts
        assert reader.message_count == 2 * n + 1
        qos = next(c for c in reader.connections if c.topic == '/odom').ext.offered_qos_profiles
        assert qos[0].reliability == QosReliability.RELIABLE
        assert qos[0].durability == QosDurability.TRANSIENT_LOCAL
        assert qos[0].history == QosHistory.UNKNOWN
        seen = {'/odom': 0, '/uav1/rotor_command': 0, '/note': 0}
        for connection, log_time, raw in reader.messages():
            msg = reader.deserialize(raw, connection.msgtype)
            i = seen[connection.topic]
            seen[connection.topic] += 1
            if connection.topic == '/odom':
                ref = _odometry(i)
                assert log_time == 1_000_000 + 10 * i
                assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (i, 1000 * i)
                assert msg.header.frame_id == 'world'
                assert msg.child_frame_id == 'uav1/base_link'
                assert msg.pose.pose.position.x == ref.pose.pose.position.x
                assert msg.pose.pose.position.z == -2.0
                assert list(msg.pose.covariance) == list(ref.pose.covariance)
                assert msg.twist.twist.linear.y == ref.twist.twist.linear.y
            elif connection.topic == '/uav1/rotor_command':
                ref = _rotor(i)
                assert log_time == 1_000_005 + 10 * i
                assert list(msg.angular_velocity) == list(ref.angular_velocity)
                assert list(msg.saturated) == list(ref.saturated)
                assert msg.header.frame_id == ref.header.frame_id
            else:
                assert msg.data == 'done: "ok" #1'
        assert seen == counts

    with open(_mcap(bag_dir), 'rb') as stream:
        reader = make_reader(stream)
        header = reader.get_header()
        assert header.profile == 'ros2' and header.library
        summary = reader.get_summary()
        schemas = {s.name: s.encoding for s in summary.schemas.values()}
        assert schemas == {'nav_msgs/msg/Odometry': 'ros2msg',
                           'multilift_msgs/msg/RotorCommand': 'ros2msg',
                           'std_msgs/msg/String': 'ros2msg'}
        for channel in summary.channels.values():
            assert channel.message_encoding == 'cdr'
            assert set(channel.metadata) == {'offered_qos_profiles', 'topic_type_hash'}
        assert summary.statistics.message_count == 2 * n + 1
        assert summary.statistics.chunk_count > 1
        expected = '' if compression == 'none' else compression
        assert {c.compression for c in summary.chunk_indexes} == {expected}
        stored = [m for m in reader.iter_metadata() if m.name == 'rosbag2']
        assert yaml.safe_load(stored[0].metadata['serialized_metadata']) == info


def test_refuses_non_empty_directory_but_takes_empty_one(tmp_path):
    full = tmp_path / 'full'
    full.mkdir()
    (full / 'something').write_text('x')
    with pytest.raises(BagError, match='already exists and is not empty'):
        BagWriter(full)
    empty = tmp_path / 'empty'
    empty.mkdir()
    BagWriter(empty).close()
    assert (empty / 'metadata.yaml').is_file()


def test_close_is_idempotent_and_misuse_is_reported(tmp_path):
    bag = BagWriter(tmp_path / 'b')
    bag.add_topic('/note', 'std_msgs/msg/String')
    with pytest.raises(BagError, match='/other was not added'):
        bag.write('/other', b'', 0)
    with pytest.raises(BagError, match='already in bag .* with type std_msgs/msg/String'):
        bag.add_topic('/note', 'std_msgs/msg/Int64')
    with pytest.raises(BagError, match='no_such_pkg'):
        bag.add_topic('/x', 'no_such_pkg/msg/X')
    bag.close()
    text = (tmp_path / 'b' / 'metadata.yaml').read_text()
    bag.close()
    assert (tmp_path / 'b' / 'metadata.yaml').read_text() == text
    with pytest.raises(BagError, match='closed'):
        bag.write('/note', serialize_message(String(data='late')), 1)


def test_empty_bag_reads_like_rosbag2s(tmp_path):
    with BagWriter(tmp_path / 'e') as bag:
        bag.add_topic('/note', 'std_msgs/msg/String')
    info = yaml.safe_load((tmp_path / 'e' / 'metadata.yaml').read_text())
    info = info['rosbag2_bagfile_information']
    assert info['message_count'] == 0
    assert info['starting_time']['nanoseconds_since_epoch'] == 2**63 - 1
    with AnyReader([tmp_path / 'e']) as reader:
        assert reader.message_count == 0
        assert [c.topic for c in reader.connections] == ['/note']


def _linear_count(path: Path) -> int:
    """Messages an mcap reader gets from the file front to back until it ends or is torn."""
    count = 0
    try:
        with open(path, 'rb') as stream:
            for _ in NonSeekingReader(stream).iter_messages(log_time_order=False):
                count += 1
    except McapError:
        pass
    return count


def test_finished_chunks_are_on_disk_while_writing(tmp_path):
    bag = BagWriter(tmp_path / 'live', chunk_size=8 * 1024)
    bag.add_topic('/odom', 'nav_msgs/msg/Odometry')
    for i in range(200):
        bag.write('/odom', serialize_message(_odometry(i)), i)
    on_disk = _linear_count(_mcap(tmp_path / 'live'))
    assert 0 < on_disk <= 200
    assert on_disk == 200 - bag.unflushed_count
    bag.flush()
    assert bag.unflushed_count == 0
    assert _linear_count(_mcap(tmp_path / 'live')) == 200
    bag.close()


def test_recover_a_torn_file(tmp_path):
    src = tmp_path / 'src'
    with BagWriter(src, chunk_size=8 * 1024) as bag:
        bag.add_topic('/uav1/rotor_command', 'multilift_msgs/msg/RotorCommand', ROSBAG2_QOS)
        for i in range(2000):
            bag.write('/uav1/rotor_command', serialize_message(_rotor(i)), 100 * i)
    data = _mcap(src).read_bytes()
    torn = tmp_path / 'torn'
    torn.mkdir()
    (torn / 'torn_0.mcap').write_bytes(data[:len(data) // 2])  # as if killed mid-run
    readable = _linear_count(torn / 'torn_0.mcap')
    assert 0 < readable < 2000
    assert recover(torn, tmp_path / 'fixed') == readable
    with AnyReader([tmp_path / 'fixed']) as reader:
        values = [list(reader.deserialize(raw, c.msgtype).angular_velocity)
                  for c, _, raw in reader.messages()]
        qos = reader.connections[0].ext.offered_qos_profiles
    assert values == [list(_rotor(i).angular_velocity) for i in range(readable)]
    assert qos[0].durability == QosDurability.TRANSIENT_LOCAL


@pytest.mark.parametrize('compression', ['zstd', 'lz4', 'none'])
def test_messages_are_written_as_the_mcap_library_writes_them(tmp_path, compression):
    """BagWriter packs each Message record itself (bag.mcap_records.MessageAppender): the file
    is the one the library's Writer.add_message gives, byte for byte, across several chunks,
    topics and log times out of order."""
    # serialized once for both bags: rclpy leaves CDR padding uninitialised, so serializing
    # a message again need not give the same bytes
    payloads = [(serialize_message(_odometry(i)), serialize_message(_rotor(i)))
                for i in range(300)]

    def fill(bag: BagWriter) -> None:
        bag.add_topic('/uav1/odom', 'nav_msgs/msg/Odometry', ROSBAG2_QOS)
        bag.add_topic('/uav1/rotor_cmd', 'multilift_msgs/msg/RotorCommand', ROSBAG2_QOS)
        for i, (odometry, rotor) in enumerate(payloads):
            bag.write('/uav1/odom', odometry, 10_000 * i)
            bag.write('/uav1/rotor_cmd', rotor, 10_000 * i + 3, publish_time_ns=7 * i)
            if i % 50 == 7:
                bag.write('/uav1/odom', odometry, 500 * i)  # earlier than the rest
        bag.close()

    fast = BagWriter(tmp_path / 'fast' / 'bag', compression=compression, chunk_size=4096)
    fill(fast)
    library = BagWriter(tmp_path / 'library' / 'bag', compression=compression, chunk_size=4096)
    writer = library._writer

    def add_many(messages, log_time, publish_time):
        for channel_id, sequence, data in messages:
            writer.add_message(channel_id, log_time, bytes(data), publish_time,
                               sequence=sequence)
    library._messages.add_many = add_many
    fill(library)
    data = _mcap(tmp_path / 'fast' / 'bag').read_bytes()
    chunks = [r for r in make_reader(open(_mcap(tmp_path / 'fast' / 'bag'), 'rb'))
              .get_summary().chunk_indexes]
    assert len(chunks) > 5
    assert data == _mcap(tmp_path / 'library' / 'bag').read_bytes()


@pytest.mark.parametrize('chunk_size', [1 << 20, 4096])
def test_write_many_writes_what_write_writes(tmp_path, chunk_size):
    """A tick's messages written together (`write_many`) are the records, sequences, times and
    metadata that a `write` of each gives: in one chunk the same file byte for byte; across
    chunks the same messages (a chunk is finished after a batch, not inside it)."""
    payloads = [(serialize_message(_odometry(i)), serialize_message(_rotor(i)))
                for i in range(300)]
    topics = [('/uav1/odom', 'nav_msgs/msg/Odometry'),
              ('/uav1/rotor_cmd', 'multilift_msgs/msg/RotorCommand')]

    def bag(name: str) -> BagWriter:
        writer = BagWriter(tmp_path / name / 'bag', chunk_size=chunk_size)
        for topic, kind in topics:
            writer.add_topic(topic, kind, ROSBAG2_QOS)
        return writer

    one_by_one, together = bag('one'), bag('together')
    for i, (odometry, rotor) in enumerate(payloads):
        tick = [('/uav1/odom', odometry), ('/uav1/rotor_cmd', rotor), ('/uav1/odom', rotor)]
        for topic, data in tick:
            one_by_one.write(topic, data, 10_000 * i)
        together.write_many(tick, 10_000 * i)
    together.write_many([], 5)  # nothing to write
    with pytest.raises(BagError, match='/nowhere was not added'):
        together.write_many([('/uav1/odom', b'x'), ('/nowhere', b'y')], 1)
    one_by_one.close()
    together.close()
    first, second = _mcap(tmp_path / 'one' / 'bag'), _mcap(tmp_path / 'together' / 'bag')

    def messages(path: Path) -> list:
        with open(path, 'rb') as stream:
            return [(channel.topic, message.sequence, message.log_time, message.publish_time,
                     message.data)
                    for _, channel, message in make_reader(stream).iter_messages()]
    assert len(messages(second)) == 900
    assert messages(first) == messages(second)
    assert ((tmp_path / 'one' / 'bag' / 'metadata.yaml').read_text()
            == (tmp_path / 'together' / 'bag' / 'metadata.yaml').read_text().replace(
                'together', 'one'))
    if chunk_size > 900 * 400:
        assert first.read_bytes() == second.read_bytes()
