"""`multilift winch UAV RATE [--timeout S]`: command a live run's winch to a reel rate.

Publishes one std_msgs/Float64 on `/uav{UAV}/winch_cmd` (RATE [m/s], positive pays out,
negative hauls in, 0 stops) for a run started with `multilift run SCENARIO --live` whose UAV
carries a winch (`uavs[i].winch`); the simulator reels at it from the tick it arrives in,
within the winch's rate and acceleration limits and stops (multilift_sim.physics.winch).
Waits for the simulator's subscription and its acknowledgement (`live_publish`); exit 1
without a run, 2 on bad arguments.
"""
from __future__ import annotations

import argparse
import math
import sys

from multilift_sim.topics import WINCH_CMD, uav_topic
from multilift_tools.live_publish import live_parser, publish_acknowledged


def _parser() -> argparse.ArgumentParser:
    parser = live_parser('winch', __doc__)
    parser.add_argument('uav', type=int, metavar='UAV', help='the UAV, from 1 (1: the leader)')
    parser.add_argument('rate', type=float, metavar='RATE',
                        help='reel rate [m/s]: positive pays out, negative hauls in, 0 stops')
    return parser


def winch_main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    if args.uav < 1 or not math.isfinite(args.rate) or args.timeout <= 0:
        print('error: winch: UAV must be >= 1, RATE finite, --timeout > 0', file=sys.stderr)
        return 2
    from std_msgs.msg import Float64

    topic = uav_topic(args.uav, WINCH_CMD)
    code, _ = publish_acknowledged('winch', Float64, topic, lambda _: Float64(data=args.rate),
                                   args.timeout, needs_clock=False)
    if code == 0:
        print(f'uav{args.uav} winch commanded to {args.rate:g} m/s')
    return code
