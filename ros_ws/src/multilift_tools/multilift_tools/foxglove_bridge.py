"""`multilift foxglove [--port P] [--host H]`: the live ROS graph over the Foxglove WebSocket
protocol, for the Foxglove app (Open connection -> Foxglove WebSocket -> ws://localhost:8765).

A node (`multilift_foxglove`) polls the graph every POLL_PERIOD s and subscribes raw to every
topic that has a publisher (hidden topics and /parameter_events excepted); each topic is a
channel of a foxglove-sdk WebSocket server (subprotocol `foxglove.sdk.v1`) with message encoding
`cdr` and a `ros2msg` schema named `pkg/msg/Type` holding the full message definition
(`msgdefs.message_definition`, as in our bags), so the app decodes custom messages too. The CDR
bytes go out untouched. A topic whose publishers are gone loses its channel (the app is told);
it comes back when a publisher does.

Subscriptions: keep_last SUBSCRIPTION_DEPTH, reliable and transient_local when every publisher
offers it (`introspection.adapted_qos`), so a client that connects during a run still gets the
last messages our publishers keep.

Time: while /clock has a publisher (a simulation runs) each message is stamped with the
simulated time of the latest /clock message and the server broadcasts that time (capability
Time), so the app's clock and plots follow simulated time as in a bag; otherwise with wall time.
When the base changes (a run starts or ends) the server starts a new session so clients reset.

The server listens on 127.0.0.1 by default (--host 0.0.0.0 to serve other machines; the data is
not encrypted). SIGINT or SIGTERM stops it: exit code 0; a port in use is exit code 1.
"""

from __future__ import annotations

import argparse
import functools
import signal
import sys
import threading
import time
from typing import Any

from multilift_sim.topics import CLOCK

DEFAULT_PORT = 8765
DEFAULT_HOST = '127.0.0.1'
POLL_PERIOD = 0.5  # [s] graph poll for new and vanished topics
SUBSCRIPTION_DEPTH = 100  # keep_last depth of the raw subscriptions
TIME_BROADCAST_PERIOD = 0.02  # [s] shortest wall interval between two time broadcasts
EXCLUDED_TOPICS = frozenset({'/parameter_events'})
SUBPROTOCOL = 'foxglove.sdk.v1'


def is_bridged(topic: str) -> bool:
    """Whether the bridge forwards `topic`: not hidden (no part starting with `_`), not
    /parameter_events."""
    return topic not in EXCLUDED_TOPICS and not any(
        part.startswith('_') for part in topic.split('/'))


def stamp_ns(clock_ns: int | None, sim_time: bool, wall_ns: int) -> int:
    """Log time [ns] of a message: the latest /clock time (0 before the first one) when
    stamping with simulated time, else wall time."""
    if sim_time:
        return clock_ns or 0
    return wall_ns


