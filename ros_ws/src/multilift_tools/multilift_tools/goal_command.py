"""`multilift goal X Y Z [--yaw DEG] [--at T] [--timeout S]`: send a live run's leader one goal.

Publishes one geometry_msgs/PoseStamped on `/formation/goal` (frame `world`, z up, [m]) for a
run started with `multilift run SCENARIO --live`: the formation flies there within the
scenario's `mission.max_speed` and `mission.max_acceleration`, then holds
(multilift_control.live_goals). Stamped with the simulated time of the run's latest `/clock`
(the goal takes effect at the next tick), or `--at T` [s]. Waits for the leader's subscription
and for its acknowledgement; exit 1 without a run, 2 on bad arguments.
"""
from __future__ import annotations

import argparse
import math
import sys
import time

from multilift_sim.topics import CLOCK, GOAL
from multilift_sim.wire.msgvalues import WORLD_FRAME, stamp

SETTLE = 0.5  # [s] without a new reader of the goal before it is sent (discovery settled)
UNKNOWN = '_NODE_NAME_UNKNOWN_'  # an endpoint's node before its participant's names arrive
RECORDER = 'recorder'  # the recorder node's name (multilift_sim.ros.recorder_node)
LINGER = 2.0  # [s] the goal kept for readers that match after it was acknowledged


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog='multilift goal', description=__doc__.split('\n')[0])
    for axis in 'XYZ':
        parser.add_argument(axis.lower(), type=float, metavar=axis, help=f'{axis} [m], world')
    parser.add_argument('--yaw', type=float, metavar='DEG',
                        help='heading [deg] (default: keep the current one)')
    parser.add_argument('--at', type=float, metavar='T',
                        help='simulated time [s] it takes effect (default: the latest /clock)')
    parser.add_argument('--timeout', type=float, default=10.0, metavar='S',
                        help='wall seconds to wait for the run (default 10)')
    return parser


def goal_main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    values = [args.x, args.y, args.z] + ([args.yaw] if args.yaw is not None else [])
    if not all(math.isfinite(v) for v in values) or args.timeout <= 0:
        print('error: goal: X Y Z and --yaw must be finite, --timeout > 0', file=sys.stderr)
        return 2
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from rclpy.duration import Duration
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    rclpy.init(args=None)
    node = Node('multilift_goal', start_parameter_services=False)
    try:
        clock: list[int] = []
        node.create_subscription(Clock, CLOCK, lambda m: clock.append(
            m.clock.sec * 1_000_000_000 + m.clock.nanosec), QoSProfile(
            depth=10, reliability=ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.VOLATILE))
        # reliable and transient local: the recorder (subscribed from the start with that
        # request) matches it, and the leader's kept reader (ros.live_input) asks for it again
        # if it matched after the message, so acknowledged is delivered
        publisher = node.create_publisher(PoseStamped, GOAL, QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL))
        deadline = time.monotonic() + args.timeout
        seen: list = [None, time.monotonic()]  # the readers last seen, since when

        def readers_matched() -> bool:
            """Every reader of GOAL the graph shows is matched, named, a leader's (not only a
            recorder's) among them, the recorder's too when the graph has a recorder, and none
            new for SETTLE s: a reader that matched the goal after it was sent would never get
            it."""
            readers = node.get_subscriptions_info_by_topic(GOAL)
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
                readers_matched() and (clock or args.at is not None)):
            rclpy.spin_once(node, timeout_sec=0.05)
        if not readers_matched():
            print(f'error: goal: nothing reads {GOAL} (is a run going with --live, on this '
                  'ROS_DOMAIN_ID?)', file=sys.stderr)
            return 1
        if args.at is None and not clock:
            print(f'error: goal: no {CLOCK} from a run (give --at T)', file=sys.stderr)
            return 1
        stamp_ns = round(args.at * 1e9) if args.at is not None else clock[-1]
        msg = PoseStamped()
        msg.header.frame_id = WORLD_FRAME
        msg.header.stamp.sec, msg.header.stamp.nanosec = stamp(stamp_ns)
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = args.x, args.y, args.z
        half = math.radians(args.yaw) / 2.0 if args.yaw is not None else None
        if half is not None:  # else the zero quaternion: keep the current heading
            msg.pose.orientation.z, msg.pose.orientation.w = math.sin(half), math.cos(half)
        else:
            msg.pose.orientation.w = 0.0
        publisher.publish(msg)
        if not publisher.wait_for_all_acked(
                Duration(seconds=max(deadline - time.monotonic(), 1.0))):
            print(f'error: goal: {GOAL} not acknowledged by its readers', file=sys.stderr)
            return 1
        # a reader that matches a moment later (a recorder discovered late on a loaded
        # machine) asks for the kept message: stay for it, LINGER s after the last new one
        readers, until = publisher.get_subscription_count(), time.monotonic() + LINGER
        while time.monotonic() < until:
            rclpy.spin_once(node, timeout_sec=0.05)
            if publisher.get_subscription_count() > readers:
                readers, until = publisher.get_subscription_count(), time.monotonic() + LINGER
                publisher.wait_for_all_acked(Duration(seconds=LINGER))
        print(f'goal ({args.x:g}, {args.y:g}, {args.z:g}) m'
              + (f', yaw {args.yaw:g} deg' if args.yaw is not None else '')
              + f' from t = {stamp_ns * 1e-9:.3f} s')
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
