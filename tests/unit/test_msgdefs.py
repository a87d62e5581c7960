"""msgdefs: the ros2msg schema text rosbag2 writes, checked by two independent parsers.

mcap-ros2-support and rosbags each parse the schema text on their own; a message serialized by
rclpy (the real CDR of the installed type) must decode to the same values through both.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from mcap_ros2._dynamic import generate_dynamic
from mcap_ros2.reader import read_ros2_messages
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from multilift_sim.wire import msgdefs
from multilift_sim.bag import BagWriter

SEP = '=' * 80


def _share(package: str) -> Path:
    return msgdefs.package_share_directory(package)


def test_odometry_text_is_rosbag2_layout():
    text = msgdefs.message_definition('nav_msgs/msg/Odometry')
    own = (_share('nav_msgs') / 'msg' / 'Odometry.msg').read_text()
    assert text.startswith(own)
    blocks = text[len(own):].split(f'\n{SEP}\nMSG: ')
    assert blocks[0] == ''
    names = [b.split('\n', 1)[0] for b in blocks[1:]]
    # rosbag2's message_definition_cache: depth first, siblings sorted, each type once.
    assert names == ['geometry_msgs/PoseWithCovariance', 'geometry_msgs/Pose',
                     'geometry_msgs/Point', 'geometry_msgs/Quaternion',
                     'geometry_msgs/TwistWithCovariance', 'geometry_msgs/Twist',
                     'geometry_msgs/Vector3', 'std_msgs/Header', 'builtin_interfaces/Time']
    for block in blocks[1:]:
        name, body = block.split('\n', 1)
        package, type_name = name.split('/')
        assert body == (_share(package) / 'msg' / f'{type_name}.msg').read_text()


def test_rotor_command_text():
    text = msgdefs.message_definition('multilift_msgs/msg/RotorCommand')
    own = (_share('multilift_msgs') / 'msg' / 'RotorCommand.msg').read_text()
    assert text == (own + f'\n{SEP}\nMSG: std_msgs/Header\n'
                    + (_share('std_msgs') / 'msg' / 'Header.msg').read_text()
                    + f'\n{SEP}\nMSG: builtin_interfaces/Time\n'
                    + (_share('builtin_interfaces') / 'msg' / 'Time.msg').read_text())
    assert msgdefs.message_definition('multilift_msgs/RotorCommand') == text


def test_type_hash_is_the_one_jazzy_publishers_advertise():
    # The value a Fast DDS publisher of nav_msgs/msg/Odometry reports in its endpoint info.
    assert msgdefs.type_description_hash('nav_msgs/msg/Odometry') == (
        'RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0')
    value = msgdefs.type_description_hash('multilift_msgs/msg/RotorCommand')
    assert value.startswith('RIHS01_') and len(value) == len('RIHS01_') + 64
    assert msgdefs.type_description_hash('std_msgs/msg/NoSuchType') == ''


def test_field_type_names_rules():
    text = '\n'.join([
        '# a comment line with Foo bar',
        'int32 A=1  # constant',
        'string NAME="x # not a type"',
        'float64 x 1.5',
        'float64[3] fixed [1.0, 2.0, 3.0]',
        'int32[<=4] bounded',
        'string<=8 short',
        'string<=8[<=2] shorts',
        'wstring w',
        'Header header',
        'Inner[] inners',
        'other_msgs/Thing[2] things',
        'builtin_interfaces/Time stamp',
    ])
    assert msgdefs.field_type_names(text, 'std_msgs') == [
        'builtin_interfaces/Time', 'other_msgs/Thing', 'std_msgs/Header', 'std_msgs/Inner']


def test_errors_name_the_problem():
    with pytest.raises(msgdefs.MessageDefinitionError, match='pkg/msg/Type'):
        msgdefs.message_definition('not a type')
    with pytest.raises(msgdefs.MessageDefinitionError, match='no_such_pkg'):
        msgdefs.message_definition('no_such_pkg/msg/Foo')
    with pytest.raises(msgdefs.MessageDefinitionError, match='NoSuchType.msg'):
        msgdefs.message_definition('std_msgs/msg/NoSuchType')


@pytest.fixture
def edge_prefix(tmp_path, monkeypatch):
    """An ament prefix with a package whose messages use constants, defaults and bounds."""
    prefix = tmp_path / 'prefix'
    (prefix / 'share' / 'ament_index' / 'resource_index' / 'packages').mkdir(parents=True)
    (prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / 'edge_msgs').touch()
    msg = prefix / 'share' / 'edge_msgs' / 'msg'
    msg.mkdir(parents=True)
    (msg / 'Edge.msg').write_text('\n'.join([
        '# Edge cases of the .msg grammar.',
        'int32 ANSWER=42',
        'string GREETING="hi # there"',
        'std_msgs/Header header',
        'float64 gain 1.5  # with a default',
        'float64[3] fixed [1.0, 2.0, 3.0]',
        'int32[<=4] bounded',
        'string<=8 short',
        'string<=8[<=2] shorts',
        'Inner[] inners',
        'edge_msgs/Inner one',
        '']))
    (msg / 'Inner.msg').write_text('uint8 k\nbyte[] data\nbool flag true\n')
    monkeypatch.setenv('AMENT_PREFIX_PATH', f'{prefix}{os.pathsep}'
                       + os.environ.get('AMENT_PREFIX_PATH', ''))
    return prefix


def test_edge_cases_parse_in_both_readers(edge_prefix):
    text = msgdefs.message_definition('edge_msgs/msg/Edge')
    assert [line for line in text.splitlines() if line.startswith('MSG: ')] == [
        'MSG: edge_msgs/Inner', 'MSG: std_msgs/Header', 'MSG: builtin_interfaces/Time']
    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(text, 'edge_msgs/msg/Edge'))
    edge, inner = store.types['edge_msgs/msg/Edge'], store.types['edge_msgs/msg/Inner']
    header, stamp = store.types['std_msgs/msg/Header'], store.types['builtin_interfaces/msg/Time']
    import numpy as np
    value = edge(
        header=header(stamp=stamp(sec=3, nanosec=4), frame_id='world'), gain=2.5,
        fixed=np.array([1.0, 2.0, 3.0]), bounded=np.array([7, 8], dtype=np.int32),
        short='abc', shorts=['x', 'yz'],
        inners=[inner(k=1, data=np.array([9, 10], dtype=np.uint8), flag=True)],
        one=inner(k=2, data=np.array([], dtype=np.uint8), flag=False))
    cdr = bytes(store.serialize_cdr(value, 'edge_msgs/msg/Edge'))
    decoded = generate_dynamic('edge_msgs/msg/Edge', text)['edge_msgs/msg/Edge'](cdr)
    assert decoded.header.stamp.sec == 3 and decoded.header.frame_id == 'world'
    assert decoded.gain == 2.5 and list(decoded.fixed) == [1.0, 2.0, 3.0]
    assert list(decoded.bounded) == [7, 8]
    assert decoded.short == 'abc' and list(decoded.shorts) == ['x', 'yz']
    assert decoded.inners[0].k == 1 and bytes(decoded.inners[0].data) == b'\x09\x0a'
    assert decoded.one.k == 2 and decoded.one.flag is False
    assert store.deserialize_cdr(cdr, 'edge_msgs/msg/Edge').shorts == ['x', 'yz']


def test_real_types_decode_in_rosbags_and_mcap_ros2(tmp_path):
    """Schemas of Odometry and RotorCommand, with rclpy's CDR, through both readers."""
    from multilift_msgs.msg import RotorCommand
    from nav_msgs.msg import Odometry
    from rclpy.serialization import serialize_message
    odom = Odometry(child_frame_id='uav1/base_link')
    odom.header.stamp.sec, odom.header.frame_id = 12, 'world'
    odom.pose.pose.position.x, odom.pose.pose.orientation.w = 1.25, 1.0
    odom.pose.covariance[7] = 0.5
    odom.twist.twist.angular.z = -0.75
    rotor = RotorCommand(angular_velocity=[100.0, 200.5, 300.0, 400.0],
                         saturated=[False, True, False, False])
    rotor.header.frame_id = 'uav1/base_link'
    bag_dir = tmp_path / 'defs'
    with BagWriter(bag_dir) as bag:
        bag.add_topic('/odom', 'nav_msgs/msg/Odometry')
        bag.add_topic('/rotor', 'multilift_msgs/msg/RotorCommand')
        bag.write('/odom', serialize_message(odom), 10)
        bag.write('/rotor', serialize_message(rotor), 20)

    # rosbags: an empty type store, so the types can come only from our schema text.
    with AnyReader([bag_dir], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        got = {c.topic: reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages()}
    assert got['/odom'].pose.pose.position.x == 1.25
    assert got['/odom'].pose.covariance[7] == 0.5
    assert got['/odom'].twist.twist.angular.z == -0.75
    assert got['/odom'].child_frame_id == 'uav1/base_link'
    assert list(got['/rotor'].angular_velocity) == [100.0, 200.5, 300.0, 400.0]
    assert list(got['/rotor'].saturated) == [False, True, False, False]

    decoded = {m.channel.topic: m.ros_msg
               for m in read_ros2_messages(str(next(bag_dir.glob('*.mcap'))))}
    assert decoded['/odom'].header.stamp.sec == 12
    assert decoded['/odom'].header.frame_id == 'world'
    assert decoded['/odom'].pose.pose.orientation.w == 1.0
    assert list(decoded['/rotor'].angular_velocity) == [100.0, 200.5, 300.0, 400.0]
    assert list(decoded['/rotor'].saturated) == [False, True, False, False]
    assert decoded['/rotor'].header.frame_id == 'uav1/base_link'
