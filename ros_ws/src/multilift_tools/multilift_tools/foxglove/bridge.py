"""The bridge of `multilift foxglove`: a ROS node forwarding every topic of the live graph to a
Foxglove WebSocket server, and publishing what its clients send (capability clientPublish:
`publish`, a default publisher per topic, made when a client advertises the channel).

A node (`multilift_foxglove`) subscribes raw to every topic that has a publisher (hidden topics
and /parameter_events excepted) as soon as the graph shows it: a thread waits on the node's
graph guard condition, which the rmw triggers on every discovery event (`GraphEvents`), and has
the executor look at the graph again (`FoxgloveBridge.poll`), so a topic is subscribed to within
milliseconds of its publisher's discovery and a run of any length is forwarded from its first
message (the publishers keep their history for late joiners, see Subscriptions); a poll every
POLL_PERIOD s stays as a safety net and closes channels (below). Discovery itself is the
rmw's: a node that starts after the bridge shows up when Fast DDS matches the two participants
(with discovery limited to localhost this was seen to wait for the bridge's next participant
announcement, 3 s by default).

Each topic is a channel with message encoding `cdr` and a `ros2msg` schema named `pkg/msg/Type`
holding the full message definition (`msgdefs.message_definition`, as in our bags), so the app
decodes custom messages too. The CDR bytes go out untouched. The WebSocket server is
`server.FoxgloveServer` (the `websockets` package, subprotocols foxglove.websocket.v1 and
foxglove.sdk.v1): a channel is registered before it is advertised, so a client that subscribes
as soon as it sees the advertisement is never refused; a topic without publishers for
REMOVE_AFTER s loses its channel (the app is told) and gets it back, under the same id, when a
publisher returns. Server info names the ROS distribution (`metadata.ROS_DISTRO`, from the
environment, else jazzy), which the app uses to pick its ROS 2 profile.

Subscriptions: keep_last SUBSCRIPTION_DEPTH, QoS adapted to the publishers (reliable and
transient_local when every publisher offers it, again when a new publisher appears:
`introspection.AdaptiveSubscription`), so a client that connects during a run still gets the
last messages our publishers keep; and a new subscription first gets the last REPLAY messages
the channel carried (so the messages that arrive between the advertisement and the client's
subscribe are not lost, and a client that subscribes late sees the recent past). A backlog is
read in batches (TAKE_BATCH), as the recorder does, so the bridge keeps up with a fast run.

Time: each message goes out with its own time: its header stamp (`header.stamp`, the stamp of a
Clock, or of the first element of an array of stamped messages such as /tf and
/visualization/markers); a message without one gets the latest /clock time while /clock has a
publisher, else wall time. The server broadcasts the /clock time (capability Time), so the
app's clock follows simulated time as in a bag; wall time otherwise. When the base changes (a
run starts or ends) the server starts a new session so clients reset. The stamps: `stamps`.

Drops: each client has a queue of CLIENT_BACKLOG messages; what does not fit (a client slower
than the run) is dropped, counted per topic and logged, and the total is printed at the end.
Not counted: a subscription overrun (more than SUBSCRIPTION_DEPTH messages of a topic waiting
to be taken), which the batched takes make unlikely; a message does not name its publisher, so
gaps in publication sequence numbers cannot be told apart from another publisher's numbers.
"""
from __future__ import annotations

import functools
import os
import time
from typing import Any

from multilift_sim.topics import CLOCK
from multilift_tools.foxglove.graph_events import GraphEvents
from multilift_tools.foxglove.server import FoxgloveServer
from multilift_tools.foxglove.stamps import cdr_stamp, stamp_ns, stamp_offset

DEFAULT_PORT = 8765
DEFAULT_HOST = '127.0.0.1'
POLL_PERIOD = 1.0  # [s] fallback graph poll (graph events come first) and channel removal
REMOVE_AFTER = 2.0  # [s] without a publisher before a topic's channel is removed
SUBSCRIPTION_DEPTH = 1000  # keep_last depth of the raw subscriptions
TAKE_BATCH = 256  # messages of one topic taken in one callback (see recorder_node)
TIME_BROADCAST_PERIOD = 0.02  # [s] shortest wall interval between two time broadcasts
DROP_LOG_PERIOD = 2.0  # [s] shortest wall interval between two drop reports
EXCLUDED_TOPICS = frozenset({'/parameter_events'})


