"""`multilift topic ...` and `multilift node ...`: what `ros2 topic` and `ros2 run` do.

    topic list [-t]                      topic names (with [types] for -t), sorted
    topic echo TOPIC [TYPE] [--once]     messages as YAML, `---` after each (Ctrl-C ends)
    topic info TOPIC                     type, publisher and subscription counts
    topic hz TOPIC [-w N] [--wall-time] [--use-sim-time]
                                         receive rate, as `ros2 topic hz` (Ctrl-C ends)
    node PKG EXECUTABLE [ARGS...]        exec <prefix>/lib/PKG/EXECUTABLE found on AMENT_PREFIX_PATH

The topic tools wait up to DISCOVERY_WAIT [s] for the ROS graph to settle (ros2cli's daemonless mode
waits too), `info` and `echo` up to TOPIC_WAIT [s] for the topic they are given; set
ROS_DOMAIN_ID / ROS_AUTOMATIC_DISCOVERY_RANGE as for the nodes you inspect.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
import time
from pathlib import Path

from multilift_sim.wire.msgdefs import ament_prefixes

DISCOVERY_WAIT = 3.0  # [s] longest wait for the graph (Fast DDS may take 2.5 s to discover)
# [s] longest wait for a named topic to appear (the wait ends when it does): on a loaded machine
# discovering a publisher took longer than DISCOVERY_WAIT (a fresh-clone CI run's `topic echo`
# of a latched topic found no publisher in 3 s)
TOPIC_WAIT = 15.0
SETTLE = 0.5  # [s] without graph change, once another node is seen, that ends the wait
HZ_WINDOW = 10000  # messages `topic hz` averages over by default (ros2 topic hz's default)
HZ_DEPTH = 100  # keep_last depth of `topic hz`'s subscription
ADAPT_PERIOD = 0.2  # [s] how often `topic echo` compares its QoS with the publishers' offers
# Ctrl-C (SIGINT) or SIGTERM asked the topic tool to stop: a flag its loops read. Raising
# KeyboardInterrupt from the signal, or letting rclpy's handler shut the context down, could
# land inside rclpy's taking of a message, which then failed as a RuntimeError ("Unable to
# convert call argument") and the tool exited 1 (seen in `topic hz` under a full test run).
_STOP = threading.Event()


def _running() -> bool:
    import rclpy
    return rclpy.ok() and not _STOP.is_set()


def _stop_if_asked() -> None:
    """Out of rclpy's calls, turn a stop request into KeyboardInterrupt (`topic_main`: exit 0)."""
    if _STOP.is_set():
        raise KeyboardInterrupt


def _spin_graph(node, until=None, timeout: float = DISCOVERY_WAIT) -> None:
    """Spin `node` until `until()` holds (or, without `until`, until another node is known and
    the graph has not changed for SETTLE s), at most `timeout` [s]."""
    import rclpy
    start = last_change = time.monotonic()
    seen = None
    while time.monotonic() - start < timeout:
        _stop_if_asked()
        rclpy.spin_once(node, timeout_sec=0.05)
        if until is not None:
            if until():
                return
            continue
        graph = sorted((t, tuple(ty), node.count_publishers(t), node.count_subscribers(t))
                       for t, ty in node.get_topic_names_and_types())
        if graph != seen:
            seen, last_change = graph, time.monotonic()
        elif (time.monotonic() - last_change >= SETTLE
              and len(node.get_node_names()) > 1):
            return


def _topic_list(node, args: argparse.Namespace) -> int:
    _spin_graph(node)
    for topic, types in sorted(node.get_topic_names_and_types()):
        print(f'{topic} [{", ".join(types)}]' if args.show_types else topic)
    return 0


def _has_topic(node, topic: str):
    return lambda: topic in dict(node.get_topic_names_and_types())


def _topic_info(node, args: argparse.Namespace) -> int:
    # the topic first (a node may be seen a moment before its topics), then the graph settled
    # (every publisher and subscription counted); an unknown topic waits TOPIC_WAIT
    _spin_graph(node, until=_has_topic(node, args.topic), timeout=TOPIC_WAIT)
    _spin_graph(node)
    types = dict(node.get_topic_names_and_types()).get(args.topic)
    if types is None:
        print(f"Unknown topic '{args.topic}'", file=sys.stderr)
        return 1
    print(f'Type: {"; ".join(types)}')
    print(f'Publisher count: {node.count_publishers(args.topic)}')
    print(f'Subscription count: {node.count_subscribers(args.topic)}')
    return 0


