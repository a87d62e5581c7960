"""`multilift bag info|play|reindex DIR`: what `ros2 bag info|play|reindex` do, for our bags.

    bag info DIR                       duration, start and end, message count and type per topic,
                                       size: `ros2 bag info`'s layout (Jazzy)
    bag play DIR [--rate R] [--loop] [--topics T ...] [--start-offset S] [--delay S]
                 [--wait-for-subscribers] [--clock-rate HZ]
                                       publish the recorded messages with their recorded timing
    bag reindex DIR                    rebuild metadata.yaml and the MCAP summary of a bag whose
                                       recorder was killed

Bags are rosbag2 directories with one MCAP file (as `bag.BagWriter` and `ros2 bag record -s mcap`
write them); DIR may also be the `.mcap` file itself for info and play.

The tools: `summary` (info), `play`, `reindex` in multilift_tools.bags.

Exit codes: 0 done, 1 the bag cannot be read or played, 2 bad arguments, 130 play interrupted.
"""
from __future__ import annotations

import argparse
import signal
import sys

from multilift_tools.bags.play import BagPlayer, PlayOptions, _Stop
from multilift_tools.bags.reindex import reindex
from multilift_tools.bags.summary import BagToolError, format_file_size, format_info, read_summary


def _info(args: argparse.Namespace) -> int:
    summary = read_summary(args.bag)
    if summary.source != 'metadata.yaml':
        how = 'its summary' if summary.source == 'summary' else 'scanned to its torn end'
        print(f'note: {summary.directory} has no metadata.yaml (was its recorder killed?); read '
              f'from the MCAP file ({how}); `multilift bag reindex {summary.directory}` repairs '
              'the bag', file=sys.stderr)
    print(format_info(summary))
    return 0


def _reindex(args: argparse.Namespace) -> int:
    result = reindex(args.bag)
    span = (f'{result.starting_time_ns * 1e-9:.3f} .. '
            f'{(result.starting_time_ns + result.duration_ns) * 1e-9:.3f} s'
            if result.messages else 'no messages')
    print(f'reindexed {result.mcap_path}: {result.messages} messages ({span}), '
          f'{format_file_size(result.size_before)} -> {format_file_size(result.size_after)}; '
          f'metadata.yaml written')
    return 0


def _play(args: argparse.Namespace) -> int:
    if not args.rate > 0:
        print(f'bag play: --rate must be > 0, got {args.rate:g}', file=sys.stderr)
        return 2
    if args.start_offset < 0 or args.delay < 0 or args.clock_rate < 0:
        print('bag play: --start-offset, --delay and --clock-rate must be >= 0', file=sys.stderr)
        return 2
    import rclpy
    from rclpy.signals import SignalHandlerOptions
    options = PlayOptions(rate=args.rate, loop=args.loop,
                          topics=tuple(args.topics) if args.topics else None,
                          start_offset=args.start_offset, delay=args.delay,
                          wait_for_subscribers=args.wait_for_subscribers,
                          clock_rate=args.clock_rate)
    stop = _Stop()
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    player = BagPlayer(args.bag, options, stop,
                       log=lambda text: print(text, file=sys.stderr, flush=True))
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    try:
        finished = player.run()
    finally:
        player.close()
        rclpy.try_shutdown()
    print(f'bag play: {player.published} messages published'
          + ('' if finished else ' (interrupted)'), file=sys.stderr)
    return 0 if finished else 130


def build_parser() -> argparse.ArgumentParser:
    """The `multilift bag` argument parser."""
    parser = argparse.ArgumentParser(prog='multilift bag', description=__doc__.split('\n')[0],
                                     epilog='See the multilift_tools.bags package docstring.')
    verbs = parser.add_subparsers(dest='verb', required=True)
    info = verbs.add_parser('info', help='print a summary of a bag, as ros2 bag info')
    info.add_argument('bag', help='bag directory (or its .mcap file)')
    play = verbs.add_parser('play', help='publish a bag with its recorded timing')
    play.add_argument('bag', help='bag directory (or its .mcap file)')
    play.add_argument('-r', '--rate', type=float, default=1.0,
                      help='playback speed factor (default 1)')
    play.add_argument('-l', '--loop', action='store_true', help='start over at the end')
    play.add_argument('--topics', nargs='+', metavar='TOPIC', help='play only these topics')
    play.add_argument('--start-offset', type=float, default=0.0, metavar='S',
                      help='skip the first S seconds of the bag')
    play.add_argument('-d', '--delay', type=float, default=0.0, metavar='S',
                      help='wait S wall seconds after creating the publishers')
    play.add_argument('--wait-for-subscribers', action='store_true',
                      help='wait (up to 30 s) until every topic has a subscriber')
    play.add_argument('--clock-rate', type=float, default=100.0, metavar='HZ',
                      help='rate of the generated /clock when /clock is not played from the '
                           'bag (default 100; 0: none)')
    reindex_parser = verbs.add_parser(
        'reindex', help='rebuild metadata.yaml and the MCAP summary of a killed recording')
    reindex_parser.add_argument('bag', help='bag directory')
    return parser


def bag_main(argv: list[str]) -> int:
    """`bag info|play|reindex ...` (argv without the word `bag`); returns the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    try:
        return {'info': _info, 'play': _play, 'reindex': _reindex}[args.verb](args)
    except BagToolError as error:
        print(f'bag {args.verb}: {error}', file=sys.stderr)
        return 1


if __name__ == '__main__':
    sys.exit(bag_main(sys.argv[1:]))
