"""Graph and message helpers shared by the recorder and the `multilift topic` tools (rclpy).

What ros2cli and rosidl_runtime_py would give, which this environment lacks: message classes from
type names, messages as ordered dicts / YAML shaped like `ros2 topic echo`, the QoS publishers offer
in rosbag2's terms, and a subscription QoS adapted to those offers.
"""

from __future__ import annotations

import array
import importlib
from typing import Any, Callable, Iterable

import yaml
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile,
                       ReliabilityPolicy)

from multilift_sim.bag.metadata_yaml import OfferedQos
from multilift_sim.wire.msgdefs import MessageDefinitionError, split_type_name

# What the recorder asks for: our publishers are reliable + transient_local, so a recorder that
# starts late still gets their startup messages. The depth is what a reader keeps until the
# recorder takes it: `window` publishes at 500 Hz of simulated time, several times faster than
# real time through ROS, so 1,000 could last under a second of a starved recorder (a CI run lost
# 2 of its /uav1/odom messages; tests/ros/test_recorder.py's burst of 6,001 kept 2,026 with
# 1,000, all with this).
RECORD_QOS_DEPTH = 10000


def import_message_type(type_name: str) -> type:
    """The Python class of `pkg/msg/Type` (e.g. `nav_msgs.msg.Odometry`)."""
    try:
        package, namespace, name = split_type_name(type_name)
    except MessageDefinitionError as error:
        raise ValueError(str(error)) from None
    try:
        module = importlib.import_module(f'{package}.{namespace}')
        return getattr(module, name)
    except (ImportError, AttributeError):
        raise ValueError(f'message type {type_name!r} is not installed: no class {name} in '
                         f'Python module {package}.{namespace} (source scripts/env.sh?)') from None


def message_to_ordered(msg: Any) -> dict[str, Any]:
    """Fields of a ROS message as a plain nested dict in field order; arrays become lists."""
    return {name: _value(getattr(msg, name)) for name in msg.get_fields_and_field_types()}


def _value(value: Any) -> Any:
    if hasattr(value, 'get_fields_and_field_types'):
        return message_to_ordered(value)
    if isinstance(value, (list, tuple)):
        return [_value(v) for v in value]
    if isinstance(value, array.array) or hasattr(value, 'tolist'):
        return value.tolist()
    if isinstance(value, bytes):  # a `byte` field (or element) is a bytes object of length 1
        return value[0] if len(value) == 1 else list(value)
    return value


class _Dumper(yaml.SafeDumper):
    """PyYAML dumper keeping dict order (as rosidl_runtime_py's OrderedDict representer)."""


_Dumper.add_representer(dict, lambda dumper, data: dumper.represent_dict(data.items()))


def message_to_yaml(msg: Any) -> str:
    """A message as `ros2 topic echo` prints it (block YAML, arrays as lists)."""
    return yaml.dump(message_to_ordered(msg), Dumper=_Dumper, allow_unicode=True,
                     width=2**31 - 1, default_flow_style=False)


def _policy_name(policy: Any) -> str:
    return policy.name.lower()


def offered_qos(endpoints: Iterable[Any]) -> list[OfferedQos]:
    """QoS profiles offered by publisher endpoints (`node.get_publishers_info_by_topic`)."""
    result = []
    for info in endpoints:
        qos = info.qos_profile
        result.append(OfferedQos(
            history=_policy_name(qos.history), depth=qos.depth,
            reliability=_policy_name(qos.reliability), durability=_policy_name(qos.durability),
            deadline_ns=qos.deadline.nanoseconds, lifespan_ns=qos.lifespan.nanoseconds,
            liveliness=_policy_name(qos.liveliness),
            liveliness_lease_duration_ns=qos.liveliness_lease_duration.nanoseconds,
            avoid_ros_namespace_conventions=qos.avoid_ros_namespace_conventions))
    return result


def adapted_qos(endpoints: Iterable[Any], depth: int = RECORD_QOS_DEPTH) -> QoSProfile:
    """Subscription QoS that matches every publisher, preferring reliable + transient_local.

    As rosbag2 and ros2cli do: reliable only if all publishers are reliable, transient_local
    only if all are transient_local (a stricter request would not match the others). With no
    publisher known yet, reliable + transient_local.
    """
    infos = list(endpoints)
    reliable = all(i.qos_profile.reliability == ReliabilityPolicy.RELIABLE for i in infos)
    latched = all(i.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for i in infos)
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST, depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
        liveliness=LivelinessPolicy.AUTOMATIC)


def compatible(offered: QoSProfile, requested: QoSProfile) -> bool:
    """Whether a publisher offering `offered` matches a subscription requesting `requested`
    (reliability and durability, the policies our endpoints set): a reliable request needs a
    reliable offer, a transient_local request a transient_local offer."""
    if (requested.reliability == ReliabilityPolicy.RELIABLE
            and offered.reliability != ReliabilityPolicy.RELIABLE):
        return False
    return not (requested.durability == DurabilityPolicy.TRANSIENT_LOCAL
                and offered.durability != DurabilityPolicy.TRANSIENT_LOCAL)


class AdaptiveSubscription:
    """A subscription whose QoS follows the publishers' offers, as `ros2 topic echo` and
    `ros2 bag record` choose theirs (`adapted_qos`), and that follows them again when a
    publisher appears that the current request would not match (`adapt()`, to be called on
    graph changes or periodically): a latched topic keeps being read transient_local, and a
    node publishing with the defaults (reliable, volatile) is still heard.

    When it adapts, the new subscription is created before the old one is destroyed, so nothing
    of the matched publishers is lost in between (a message may arrive twice then).
    """

    def __init__(self, node: Any, msg_type: type, topic: str, callback: Callable[..., None],
                 depth: int = RECORD_QOS_DEPTH, raw: bool = False,
                 durability: DurabilityPolicy | None = None,
                 on_adapt: Callable[[QoSProfile], None] | None = None) -> None:
        self.node, self.msg_type, self.topic = node, msg_type, topic
        self.callback, self.depth, self.raw = callback, depth, raw
        self.durability = durability
        self.on_adapt = on_adapt
        self.qos = self._wanted()
        self.subscription = self._create(self.qos)

    def _wanted(self) -> QoSProfile:
        qos = adapted_qos(self.node.get_publishers_info_by_topic(self.topic), self.depth)
        if self.durability is not None:
            qos.durability = self.durability
        return qos

    def _create(self, qos: QoSProfile) -> Any:
        return self.node.create_subscription(self.msg_type, self.topic, self.callback, qos,
                                             raw=self.raw)

    def matches_publishers(self) -> bool:
        """Whether every publisher of the topic known now matches the current request."""
        return all(compatible(info.qos_profile, self.qos)
                   for info in self.node.get_publishers_info_by_topic(self.topic))

    def adapt(self) -> bool:
        """Re-subscribe with the QoS the publishers now allow if one of them does not match;
        True if it did."""
        if self.matches_publishers():
            return False
        qos = self._wanted()
        old, self.subscription, self.qos = self.subscription, self._create(qos), qos
        self.node.destroy_subscription(old)
        if self.on_adapt is not None:
            self.on_adapt(qos)
        return True

    def destroy(self) -> None:
        self.node.destroy_subscription(self.subscription)


def qos_text(qos: QoSProfile) -> str:
    """`reliable, transient_local`: the two policies a log line names."""
    return f'{_policy_name(qos.reliability)}, {_policy_name(qos.durability)}'