def _topic_echo(node, args: argparse.Namespace) -> int:
    import rclpy
    from multilift_sim.ros import introspection
    type_name = args.type
    if type_name is None:
        _spin_graph(node, until=_has_topic(node, args.topic), timeout=TOPIC_WAIT)
        types = dict(node.get_topic_names_and_types()).get(args.topic)
        if not types:
            print(f"Could not determine the type for the passed topic '{args.topic}' "
                  '(nothing publishes it yet?); give the type: topic echo TOPIC pkg/msg/Type',
                  file=sys.stderr)
            return 1
        type_name = types[0]
    try:
        msg_type = introspection.import_message_type(type_name)
    except ValueError as error:
        print(f'topic echo: {error}', file=sys.stderr)
        return 1
    received = []

    def on_message(msg) -> None:
        if args.once and received:
            return
        received.append(True)
        sys.stdout.write(introspection.message_to_yaml(msg) + '---\n')
        sys.stdout.flush()

    # QoS adapted to the publishers, and again when one appears that it would not match
    # (a transient_local request misses a volatile publisher): a latched message is printed
    # whichever of the publisher and this subscription came first
    subscription = introspection.AdaptiveSubscription(node, msg_type, args.topic, on_message,
                                                      depth=10)
    next_check = time.monotonic() + ADAPT_PERIOD
    while _running() and not (args.once and received):
        rclpy.spin_once(node, timeout_sec=0.1)
        if time.monotonic() >= next_check:
            next_check = time.monotonic() + ADAPT_PERIOD
            subscription.adapt()
    return 0


class RateWindow:
    """Receive-rate statistics of one topic, computed as `ros2 topic hz` (Jazzy) does.

    `add(t_ns)` takes the receive time [ns] of each message on the chosen clock; `report()`
    gives (rate [Hz], min, max, std dev of the intervals [s], intervals in the window) at most
    once per second of that clock, else None. A time of 0 (ROS time before the first /clock)
    is ignored, as ros2's. A clock that goes back (a new run, a looping `bag play`) restarts the
    window and the once-a-second schedule; ros2 keeps the schedule and so stays silent until
    the new clock passes the old time.
    """

    def __init__(self, window: int = HZ_WINDOW) -> None:
        self.window = window
        self.intervals: list[int] = []  # [ns]
        self.first_ns = -1
        self.last_ns = 0
        self.last_printed_ns = 0

    def add(self, t_ns: int) -> None:
        """One message received at `t_ns` [ns]."""
        if t_ns == 0:
            self.intervals = []
            return
        if self.first_ns < 0 or self.first_ns > t_ns or t_ns < self.last_ns:
            self.first_ns = self.last_ns = t_ns
            self.intervals = []
            self.last_printed_ns = 0
            return
        self.intervals.append(t_ns - self.last_ns)
        self.last_ns = t_ns
        if len(self.intervals) > self.window:
            self.intervals.pop(0)

    def report(self) -> tuple[float, float, float, float, int] | None:
        """(rate [Hz], min [s], max [s], std dev [s], window) once a second, else None."""
        if not self.intervals:
            return None
        if self.last_printed_ns == 0:
            self.last_printed_ns = self.last_ns
            return None
        if self.last_ns < self.last_printed_ns + 1_000_000_000:
            return None
        n = len(self.intervals)
        mean = sum(self.intervals) / n
        std = (sum((x - mean) ** 2 for x in self.intervals) / n) ** 0.5
        self.last_printed_ns = self.last_ns
        rate = 1e9 / mean if mean > 0 else 0.0
        return rate, min(self.intervals) * 1e-9, max(self.intervals) * 1e-9, std * 1e-9, n


def format_hz(rate: float, min_s: float, max_s: float, std_s: float, window: int) -> str:
    """Two lines as `ros2 topic hz` prints them (rate [Hz], intervals [s])."""
    return (f'average rate: {rate:.3f}\n\tmin: {min_s:.3f}s max: {max_s:.3f}s '
            f'std dev: {std_s:.5f}s window: {window}')


