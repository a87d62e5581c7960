"""`multilift winch UAV RATE [--at T] [--timeout S]`: command a live run's winch to a reel rate.

Publishes one std_msgs/Float64 on `/uav{UAV}/winch_cmd` (RATE [m/s], positive pays out,
negative hauls in, 0 stops) for a run started with `multilift run SCENARIO --live` whose UAV
carries a winch (`uavs[i].winch`); the simulator reels at it from the tick it arrives in,
within the winch's rate and acceleration limits and stops (multilift_sim.physics.winch).
With `--at T` [s] it publishes a multilift_msgs/WinchCommand stamped T on
`/uav{UAV}/winch_cmd_stamped` instead: the rate takes effect at the first tick at or after T
of simulated time (at once when T has passed). Waits for the simulator's subscription and
its acknowledgement (`live_publish`); exit 1 without a run, 2 on bad arguments.
"""
from __future__ import annotations

import argparse
import math
import sys

from multilift_sim.topics import WINCH_CMD, WINCH_CMD_STAMPED, uav_topic
from multilift_sim.wire.msgvalues import stamp
from multilift_tools.live_publish import live_parser, publish_acknowledged


def _parser() -> argparse.ArgumentParser:
    parser = live_parser('winch', __doc__)
    parser.add_argument('uav', type=int, metavar='UAV', help='the UAV, from 1 (1: the leader)')
    parser.add_argument('rate', type=float, metavar='RATE',
                        help='reel rate [m/s]: positive pays out, negative hauls in, 0 stops')
    parser.add_argument('--at', type=float, metavar='T',
                        help='simulated time [s] it takes effect (default: the tick it arrives '
                             'in)')
    return parser


def winch_main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    if (args.uav < 1 or not math.isfinite(args.rate) or args.timeout <= 0
            or (args.at is not None and not (math.isfinite(args.at) and args.at >= 0.0))):
        print('error: winch: UAV must be >= 1, RATE finite, --at >= 0, --timeout > 0',
              file=sys.stderr)
        return 2
    if args.at is None:
        from std_msgs.msg import Float64
        code, _ = publish_acknowledged('winch', Float64, uav_topic(args.uav, WINCH_CMD),
                                       lambda _: Float64(data=args.rate), args.timeout,
                                       needs_clock=False)
    else:
        from multilift_msgs.msg import WinchCommand

        def build(_) -> WinchCommand:
            msg = WinchCommand(rate=args.rate)
            msg.header.frame_id = f'uav{args.uav}/base_link'
            msg.header.stamp.sec, msg.header.stamp.nanosec = stamp(round(args.at * 1e9))
            return msg
        code, _ = publish_acknowledged('winch', WinchCommand,
                                       uav_topic(args.uav, WINCH_CMD_STAMPED), build,
                                       args.timeout, needs_clock=False)
    if code == 0:
        print(f'uav{args.uav} winch commanded to {args.rate:g} m/s'
              + (f' from t = {args.at:.3f} s' if args.at is not None else ''))
    return code
