"""`multilift goal X Y Z [--yaw DEG] [--at T] [--timeout S]`: send a live run's leader one goal.

Publishes one geometry_msgs/PoseStamped on `/formation/goal` (frame `world`, z up, [m]) for a
run started with `multilift run SCENARIO --live`: the formation flies there within the
scenario's `mission.max_speed` and `mission.max_acceleration`, then holds
(multilift_control.live_goals). Stamped with the simulated time of the run's latest `/clock`
(the goal takes effect at the next tick), or `--at T` [s]. Waits for the leader's subscription
and for its acknowledgement (`live_publish`); exit 1 without a run, 2 on bad arguments.
"""
from __future__ import annotations

import argparse
import math
import sys

from multilift_sim.topics import GOAL
from multilift_sim.wire.msgvalues import WORLD_FRAME, stamp
from multilift_tools.live_publish import live_parser, publish_acknowledged


def _parser() -> argparse.ArgumentParser:
    parser = live_parser('goal', __doc__)
    for axis in 'XYZ':
        parser.add_argument(axis.lower(), type=float, metavar=axis, help=f'{axis} [m], world')
    parser.add_argument('--yaw', type=float, metavar='DEG',
                        help='heading [deg] (default: keep the current one)')
    parser.add_argument('--at', type=float, metavar='T',
                        help='simulated time [s] it takes effect (default: the latest /clock)')
    return parser


def goal_main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    values = [args.x, args.y, args.z] + ([args.yaw] if args.yaw is not None else [])
    if not all(math.isfinite(v) for v in values) or args.timeout <= 0:
        print('error: goal: X Y Z and --yaw must be finite, --timeout > 0', file=sys.stderr)
        return 2
    from geometry_msgs.msg import PoseStamped

    def build(clock_ns: int | None) -> PoseStamped:
        stamp_ns = round(args.at * 1e9) if args.at is not None else clock_ns
        msg = PoseStamped()
        msg.header.frame_id = WORLD_FRAME
        msg.header.stamp.sec, msg.header.stamp.nanosec = stamp(stamp_ns)
        msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = args.x, args.y, args.z
        half = math.radians(args.yaw) / 2.0 if args.yaw is not None else None
        if half is not None:  # else the zero quaternion: keep the current heading
            msg.pose.orientation.z, msg.pose.orientation.w = math.sin(half), math.cos(half)
        else:
            msg.pose.orientation.w = 0.0
        return msg
    code, clock_ns = publish_acknowledged('goal', PoseStamped, GOAL, build, args.timeout,
                                          needs_clock=args.at is None)
    if code:
        return code
    stamp_ns = round(args.at * 1e9) if args.at is not None else clock_ns
    print(f'goal ({args.x:g}, {args.y:g}, {args.z:g}) m'
          + (f', yaw {args.yaw:g} deg' if args.yaw is not None else '')
          + f' from t = {stamp_ns * 1e-9:.3f} s')
    return 0
