"""`multilift foxglove [--port P] [--host H]`: the live ROS graph over the Foxglove WebSocket
protocol, for the Foxglove app (Open connection -> Foxglove WebSocket -> ws://localhost:8765).
`multilift foxglove --layout FILE SCENARIO` writes a Foxglove layout for a scenario instead.

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
decodes custom messages too. The CDR bytes go out untouched. The WebSocket server is this
module's own (`FoxgloveServer`, the `websockets` package, subprotocols foxglove.websocket.v1 and
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
run starts or ends) the server starts a new session so clients reset.

Drops: each client has a queue of CLIENT_BACKLOG messages; what does not fit (a client slower
than the run) is dropped, counted per topic and logged, and the total is printed at the end.
Not counted: a subscription overrun (more than SUBSCRIPTION_DEPTH messages of a topic waiting
to be taken), which the batched takes make unlikely; a message does not name its publisher, so
gaps in publication sequence numbers cannot be told apart from another publisher's numbers.

The server listens on 127.0.0.1 by default (--host 0.0.0.0 to serve other machines; the data is
not encrypted). SIGINT or SIGTERM stops it: exit code 0; a port in use is exit code 1.
"""

from __future__ import annotations

import argparse
import asyncio
import collections
import functools
import json
import os
import signal
import struct
import sys
import threading
import time
from typing import Any

from multilift_sim.topics import CLOCK

DEFAULT_PORT = 8765
DEFAULT_HOST = '127.0.0.1'
POLL_PERIOD = 1.0  # [s] fallback graph poll (graph events come first) and channel removal
WALL_TIME_PERIOD = 0.5  # [s] wall time broadcast while there is no /clock
REMOVE_AFTER = 2.0  # [s] without a publisher before a topic's channel is removed
SUBSCRIPTION_DEPTH = 1000  # keep_last depth of the raw subscriptions
TAKE_BATCH = 256  # messages of one topic taken in one callback (see recorder_node)
CLIENT_BACKLOG = 200_000  # messages queued for one client before drops
REPLAY = 1000  # last messages of a channel a new subscription gets first (as transient_local)
TIME_BROADCAST_PERIOD = 0.02  # [s] shortest wall interval between two time broadcasts
DROP_LOG_PERIOD = 2.0  # [s] shortest wall interval between two drop reports
EXCLUDED_TOPICS = frozenset({'/parameter_events'})
SUBPROTOCOL = 'foxglove.sdk.v1'
SUBPROTOCOLS = ('foxglove.websocket.v1', SUBPROTOCOL)  # the app's, foxglove-sdk's
MESSAGE_DATA, TIME = 0x01, 0x02  # binary opcodes (server -> client)


def is_bridged(topic: str) -> bool:
    """Whether the bridge forwards `topic`: not hidden (no part starting with `_`), not
    /parameter_events."""
    return topic not in EXCLUDED_TOPICS and not any(
        part.startswith('_') for part in topic.split('/'))


def stamp_ns(clock_ns: int | None, sim_time: bool, wall_ns: int) -> int:
    """Time [ns] of a message without a stamp of its own: the latest /clock time (0 before the
    first one) when stamping with simulated time, else wall time."""
    if sim_time:
        return clock_ns or 0
    return wall_ns


def stamp_offset(msg_type: type) -> tuple[int, bool] | None:
    """Where a message's own time is in its CDR bytes: (offset of `sec`, whether it is the first
    element of a sequence) for a message whose first field is a std_msgs/Header or a
    builtin_interfaces/Time, or a sequence of such messages; None without one."""
    from multilift_sim.ros.introspection import import_message_type
    fields = list(msg_type.get_fields_and_field_types().values())
    if not fields:
        return None
    first = fields[0]
    if first in ('std_msgs/Header', 'builtin_interfaces/Time'):
        return 4, False
    if first.startswith('sequence<') and '/' in first:
        element = first[len('sequence<'):].rstrip('>').split(',')[0]
        package, name = element.split('/')
        try:
            inner = import_message_type(f'{package}/msg/{name}')
        except ValueError:
            return None
        if stamp_offset(inner) == (4, False):
            return 8, True
    return None


