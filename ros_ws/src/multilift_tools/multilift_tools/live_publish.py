"""Publishing one message to a live run and making sure it arrived: what `multilift goal`
(/formation/goal) and `multilift winch` (/uav{i}/winch_cmd) share.

`publish_acknowledged` waits until every reader of the topic the graph shows is matched and
named, a run's node among them (not only the recorder), the recorder too when the graph has
one, and none new for SETTLE s (a reader that matched after the message was sent would never
get it); then publishes reliable and transient local, waits for the acknowledgements, and stays
LINGER s for a reader matching late (a recorder discovered late on a loaded machine asks for
the kept message).
"""
from __future__ import annotations

import argparse
import sys
import time
from typing import Any, Callable

from multilift_sim.topics import CLOCK

SETTLE = 0.5  # [s] without a new reader of the topic before the message is sent
UNKNOWN = '_NODE_NAME_UNKNOWN_'  # an endpoint's node before its participant's names arrive
RECORDER = 'recorder'  # the recorder node's name (multilift_sim.ros.recorder_node)
LINGER = 2.0  # [s] the message kept for readers that match after it was acknowledged


def live_parser(command: str, doc: str) -> argparse.ArgumentParser:
    """The argument parser of `multilift COMMAND` (its description `doc`'s first line) with
    the option every live command has: --timeout, the wall seconds to wait for the run."""
    parser = argparse.ArgumentParser(prog=f'multilift {command}', description=doc.split('\n')[0])
    parser.add_argument('--timeout', type=float, default=10.0, metavar='S',
                        help='wall seconds to wait for the run (default 10)')
    return parser


def publish_acknowledged(command: str, msg_type: type, topic: str,
                         build: Callable[[int | None], Any], timeout: float,
                         needs_clock: bool) -> tuple[int, int | None]:
    """Publish `build(t_ns)` on `topic` once every reader is there (`t_ns` [ns]: the simulated
    time of the run's latest /clock, None when not `needs_clock`); (exit code, t_ns): 0 when
    acknowledged, 1 without a run (one line on stderr, `command` naming the tool)."""
    import rclpy
    from rclpy.duration import Duration
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    rclpy.init(args=None)
    node = Node(f'multilift_{command}', start_parameter_services=False)
    try:
        clock: list[int] = []
        if needs_clock:
            node.create_subscription(Clock, CLOCK, lambda m: clock.append(
                m.clock.sec * 1_000_000_000 + m.clock.nanosec), QoSProfile(
                depth=10, reliability=ReliabilityPolicy.BEST_EFFORT,
                durability=DurabilityPolicy.VOLATILE))
        # reliable and transient local: the recorder (subscribed from the start with that
        # request) matches it, and a reader that asks again after matching late gets it
        publisher = node.create_publisher(msg_type, topic, QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL))
        deadline = time.monotonic() + timeout
        seen: list = [None, time.monotonic()]  # the readers last seen, since when

        def readers_matched() -> bool:
            readers = node.get_subscriptions_info_by_topic(topic)
            names = sorted((r.node_name, r.node_namespace) for r in readers)
            if names != seen[0]:
                seen[:] = [names, time.monotonic()]
            reading = {r.node_name for r in readers}
            return (bool(readers) and UNKNOWN not in reading
                    and bool(reading - {RECORDER})
                    and (RECORDER in reading or RECORDER not in node.get_node_names())
                    and publisher.get_subscription_count() >= len(readers)
                    and time.monotonic() - seen[1] >= SETTLE)
        while time.monotonic() < deadline and not (
                readers_matched() and (clock or not needs_clock)):
            rclpy.spin_once(node, timeout_sec=0.05)
        if not readers_matched():
            print(f'error: {command}: nothing reads {topic} (is a run going with --live, on '
                  'this ROS_DOMAIN_ID?)', file=sys.stderr)
            return 1, None
        if needs_clock and not clock:
            print(f'error: {command}: no {CLOCK} from a run (give --at T)', file=sys.stderr)
            return 1, None
        t_ns = clock[-1] if clock else None
        publisher.publish(build(t_ns))
        if not publisher.wait_for_all_acked(
                Duration(seconds=max(deadline - time.monotonic(), 1.0))):
            print(f'error: {command}: {topic} not acknowledged by its readers', file=sys.stderr)
            return 1, None
        readers, until = publisher.get_subscription_count(), time.monotonic() + LINGER
        while time.monotonic() < until:
            rclpy.spin_once(node, timeout_sec=0.05)
            if publisher.get_subscription_count() > readers:
                readers, until = publisher.get_subscription_count(), time.monotonic() + LINGER
                publisher.wait_for_all_acked(Duration(seconds=LINGER))
        return 0, t_ns
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
