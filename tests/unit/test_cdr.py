"""multilift_sim.wire.cdr and cdr_scene against rclpy: every packer's bytes decode (with rosbags
from the installed .msg definitions, and with rclpy) to the message the rclpy builders of
multilift_sim.ros make from the same inputs, and equal rclpy's `serialize_message` except in the
padding, which the packers zero."""
from __future__ import annotations

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from multilift_sim.wire import cdr, cdr_layout, cdr_scene, msgdefs, msgvalues
from multilift_sim.ros import messages
from multilift_sim.ros.markers import FormationMarkers

T_NS = 12_340_000_001


@pytest.fixture(scope='module')
def typestore():
    store = get_typestore(Stores.EMPTY)
    for name in ('rosgraph_msgs/msg/Clock', 'nav_msgs/msg/Odometry',
                 'geometry_msgs/msg/Vector3Stamped', 'multilift_msgs/msg/RotorCommand',
                 'multilift_msgs/msg/AttitudeSetpoint', 'multilift_msgs/msg/TrackingReference',
                 'multilift_msgs/msg/VirtualConstraintError', 'multilift_msgs/msg/FormationState',
                 'visualization_msgs/msg/MarkerArray', 'geometry_msgs/msg/TransformStamped',
                 'multilift_msgs/msg/FormationSnapshot', 'tf2_msgs/msg/TFMessage',
                 'multilift_msgs/msg/FormationEvent'):
        store.register(get_types_from_msg(msgdefs.message_definition(name), name))
    return store


def fields(value):
    """A plain nested structure of an rclpy or rosbags message, for comparison."""
    if isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, bytes):
        return list(value)
    if isinstance(value, np.ndarray):
        return [fields(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)) or type(value).__name__ == 'array':
        return [fields(v) for v in value]
    slots = getattr(value, '__slots__', None) or list(getattr(value, '__dataclass_fields__'))
    return {s.lstrip('_'): fields(getattr(value, s)) for s in slots
            if s.strip('_') not in ('check_fields', 'msgtype') and not s.isupper()}


def unpadded(data: bytes, layout: cdr_layout.Layout) -> bytes:
    out = bytearray(data)
    for offset, length in layout.pad:
        out[offset:offset + length] = bytes(length)
    return bytes(out)


def check(packed: bytes, packer, msg, typestore) -> None:
    """`packer`: the packer or the Layout it packed with."""
    layout = packer if isinstance(packer, cdr_layout.Layout) else packer.layout
    rclpy_bytes = serialize_message(msg)
    assert len(packed) == len(rclpy_bytes)
    assert packed == unpadded(rclpy_bytes, layout)
    assert all(packed[o:o + n] == bytes(n) for o, n in layout.pad)
    # rclpy's own round trip: float32 fields rounded as they travel
    expected = fields(deserialize_message(rclpy_bytes, type(msg)))
    assert fields(deserialize_message(packed, type(msg))) == expected
    type_name = type(msg).__module__.split('.')[0] + '/msg/' + type(msg).__name__
    decoded = fields(typestore.deserialize_cdr(packed, type_name))
    assert _close(decoded, expected)