def cdr_stamp(data: bytes, where: tuple[int, bool] | None) -> int | None:
    """The stamp [ns] at `where` (`stamp_offset`) in CDR `data`, or None (none there)."""
    if where is None or len(data) < where[0] + 8:
        return None
    order = '<' if data[1] & 1 else '>'
    offset, in_sequence = where
    if in_sequence and struct.unpack_from(order + 'I', data, 4)[0] == 0:
        return None
    sec, nanosec = struct.unpack_from(order + 'iI', data, offset)
    return sec * 1_000_000_000 + nanosec


class _Client:
    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.subscriptions: dict[int, int] = {}  # subscription id -> channel id
        self.by_channel: dict[int, int] = {}  # channel id -> subscription id
        self.queue: collections.deque = collections.deque()
        self.ready = asyncio.Event()


class FoxgloveServer:
    """A Foxglove WebSocket protocol server (the parts a live view uses: server info,
    advertise/unadvertise, subscribe/unsubscribe, message data, time, status), on an asyncio
    loop in a thread of its own. `add_channel`, `remove_channel`, `log`, `broadcast_time` and
    `clear_session` may be called from any thread."""

    def __init__(self, host: str, port: int, name: str, metadata: dict[str, str],
                 log=print) -> None:
        self.name, self.metadata, self.log_line = name, metadata, log
        self.channels: dict[int, dict] = {}
        self._ids: dict[str, int] = {}  # topic -> channel id (kept, reused on return)
        self._lock = threading.Lock()
        self._clients: set[_Client] = set()
        self._pending: collections.deque = collections.deque()
        self._history: dict[int, collections.deque] = {}  # channel id -> (log_time, data)
        self._scheduled = False
        self.session_id = str(time.time_ns())
        self.dropped: collections.Counter = collections.Counter()  # topic -> messages
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self.loop.run_forever, daemon=True,
                                        name='foxglove-server')
        self._thread.start()
        try:
            self._server = asyncio.run_coroutine_threadsafe(self._serve(host, port),
                                                            self.loop).result()
        except OSError as error:
            self.loop.call_soon_threadsafe(self.loop.stop)
            self._thread.join(timeout=5)
            raise RuntimeError(str(error)) from None
        self.port = self._server.sockets[0].getsockname()[1]

    async def _serve(self, host: str, port: int):
        from websockets.asyncio.server import serve
        return await serve(self._handle, host, port, subprotocols=list(SUBPROTOCOLS),
                           compression=None, max_size=None, max_queue=None)

    # -- from any thread -------------------------------------------------------------------
    def add_channel(self, topic: str, schema_name: str, schema: str) -> int:
        """Register a channel (its id) and then advertise it."""
        with self._lock:
            channel_id = self._ids.setdefault(topic, len(self._ids) + 1)
            self.channels[channel_id] = {
                'id': channel_id, 'topic': topic, 'encoding': 'cdr', 'schemaName': schema_name,
                'schema': schema, 'schemaEncoding': 'ros2msg'}
        self._call(self._broadcast_json, {'op': 'advertise',
                                          'channels': [self.channels[channel_id]]})
        return channel_id

    def remove_channel(self, channel_id: int) -> None:
        with self._lock:
            self.channels.pop(channel_id, None)
        self._call(self._unadvertise, channel_id)

    def log(self, channel_id: int, log_time: int, data: bytes) -> None:
        """Send one message of a channel to every client subscribed to it."""
        self._pending.append((channel_id, log_time, data))
        if not self._scheduled:
            self._scheduled = True
            self._call(self._dispatch)

    def broadcast_time(self, t_ns: int) -> None:
        self._call(self._broadcast_binary, struct.pack('<BQ', TIME, max(0, t_ns)))

    def clear_session(self) -> None:
        """A new session id: clients reset their state (new server info)."""
        self.session_id = str(time.time_ns())
        self._call(self._broadcast_json, self._server_info())

    def stop(self) -> None:
        async def close() -> None:
            self._server.close()
            await self._server.wait_closed()
        try:
            asyncio.run_coroutine_threadsafe(close(), self.loop).result(timeout=5)
        except Exception:  # noqa: BLE001 - stopping anyway
            pass
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(timeout=5)

    def _call(self, function, *args) -> None:
        try:
            self.loop.call_soon_threadsafe(function, *args)
        except RuntimeError:  # the loop is closed: stopping
            pass

    # -- on the loop -----------------------------------------------------------------------
    def _server_info(self) -> dict:
        return {'op': 'serverInfo', 'name': self.name, 'capabilities': ['time'],
                'supportedEncodings': [], 'metadata': dict(self.metadata),
                'sessionId': self.session_id}

    def _dispatch(self) -> None:
        self._scheduled = False
        pending, self._pending = self._pending, collections.deque()
        for channel_id, log_time, data in pending:
            history = self._history.get(channel_id)
            if history is None:
                history = self._history[channel_id] = collections.deque(maxlen=REPLAY)
            history.append((log_time, data))
            for client in self._clients:
                sub_id = client.by_channel.get(channel_id)
                if sub_id is None:
                    continue
                if len(client.queue) >= CLIENT_BACKLOG:
                    channel = self.channels.get(channel_id)
                    self.dropped[channel['topic'] if channel else '?'] += 1
                    continue
                client.queue.append(struct.pack('<BIQ', MESSAGE_DATA, sub_id, log_time) + data)
                client.ready.set()

    def _enqueue(self, client: _Client, frame) -> None:
        client.queue.append(frame)
        client.ready.set()

    def _broadcast_json(self, message: dict) -> None:
        text = json.dumps(message)
        for client in self._clients:
            self._enqueue(client, text)

    def _broadcast_binary(self, frame: bytes) -> None:
        for client in self._clients:
            self._enqueue(client, frame)

    def _unadvertise(self, channel_id: int) -> None:
        self._history.pop(channel_id, None)
        for client in self._clients:
            sub_id = client.by_channel.pop(channel_id, None)
            if sub_id is not None:
                client.subscriptions.pop(sub_id, None)
        self._broadcast_json({'op': 'unadvertise', 'channelIds': [channel_id]})

    async def _handle(self, ws) -> None:
        client = _Client(ws)
        self._enqueue(client, json.dumps(self._server_info()))
        with self._lock:
            channels = list(self.channels.values())
        if channels:
            self._enqueue(client, json.dumps({'op': 'advertise', 'channels': channels}))
        self._clients.add(client)
        writer = asyncio.ensure_future(self._write(client))
        try:
            async for text in ws:
                if isinstance(text, str):
                    self._on_client_message(client, text)
        except Exception:  # noqa: BLE001 - a client that went away
            pass
        finally:
            self._clients.discard(client)
            writer.cancel()

    async def _write(self, client: _Client) -> None:
        while True:
            await client.ready.wait()
            client.ready.clear()
            while client.queue:
                await client.ws.send(client.queue.popleft())

    def _status(self, client: _Client, level: int, message: str) -> None:
        self._enqueue(client, json.dumps({'op': 'status', 'level': level, 'message': message}))

    def _on_client_message(self, client: _Client, text: str) -> None:
        try:
            message = json.loads(text)
        except ValueError:
            return
        if message.get('op') == 'subscribe':
            for sub in message.get('subscriptions', []):
                channel_id, sub_id = sub.get('channelId'), sub.get('id')
                if channel_id not in self.channels:
                    self._status(client, 2, f'Unknown channel ID: {channel_id}')
                    continue
                client.subscriptions[sub_id] = channel_id
                client.by_channel[channel_id] = sub_id
                # what the channel carried before this subscription (a client subscribes a
                # moment after the advertisement, when the publishers' kept messages may have
                # arrived already): the last REPLAY messages, then the live ones
                for log_time, data in self._history.get(channel_id, ()):
                    client.queue.append(struct.pack('<BIQ', MESSAGE_DATA, sub_id, log_time)
                                        + data)
                client.ready.set()
        elif message.get('op') == 'unsubscribe':
            for sub_id in message.get('subscriptionIds', []):
                channel_id = client.subscriptions.pop(sub_id, None)
                if channel_id is not None:
                    client.by_channel.pop(channel_id, None)