def _topic_hz(node, args: argparse.Namespace) -> int:
    import rclpy
    from rclpy.clock import Clock, ClockType
    from rclpy.qos import DurabilityPolicy
    from multilift_sim.ros import introspection
    _spin_graph(node, until=_has_topic(node, args.topic))
    if args.topic not in dict(node.get_topic_names_and_types()):
        print(f'WARNING: topic [{args.topic}] does not appear to be published yet',
              file=sys.stderr, flush=True)
        while rclpy.ok() and args.topic not in dict(node.get_topic_names_and_types()):
            _stop_if_asked()
            rclpy.spin_once(node, timeout_sec=0.1)
    type_name = dict(node.get_topic_names_and_types())[args.topic][0]
    try:
        msg_type = introspection.import_message_type(type_name)
    except ValueError as error:
        print(f'topic hz: {error}', file=sys.stderr)
        return 1
    qos = introspection.adapted_qos(node.get_publishers_info_by_topic(args.topic),
                                    depth=HZ_DEPTH)
    qos.durability = DurabilityPolicy.VOLATILE  # a latched backlog would be one burst
    clock = Clock(clock_type=ClockType.SYSTEM_TIME) if args.wall_time else node.get_clock()
    stats = RateWindow(args.window)
    node.create_subscription(msg_type, args.topic,
                             lambda data: stats.add(clock.now().nanoseconds), qos, raw=True)
    while _running():
        rclpy.spin_once(node, timeout_sec=0.1)
        result = stats.report()
        if result is not None:
            print(format_hz(*result), flush=True)
    return 0


def _window_size(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError('window must be a positive number of messages')
    return value


def topic_main(argv: list[str]) -> int:
    """`topic list|echo|info|hz ...` (argv without the word `topic`); returns the exit code."""
    parser = argparse.ArgumentParser(prog='multilift topic', description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    verbs = parser.add_subparsers(dest='verb', required=True)
    listing = verbs.add_parser('list', help='list topics')
    listing.add_argument('-t', '--show-types', action='store_true', help='print topic types')
    echo = verbs.add_parser('echo', help='print messages of a topic as YAML')
    echo.add_argument('topic')
    echo.add_argument('type', nargs='?', help='pkg/msg/Type (default: from the graph)')
    echo.add_argument('--once', action='store_true', help='print one message and exit')
    info = verbs.add_parser('info', help='type and endpoint counts of a topic')
    info.add_argument('topic')
    hz = verbs.add_parser('hz', help='receive rate of a topic, as ros2 topic hz')
    hz.add_argument('topic')
    hz.add_argument('-w', '--window', type=_window_size, default=HZ_WINDOW,
                    help=f'messages to average over (default {HZ_WINDOW})')
    hz.add_argument('--wall-time', action='store_true',
                    help='time receipts on the wall clock even with --use-sim-time')
    hz.add_argument('--use-sim-time', action='store_true',
                    help='time receipts on /clock (simulated time) instead of the system clock')
    args = parser.parse_args(argv)

    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.parameter import Parameter
    from rclpy.signals import SignalHandlerOptions
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: _STOP.set())
    overrides = ([Parameter('use_sim_time', Parameter.Type.BOOL, True)]
                 if getattr(args, 'use_sim_time', False) else [])
    node = rclpy.create_node(f'_multilift_topic_{os.getpid()}', start_parameter_services=False,
                             parameter_overrides=overrides)
    try:
        return {'list': _topic_list, 'info': _topic_info, 'echo': _topic_echo,
                'hz': _topic_hz}[args.verb](node, args)
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def package_executables(package: str) -> tuple[Path | None, list[str]]:
    """`(<prefix>/lib/<package>, executables in it)` of the first prefix that has the package."""
    for prefix in ament_prefixes():
        marker = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / package
        if marker.is_file():
            lib = prefix / 'lib' / package
            names = sorted(p.name for p in lib.iterdir()
                           if p.is_file() and os.access(p, os.X_OK)) if lib.is_dir() else []
            return lib, names
    return None, []


def node_main(argv: list[str]) -> int:
    """`node PKG EXECUTABLE [ARGS...]`: replace this process by the executable, as `ros2 run`.

    Returns only on error (exit code 1); on success the executable's exit code is the process's.
    """
    if len(argv) < 2 or argv[0] in ('-h', '--help'):
        print('usage: multilift node PKG EXECUTABLE [ARGS...]  (as ros2 run; e.g. '
              'multilift node multilift_sim recorder_node --ros-args -p bag:=DIR)',
              file=sys.stderr)
        return 1 if len(argv) < 2 else 0
    package, executable, rest = argv[0], argv[1], argv[2:]
    lib, names = package_executables(package)
    if lib is None:
        print(f"Package '{package}' not found on AMENT_PREFIX_PATH "
              '(source scripts/env.sh and build with scripts/setup)', file=sys.stderr)
        return 1
    if executable not in names:
        listed = ', '.join(names) if names else 'none'
        print(f"No executable '{executable}' in package '{package}' ({lib}); "
              f'its executables: {listed}', file=sys.stderr)
        return 1
    path = lib / executable
    sys.stdout.flush()
    sys.stderr.flush()
    os.execv(path, [str(path), *rest])
    return 1  # not reached