def is_bridged(topic: str) -> bool:
    """Whether the bridge forwards `topic`: not hidden (no part starting with `_`), not
    /parameter_events."""
    return topic not in EXCLUDED_TOPICS and not any(
        part.startswith('_') for part in topic.split('/'))


class FoxgloveBridge:
    """The bridge node and its WebSocket server (see the module docstring). With `executor`
    the node is added to it and graph events schedule a `poll` on it (`GraphEvents`); without
    one only the POLL_PERIOD poll finds topics."""

    def __init__(self, port: int = DEFAULT_PORT, host: str = DEFAULT_HOST,
                 log=print, executor: Any = None) -> None:
        from rclpy.node import Node
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock

        self.log = log
        self.publishers: dict[str, Any] = {}  # topic -> a publisher of clients' messages
        self.server = FoxgloveServer(host, port, 'multilift',
                                     {'ROS_DISTRO': os.environ.get('ROS_DISTRO') or 'jazzy'},
                                     log, on_publish=self.publish)
        self.node = Node('multilift_foxglove', start_parameter_services=False)
        self.channels: dict[str, int] = {}  # topic -> channel id
        self.subscriptions: dict[str, Any] = {}  # topic -> AdaptiveSubscription
        self.types: dict[str, str] = {}  # topic -> pkg/msg/Type
        self._stamps: dict[str, tuple[int, bool] | None] = {}
        self._silent_since: dict[str, float] = {}
        self._skipped: set[str] = set()
        self.clock_ns: int | None = None
        self.sim_time = False
        self.forwarded = 0
        self._last_broadcast = 0.0
        self._last_drop_log = 0.0
        self._reported_drops = 0
        self.node.create_subscription(
            Clock, CLOCK, self._on_clock,
            QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT,
                       durability=DurabilityPolicy.VOLATILE))
        self.node.create_timer(POLL_PERIOD, self.poll)
        self.graph_events: GraphEvents | None = None
        self._executor = executor
        self._poll_scheduled = False
        self.poll()
        if executor is not None:
            executor.add_node(self.node)
            try:
                self.graph_events = GraphEvents(self.node, self._graph_changed)
            except (OSError, AttributeError, RuntimeError) as error:
                log(f'no graph events ({error}); polling the graph every {POLL_PERIOD} s')

    @property
    def port(self) -> int:
        """The port the server listens on."""
        return self.server.port

    @property
    def dropped(self) -> int:
        """Messages not forwarded to a client that fell CLIENT_BACKLOG messages behind."""
        return sum(self.server.dropped.values())

    # -- graph -----------------------------------------------------------------------------
    def _graph_changed(self) -> None:
        """From the GraphEvents thread: one poll on the executor for a burst of events (an event
        during that poll schedules the next)."""
        if not self._poll_scheduled:
            self._poll_scheduled = True
            self._executor.create_task(self._poll_after_event)

    def _poll_after_event(self) -> None:
        self._poll_scheduled = False
        self.poll()

    def poll(self) -> None:
        """Add channels for new topics, drop those without publishers, pick the time base."""
        graph = dict(self.node.get_topic_names_and_types())
        sim_time = self.node.count_publishers(CLOCK) > 0
        if sim_time != self.sim_time:
            self.sim_time = sim_time
            if not sim_time:
                self.clock_ns = None
            self.server.clear_session()
            self.log(f'time base: {"simulated (/clock)" if sim_time else "wall"}')
        now = time.monotonic()
        for topic in list(self.channels):
            if topic in graph and self.node.count_publishers(topic) > 0:
                self._silent_since.pop(topic, None)
                self.subscriptions[topic].adapt()
            elif now - self._silent_since.setdefault(topic, now) >= REMOVE_AFTER:
                self._remove(topic)
        for topic, types in sorted(graph.items()):
            if (topic in self.channels or topic in self._skipped or not is_bridged(topic)
                    or self.node.count_publishers(topic) == 0):
                continue
            self._add(topic, types[0])
        self._report_drops()

    def _add(self, topic: str, type_name: str) -> None:
        from multilift_sim.wire import msgdefs
        from multilift_sim.ros import introspection
        try:
            msg_type = introspection.import_message_type(type_name)
            definition = msgdefs.message_definition(type_name)
        except (ValueError, msgdefs.MessageDefinitionError) as error:
            self.log(f'not bridging {topic}: {error}')
            self._skipped.add(topic)
            return
        self._stamps[topic] = stamp_offset(msg_type)
        self.types[topic] = type_name
        channel_id = self.server.add_channel(topic, type_name, definition)
        self.channels[topic] = channel_id
        self.subscriptions[topic] = introspection.AdaptiveSubscription(
            self.node, msg_type, topic, functools.partial(self._on_message, topic, channel_id),
            depth=SUBSCRIPTION_DEPTH, raw=True)
        self.log(f'bridging {topic} [{type_name}]')

    def _remove(self, topic: str) -> None:
        self.subscriptions.pop(topic).destroy()
        self.server.remove_channel(self.channels.pop(topic))
        self.types.pop(topic, None)
        self._silent_since.pop(topic, None)
        self.log(f'{topic} has no publisher any more; channel closed')

    # -- messages --------------------------------------------------------------------------
    def _forward(self, topic: str, channel_id: int, data: bytes) -> None:
        stamp = cdr_stamp(data, self._stamps.get(topic))
        if stamp is None:
            stamp = stamp_ns(self.clock_ns, self.sim_time, time.time_ns())
        self.server.log(channel_id, stamp, data)
        self.forwarded += 1

    def _on_message(self, topic: str, channel_id: int, data: bytes) -> None:
        self._forward(topic, channel_id, data)
        subscription = self.subscriptions.get(topic)
        if subscription is None:
            return
        handle = subscription.subscription.handle
        for _ in range(TAKE_BATCH):
            with handle:
                taken = handle.take_message(subscription.msg_type, True)
            if taken is None:
                return
            self._forward(topic, channel_id, taken[0])

    def publish(self, topic: str, type_name: str, data: bytes | None) -> None:
        """A client's message (CDR bytes of `type_name`) on `topic`, published as a default
        node publishes (reliable, volatile, depth 10): a goal from Foxglove's publish panel
        (`/formation/goal`, `multilift run --live`); data None: the client advertised the
        channel (the publisher is made then). From the server's thread."""
        from multilift_sim.ros import introspection
        publisher = self.publishers.get(topic)
        if publisher is None or publisher.msg_type.__name__ != type_name.split('/')[-1]:
            if publisher is not None:
                self.node.destroy_publisher(publisher)
            publisher = self.node.create_publisher(
                introspection.import_message_type(type_name), topic, 10)
            self.publishers[topic] = publisher
            self.log(f'publishing clients\' {topic} [{type_name}]')
        if data is not None:
            publisher.publish(data)

    def _on_clock(self, msg: Any) -> None:
        self.clock_ns = msg.clock.sec * 1_000_000_000 + msg.clock.nanosec
        now = time.monotonic()
        if self.sim_time and now - self._last_broadcast >= TIME_BROADCAST_PERIOD:
            self._last_broadcast = now
            self.server.broadcast_time(self.clock_ns)

    def _report_drops(self, final: bool = False) -> None:
        dropped = self.dropped
        now = time.monotonic()
        if dropped != self._reported_drops and (final or now - self._last_drop_log
                                                >= DROP_LOG_PERIOD):
            self._last_drop_log = now
            self._reported_drops = dropped
            worst = self.server.dropped.most_common(3)
            self.log(f'dropped {dropped} messages so far (' + ', '.join(
                f'{topic}: {count}' for topic, count in worst) + ')')

    def broadcast_wall_time(self) -> None:
        """Tell clients the wall time when there is no simulated time."""
        if not self.sim_time:
            self.server.broadcast_time(time.time_ns())

    def close(self) -> None:
        """Stop the graph events and the server, destroy the node."""
        self._report_drops(final=True)
        if self.graph_events is not None:
            self.graph_events.close()
            if self.graph_events.error:
                self.log(f'graph events had stopped: {self.graph_events.error}')
        self.server.stop()
        self.node.destroy_node()
