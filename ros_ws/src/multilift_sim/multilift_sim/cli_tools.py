"""`multilift topic ...` and `multilift node ...`: what `ros2 topic` and `ros2 run` do.

    topic list [-t]                      topic names (with [types] for -t), sorted
    topic echo TOPIC [TYPE] [--once]     messages as YAML, `---` after each (Ctrl-C ends)
    topic info TOPIC                     type, publisher and subscription counts
    node PKG EXECUTABLE [ARGS...]        exec <prefix>/lib/PKG/EXECUTABLE found on AMENT_PREFIX_PATH

The topic tools wait up to DISCOVERY_WAIT [s] for the ROS graph to settle (ros2cli's daemonless mode
waits too); set ROS_DOMAIN_ID / ROS_AUTOMATIC_DISCOVERY_RANGE as for the nodes you inspect.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from multilift_sim.msgdefs import ament_prefixes

DISCOVERY_WAIT = 3.0  # [s] longest wait for the graph (Fast DDS may take 2.5 s to discover)
SETTLE = 0.5  # [s] without graph change, once another node is seen, that ends the wait


def _spin_graph(node, until=None, timeout: float = DISCOVERY_WAIT) -> None:
    """Spin `node` until `until()` holds (or, without `until`, until another node is known and
    the graph has not changed for SETTLE s), at most `timeout` [s]."""
    import rclpy
    start = last_change = time.monotonic()
    seen = None
    while time.monotonic() - start < timeout:
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
    from multilift_sim import introspection
    type_name = args.type
    if type_name is None:
        _spin_graph(node, until=_has_topic(node, args.topic))
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
    qos = introspection.adapted_qos(node.get_publishers_info_by_topic(args.topic), depth=10)
    received = []

    def on_message(msg) -> None:
        if args.once and received:
            return
        received.append(True)
        sys.stdout.write(introspection.message_to_yaml(msg) + '---\n')
        sys.stdout.flush()

    node.create_subscription(msg_type, args.topic, on_message, qos)
    while rclpy.ok() and not (args.once and received):
        rclpy.spin_once(node, timeout_sec=0.1)
    return 0


def topic_main(argv: list[str]) -> int:
    """`topic list|echo|info ...` (argv without the word `topic`); returns the exit code."""
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
    args = parser.parse_args(argv)

    import rclpy
    from rclpy.executors import ExternalShutdownException
    rclpy.init()
    node = rclpy.create_node(f'_multilift_topic_{os.getpid()}', start_parameter_services=False)
    try:
        return {'list': _topic_list, 'info': _topic_info, 'echo': _topic_echo}[args.verb](
            node, args)
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