class GraphEvents:
    """Calls `on_change()`, from a thread of its own, each time the rmw reports a change of the
    ROS graph as `node` sees it (a participant, publisher or subscription discovered or gone):
    rcl's graph guard condition of the node (`rcl_node_get_graph_guard_condition`). rclpy
    (Jazzy) neither exposes it nor lets its EventsExecutor wait on guard conditions, so the
    thread waits on it in an rcl wait set of its own, through ctypes on librcl (the library
    rclpy has loaded), together with a guard condition of its own that `close` triggers.
    `on_change` should be cheap: a burst of discovery events calls it once per event."""

    def __init__(self, node: Any, on_change) -> None:
        import ctypes
        from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

        class WaitSet(ctypes.Structure):  # rcl_wait_set_t (rcl/wait.h)
            _fields_ = [(f'{kind}{part}', ctypes.c_void_p if part == 's' else ctypes.c_size_t)
                        for kind in ('subscription', 'guard_condition', 'timer', 'client',
                                     'service', 'event') for part in ('s', '_count')] + [
                ('impl', ctypes.c_void_p)]

        class Allocator(ctypes.Structure):  # rcutils_allocator_t
            _fields_ = [(name, ctypes.c_void_p) for name in (
                'allocate', 'deallocate', 'reallocate', 'zero_allocate', 'state')]

        rcl, rcutils = ctypes.CDLL('librcl.so'), ctypes.CDLL('librcutils.so')
        rcutils.rcutils_get_default_allocator.restype = Allocator
        rcl.rcl_node_get_graph_guard_condition.restype = ctypes.c_void_p
        rcl.rcl_node_get_graph_guard_condition.argtypes = [ctypes.c_void_p]
        wait_set_p = ctypes.POINTER(WaitSet)
        rcl.rcl_wait_set_init.argtypes = [wait_set_p] + [ctypes.c_size_t] * 6 + [
            ctypes.c_void_p, Allocator]
        rcl.rcl_wait_set_add_guard_condition.argtypes = [wait_set_p, ctypes.c_void_p,
                                                         ctypes.c_void_p]
        rcl.rcl_wait_set_clear.argtypes = [wait_set_p]
        rcl.rcl_wait.argtypes = [wait_set_p, ctypes.c_int64]
        rcl.rcl_wait_set_fini.argtypes = [wait_set_p]
        self._rcl, self._rcutils, self._ctypes = rcl, rcutils, ctypes
        self.on_change = on_change
        self._node = node  # keeps the rcl node (and its graph guard condition) alive
        self._graph = rcl.rcl_node_get_graph_guard_condition(node.handle.pointer)
        if not self._graph:
            raise RuntimeError('the node has no graph guard condition')
        self._stop = _rclpy.GuardCondition(node.context.handle)
        self._wait_set = WaitSet()
        ret = rcl.rcl_wait_set_init(ctypes.byref(self._wait_set), 0, 2, 0, 0, 0, 0,
                                    node.context.handle.pointer,
                                    rcutils.rcutils_get_default_allocator())
        if ret != 0:
            rcutils.rcutils_reset_error()
            self._stop.destroy_when_not_in_use()
            raise RuntimeError(f'rcl_wait_set_init returned {ret}')
        self._stopping = False
        self.error: str | None = None
        self._thread = threading.Thread(target=self._run, daemon=True, name='graph-events')
        self._thread.start()

    def _run(self) -> None:
        rcl, ctypes = self._rcl, self._ctypes
        wait_set = ctypes.byref(self._wait_set)
        while not self._stopping:
            rcl.rcl_wait_set_clear(wait_set)
            rcl.rcl_wait_set_add_guard_condition(wait_set, self._graph, None)
            rcl.rcl_wait_set_add_guard_condition(wait_set, self._stop.pointer, None)
            ret = rcl.rcl_wait(wait_set, -1)  # rcl_wait nulls the entries not triggered
            if self._stopping:
                return
            if ret != 0:
                self._rcutils.rcutils_reset_error()
                self.error = f'rcl_wait returned {ret}'
                return
            if ctypes.cast(self._wait_set.guard_conditions,
                           ctypes.POINTER(ctypes.c_void_p))[0]:
                try:
                    self.on_change()
                except Exception as error:  # noqa: BLE001 - the poll remains
                    self.error = f'{type(error).__name__}: {error}'
                    return

    def close(self) -> None:
        """Stop the thread (before the node is destroyed) and free the wait set."""
        self._stopping = True
        self._stop.trigger_guard_condition()
        self._thread.join(timeout=5)
        if not self._thread.is_alive():  # else it still waits: leave it its wait set
            self._rcl.rcl_wait_set_fini(self._ctypes.byref(self._wait_set))
            self._stop.destroy_when_not_in_use()


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
        self.server = FoxgloveServer(host, port, 'multilift',
                                     {'ROS_DISTRO': os.environ.get('ROS_DISTRO') or 'jazzy'},
                                     log)
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
        from multilift_sim import msgdefs
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