def _close(a, b) -> bool:
    """Equal field by field (rosbags and rclpy name and nest the fields alike)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys()
        return all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list):
        assert len(a) == len(b)
        return all(_close(x, y) for x, y in zip(a, b))
    assert a == b, (a, b)
    return True


def test_clock(typestore):
    packer = cdr.Clock()
    check(packer.pack(T_NS), packer, messages.clock(T_NS), typestore)


def test_uav_and_payload_odometry(twin, typestore):
    _, snap = twin
    uav = snap.uavs[1]
    packer = cdr.Odometry(msgvalues.uav_frame(2))
    values = msgvalues.odometry(uav.position, uav.velocity, uav.orientation,
                                uav.body_velocity, uav.body_rates)
    check(packer.pack(T_NS, *values), packer, messages.uav_odometry(T_NS, 2, uav), typestore)
    packer = cdr.Odometry(msgvalues.PAYLOAD_FRAME)
    values = msgvalues.odometry(snap.payload_position, snap.payload_velocity, None, None, None)
    check(packer.pack(T_NS, *values), packer,
          messages.payload_odometry(T_NS, snap.payload_position, snap.payload_velocity),
          typestore)


def test_vector3_stamped(typestore):
    gust = np.array([0.25, -1.5, 1e-300])
    packer = cdr.Vector3Stamped()
    check(packer.pack(T_NS, *gust), packer, messages.gust(T_NS, gust), typestore)


class _Output:
    rotor_speeds = np.array([1500.5, 1490.25, 1e-9, -0.0])
    saturated = np.array([True, False, False, True])
    attitude_setpoint = np.array([0.1, -0.2, 3.0])
    thrust = 17.125


def test_rotor_command_and_attitude_setpoint(typestore):
    out = _Output()
    packer = cdr.RotorCommand(4, msgvalues.uav_frame(1))
    check(packer.pack(T_NS, out.rotor_speeds.tolist(), out.saturated.tolist()), packer,
          messages.rotor_command(T_NS, 1, out), typestore)
    packer = cdr.AttitudeSetpoint(msgvalues.uav_frame(12))
    check(packer.pack(T_NS, *out.attitude_setpoint, out.thrust), packer,
          messages.attitude_setpoint(T_NS, 12, out), typestore)


def test_tracking_reference(typestore):
    class Reference:
        position = np.array([1.0, 2.0, 3.0])
        velocity = np.array([0.5, 0.0, -0.5])
        acceleration = np.array([0.0, 1e-3, 9.0])
    ref = Reference()
    packer = cdr.TrackingReference()
    check(packer.pack(T_NS, *ref.position, *ref.velocity, *ref.acceleration), packer,
          messages.tracking_reference(T_NS, ref), typestore)


@pytest.mark.parametrize('row', [[1200.0, 12.0, 0.0, 1.0, 3.0, 0.25],      # uav2 rotor 4
                                 [601.0, 6.005, 1.0, 2.0, 0.0, 1.0]])     # uav3 lets go
def test_formation_event(row, typestore):
    packer = cdr.FormationEvent()
    packed = packer.pack(T_NS, *msgvalues.formation_event(row))
    check(packed, packer, messages.formation_event(T_NS, row), typestore)


@pytest.mark.parametrize('n', [1, 2, 3, 10])
def test_float_sequences(n, typestore):
    rng = np.random.default_rng(n)
    a, b, c = rng.normal(size=(3, n))
    taut = rng.random(n) < 0.5
    packer = cdr.formation_state(n)
    check(packer.pack(T_NS, a.tolist(), b.tolist(), c.tolist(), taut.tolist()), packer,
          messages.formation_state(T_NS, a, b, c, taut), typestore)
    packer = cdr.virtual_constraint_error(n)
    check(packer.pack(T_NS, a.tolist(), b.tolist()), packer,
          messages.formation_error(T_NS, a, b), typestore)
    with pytest.raises(ValueError):
        packer.pack(T_NS, a.tolist(), b.tolist()[:-1] + [0.0, 0.0])


def test_marker_array(twin, typestore):
    scenario, snap = twin
    tensions = [4.0, -5.0]
    msg = FormationMarkers(scenario).build(snap, tensions, T_NS)
    packer_markers = FormationMarkers(scenario)  # its own scene, updated as the bag does
    scene = packer_markers.scene
    scene.update([u.position for u in snap.uavs], [u.euler for u in snap.uavs],
                 snap.payload_position, tensions)
    packer = cdr_scene.MarkerArray(scene.specs)
    check(packer.pack(T_NS), packer, msg, typestore)


def test_tf_message(twin, typestore):
    tf2 = pytest.importorskip('tf2_msgs.msg')
    from geometry_msgs.msg import TransformStamped
    _, snap = twin
    children = [msgvalues.uav_frame(i + 1) for i in range(len(snap.uavs))] + ['payload']
    translations = [msgvalues.vec3(u.position) for u in snap.uavs] + [
        msgvalues.vec3(snap.payload_position)]
    rotations = [msgvalues.quaternion(u.euler) for u in snap.uavs] + [
        msgvalues.IDENTITY]
    msg = tf2.TFMessage()
    for child, t, r in zip(children, translations, rotations):
        ts = TransformStamped(child_frame_id=child)
        ts.header.stamp.sec, ts.header.stamp.nanosec = msgvalues.stamp(T_NS)
        ts.header.frame_id = 'world'
        tr = ts.transform.translation
        tr.x, tr.y, tr.z = t
        q = ts.transform.rotation
        q.x, q.y, q.z, q.w = r
        msg.transforms.append(ts)
    packer = cdr_scene.TFMessage(children)
    check(packer.pack(T_NS, translations, rotations), packer, msg, typestore)


def test_tf_message_decodes_with_rosbags(typestore):
    """Without tf2_msgs installed for rclpy: rosbags decodes it against the definition."""
    packer = cdr_scene.TFMessage(['uav1/base_link', 'payload'])
    data = packer.pack(T_NS, [(1.0, 2.0, 3.0), (4.0, 5.0, 6.5)],
                       [(0.0, 0.0, 0.0, 1.0), (0.5, 0.5, 0.5, 0.5)])
    store = get_typestore(Stores.ROS2_JAZZY)
    msg = store.deserialize_cdr(data, 'tf2_msgs/msg/TFMessage')
    assert [t.child_frame_id for t in msg.transforms] == ['uav1/base_link', 'payload']
    assert [t.header.frame_id for t in msg.transforms] == ['world', 'world']
    assert msg.transforms[1].transform.translation.z == 6.5
    assert msg.transforms[1].transform.rotation.w == 0.5
    assert (msg.transforms[0].header.stamp.sec, msg.transforms[0].header.stamp.nanosec) == (
        12, 340_000_001)


def test_formation_snapshot(twin, typestore):
    _, snap = twin
    packer = cdr.FormationSnapshot([4, 4])
    for previous in (None, [np.array([1500.0, 1490.0, 1500.0, 1510.0]),
                            np.array([1.0, 2.0, 3.0, 4.5])]):
        values = msgvalues.formation_snapshot(snap, previous)
        check(packer.pack(snap.t_ns, *values), packer.layout(len(values[-1])),
              messages.formation_snapshot(snap, previous, [4, 4]), typestore)


def test_formation_snapshot_unpacks_what_rclpy_serializes(twin):
    _, snap = twin
    packer = cdr.FormationSnapshot([4, 4])
    speeds = [np.array([1500.0, 1490.0, 1500.0, 1510.0]), np.array([1.0, 2.0, 3.0, 4.5])]
    for previous in (None, speeds):
        # rclpy's bytes (padding not zeroed) read back to the values packed
        data = serialize_message(messages.formation_snapshot(snap, previous, [4, 4]))
        t_ns, *arrays = packer.unpack(data)
        assert t_ns == snap.t_ns
        for got, want in zip(arrays, msgvalues.formation_snapshot(snap, previous)):
            np.testing.assert_array_equal(got, want)
    # another formation's snapshot is refused, naming what differs
    three = cdr.FormationSnapshot([4, 4, 4])
    with pytest.raises(ValueError, match='bytes is not one of 3 UAVs'):
        three.unpack(data)
    hexa = cdr.FormationSnapshot([6, 2])
    with pytest.raises(ValueError, match=r'rotor_count \[4, 4\] where this formation has '
                                         r'\[6, 2\]'):
        hexa.unpack(data)
    with pytest.raises(ValueError, match='encapsulation'):
        packer.unpack(b'\x00\x00' + data[2:])