class FoxgloveBridge:
    """The bridge node and its foxglove-sdk server (see the module docstring)."""

    def __init__(self, port: int = DEFAULT_PORT, host: str = DEFAULT_HOST,
                 log=print) -> None:
        import foxglove
        from rclpy.node import Node
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock
        from foxglove.websocket import Capability

        self._foxglove = foxglove
        self.log = log
        self.context = foxglove.Context()
        self.server = foxglove.start_server(
            name='multilift', host=host, port=port, capabilities=[Capability.Time],
            supported_encodings=['cdr'], context=self.context)
        self.node = Node('multilift_foxglove', start_parameter_services=False)
        self.channels: dict[str, Any] = {}  # topic -> foxglove Channel
        self.subscriptions: dict[str, Any] = {}  # topic -> rclpy Subscription
        self.types: dict[str, str] = {}  # topic -> pkg/msg/Type
        self._skipped: set[str] = set()
        self.clock_ns: int | None = None
        self.sim_time = False
        self.forwarded = 0
        self._last_broadcast = 0.0
        self.node.create_subscription(
            Clock, CLOCK, self._on_clock,
            QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT,
                       durability=DurabilityPolicy.VOLATILE))
        self.node.create_timer(POLL_PERIOD, self.poll)
        self.poll()

    @property
    def port(self) -> int:
        """The port the server listens on."""
        return self.server.port

    # -- graph -----------------------------------------------------------------------------
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
        for topic in list(self.channels):
            if topic not in graph or self.node.count_publishers(topic) == 0:
                self._remove(topic)
        for topic, types in sorted(graph.items()):
            if (topic in self.channels or topic in self._skipped or not is_bridged(topic)
                    or self.node.count_publishers(topic) == 0):
                continue
            self._add(topic, types[0])

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
        schema = self._foxglove.Schema(name=type_name, encoding=msgdefs.SCHEMA_ENCODING,
                                       data=definition.encode('utf-8'))
        channel = self._foxglove.Channel(topic, message_encoding='cdr', schema=schema,
                                         context=self.context)
        qos = introspection.adapted_qos(self.node.get_publishers_info_by_topic(topic),
                                        depth=SUBSCRIPTION_DEPTH)
        self.channels[topic] = channel
        self.types[topic] = type_name
        self.subscriptions[topic] = self.node.create_subscription(
            msg_type, topic, functools.partial(self._on_message, channel), qos, raw=True)
        self.log(f'bridging {topic} [{type_name}]')

    def _remove(self, topic: str) -> None:
        self.node.destroy_subscription(self.subscriptions.pop(topic))
        self.channels.pop(topic).close()
        self.types.pop(topic, None)
        self.log(f'{topic} has no publisher any more; channel closed')

    # -- messages --------------------------------------------------------------------------
    def _on_message(self, channel: Any, data: bytes) -> None:
        channel.log(data, log_time=stamp_ns(self.clock_ns, self.sim_time, time.time_ns()))
        self.forwarded += 1

    def _on_clock(self, msg: Any) -> None:
        self.clock_ns = msg.clock.sec * 1_000_000_000 + msg.clock.nanosec
        now = time.monotonic()
        if self.sim_time and now - self._last_broadcast >= TIME_BROADCAST_PERIOD:
            self._last_broadcast = now
            self.server.broadcast_time(self.clock_ns)

    def broadcast_wall_time(self) -> None:
        """Tell clients the wall time when there is no simulated time."""
        if not self.sim_time:
            self.server.broadcast_time(time.time_ns())

    def close(self) -> None:
        """Stop the server and destroy the node."""
        self.server.stop()
        self.node.destroy_node()


def foxglove_main(argv: list[str]) -> int:
    """`foxglove [--port P] [--host H]` (argv without the word `foxglove`); the exit code."""
    parser = argparse.ArgumentParser(prog='multilift foxglove', description=__doc__.split('\n')[0],
                                     epilog='See the foxglove_bridge module docstring.')
    parser.add_argument('--port', type=int, default=DEFAULT_PORT,
                        help=f'TCP port (default {DEFAULT_PORT}; 0: any free port)')
    parser.add_argument('--host', default=DEFAULT_HOST,
                        help=f'address to listen on (default {DEFAULT_HOST})')
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    if not 0 <= args.port <= 65535:
        print(f'foxglove: --port {args.port} is not a TCP port', file=sys.stderr)
        return 2

    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.signals import SignalHandlerOptions

    from multilift_sim.ros.common import make_executor

    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda signum, frame: stop.set())
    signal.signal(signal.SIGTERM, lambda signum, frame: stop.set())

    def log(text: str) -> None:
        print(f'foxglove: {text}', flush=True)

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    bridge = None
    try:
        try:
            bridge = FoxgloveBridge(args.port, args.host, log)
        except RuntimeError as error:  # the server could not bind
            print(f'foxglove: cannot serve on {args.host}:{args.port}: {error}', file=sys.stderr)
            return 1
        log(f'serving ws://{args.host}:{bridge.port} (subprotocol {SUBPROTOCOL}); '
            'Ctrl-C stops')
        executor = make_executor()
        executor.add_node(bridge.node)
        last_wall_broadcast = 0.0
        while not stop.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=0.1)
            if time.monotonic() - last_wall_broadcast >= POLL_PERIOD:
                last_wall_broadcast = time.monotonic()
                bridge.broadcast_wall_time()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if bridge is not None:
            log(f'stopped after forwarding {bridge.forwarded} messages')
            bridge.close()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(foxglove_main(sys.argv[1:]))
