"""`multilift foxglove [--port P] [--host H]`: the live ROS graph over the Foxglove WebSocket
protocol, for the Foxglove app (Open connection -> Foxglove WebSocket -> ws://localhost:8765).
`multilift foxglove --layout FILE SCENARIO` writes a Foxglove layout for a scenario instead.

The server listens on 127.0.0.1 by default (--host 0.0.0.0 to serve other machines; the data is
not encrypted). SIGINT or SIGTERM stops it: exit code 0; a port in use is exit code 1.

How the bridge forwards topics, their time and drops: multilift_tools.foxglove.bridge.
"""
from __future__ import annotations

import argparse
import signal
import sys
import threading
import time

from multilift_tools.foxglove.bridge import DEFAULT_HOST, DEFAULT_PORT, FoxgloveBridge
from multilift_tools.foxglove.server import SUBPROTOCOL

WALL_TIME_PERIOD = 0.5  # [s] wall time broadcast while there is no /clock


def foxglove_main(argv: list[str]) -> int:
    """`foxglove [--port P] [--host H]` or `foxglove --layout FILE SCENARIO` (argv without the
    word `foxglove`); the exit code."""
    parser = argparse.ArgumentParser(prog='multilift foxglove', description=__doc__.split('\n')[0],
                                     epilog='See the multilift_tools.foxglove package docstring.')
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
        from multilift_tools.foxglove.layout import write_layout
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