def foxglove_main(argv: list[str]) -> int:
    """`foxglove [--port P] [--host H]` or `foxglove --layout FILE SCENARIO` (argv without the
    word `foxglove`); the exit code."""
    parser = argparse.ArgumentParser(prog='multilift foxglove', description=__doc__.split('\n')[0],
                                     epilog='See the foxglove_bridge module docstring.')
    parser.add_argument('--port', type=int, default=DEFAULT_PORT,
                        help=f'TCP port (default {DEFAULT_PORT}; 0: any free port)')
    parser.add_argument('--host', default=DEFAULT_HOST,
                        help=f'address to listen on (default {DEFAULT_HOST})')
    parser.add_argument('--layout', metavar='FILE',
                        help='write a Foxglove layout for SCENARIO to FILE and exit')
    parser.add_argument('scenario', nargs='?', help='with --layout: a name in scenarios/ or a '
                                                    'YAML path')
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    if args.layout or args.scenario:
        if not (args.layout and args.scenario):
            print('foxglove: --layout FILE and SCENARIO go together', file=sys.stderr)
            return 2
        from multilift_sim.scenario import ScenarioError
        from multilift_tools.foxglove_layout import write_layout
        try:
            print(f'foxglove: layout of {args.scenario} written to '
                  f'{write_layout(args.layout, args.scenario)}')
        except (ScenarioError, OSError) as error:
            print(f'foxglove: {error}', file=sys.stderr)
            return 2
        return 0
    if not 0 <= args.port <= 65535:
        print(f'foxglove: --port {args.port} is not a TCP port', file=sys.stderr)
        return 2

    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.signals import SignalHandlerOptions

    from multilift_sim.ros.common import make_executor
    from multilift_sim.ros.fastdds import LIVE_VIEW_ANNOUNCEMENT, use_fastdds_profile
    from multilift_sim.ros.shared_memory import remove_before_start

    use_fastdds_profile(LIVE_VIEW_ANNOUNCEMENT)  # (scripts/multilift has set it already)
    remove_before_start()  # Fast DDS's shared memory of killed processes
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda signum, frame: stop.set())
    signal.signal(signal.SIGTERM, lambda signum, frame: stop.set())

    def log(text: str) -> None:
        print(f'foxglove: {text}', flush=True)

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    bridge = None
    try:
        executor = make_executor()
        try:
            bridge = FoxgloveBridge(args.port, args.host, log, executor)
        except RuntimeError as error:  # the server could not bind
            print(f'foxglove: cannot serve on {args.host}:{args.port}: {error}', file=sys.stderr)
            return 1
        log(f'serving ws://{args.host}:{bridge.port} (subprotocol {SUBPROTOCOL}); '
            'Ctrl-C stops')
        last_wall_broadcast = 0.0
        while not stop.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=0.1)
            if time.monotonic() - last_wall_broadcast >= WALL_TIME_PERIOD:
                last_wall_broadcast = time.monotonic()
                bridge.broadcast_wall_time()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if bridge is not None:
            log(f'stopped after forwarding {bridge.forwarded} messages '
                f'({bridge.dropped} dropped)')
            bridge.close()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(foxglove_main(sys.argv[1:]))
