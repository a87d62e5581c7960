"""`scripts/multilift`: the command line of multilift (what ros2cli and launch give elsewhere).

    multilift run SCENARIO [--bag DIR] [--duration S] [--realtime] [--headless | --compose]
                           [--external uav1[,uav3,...]]
    multilift node PKG EXECUTABLE [args...]
    multilift topic list | echo TOPIC [--once] | info TOPIC
    multilift plot BAG [--out DIR] | animate BAG [--out FILE.gif] | compare BAG_A BAG_B
    multilift modal SCENARIO [--out DIR] [--hold-uavs]
    multilift loads SCENARIO [--json FILE]
    multilift study baumgarte|swing_feedback [--out DIR]
    multilift bag info|play|reindex DIR | foxglove [--port P] | sweep | reproduce

Exit codes: 0 done, 1 the run failed, 2 bad input, 130 interrupted.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys

from multilift_sim.kernels import PLAIN_COUNTS
from multilift_sim.ros.fastdds import LIVE_VIEW_ANNOUNCEMENT, use_fastdds_profile
from multilift_tools.run_command import cmd_run


def cmd_node(args: argparse.Namespace) -> int:
    from multilift_tools.topic_tools import node_main
    return node_main([args.package, args.executable, *args.rest])


def cmd_topic(args: argparse.Namespace) -> int:
    from multilift_tools.topic_tools import topic_main
    return topic_main(args.rest)


# Subcommands whose parsing lives with their module: name -> (module, function, help)
DELEGATED = {
    'plot': ('multilift_tools.figures', 'plot_main', 'PNG figures from a bag'),
    'animate': ('multilift_tools.animation', 'animate_main', 'GIF of the formation from a bag'),
    'compare': ('multilift_tools.compare', 'compare_main',
                'seed Fig. 4.15-4.17 comparisons of two bags'),
    'modal': ('multilift_tools.modal_cli', 'modal_main',
              'eigenvalues and pendulum periods at the static equilibrium (seed §2.8)'),
    'loads': ('multilift_tools.loads_cli', 'loads_main',
              "each cable's tension and each UAV's thrust margin, at hover and over the mission "
              '(statics of Eq. 2.73)'),
    'goal': ('multilift_tools.goal_command', 'goal_main',
             'send the formation a live goal: X Y Z [--yaw DEG] (run --live)'),
    'winch': ('multilift_tools.winch_command', 'winch_main',
              "command a UAV's winch to a reel rate: UAV RATE [m/s] (run --live)"),
    'study': ('multilift_tools.studies', 'study_main', 'studies: baumgarte (seed Fig. 4.2-4.3)'),
    'bag': ('multilift_tools.bags.command', 'bag_main',
            'bag info DIR | play DIR | reindex DIR, like `ros2 bag`'),
    'foxglove': ('multilift_tools.foxglove.command', 'foxglove_main',
                 'serve the live graph to Foxglove over WebSocket (ws://localhost:8765)'),
    'sweep': ('multilift_tools.campaign.sweep', 'sweep_main',
              'a campaign of headless runs (grid and sampled) on a Dask cluster, a table row '
              'each'),
    'plot-sweep': ('multilift_tools.campaign.plot_sweep', 'plot_sweep_main',
                   'figures and the worst runs of a sweep table'),
    'reproduce': ('multilift_tools.report.command', 'reproduce_main',
                  "the seed's §2.8 and Ch. 4 results, figures and docs/reproduction.md"),
}


def _delegate(args: argparse.Namespace) -> int:
    import importlib
    module, function, _ = DELEGATED[args.command]
    try:
        entry = getattr(importlib.import_module(module), function)
    except ModuleNotFoundError as exc:
        print(f'error: {args.command}: {exc} (run scripts/setup)', file=sys.stderr)
        return 2
    return entry(args.rest)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog='multilift', description=__doc__.split('\n')[0])
    sub = parser.add_subparsers(dest='command', required=True)
    run = sub.add_parser('run', help='run a scenario: simulator, controllers, recorder')
    run.add_argument('scenario', help='a name in scenarios/ or a YAML path')
    run.add_argument('--bag', help='record every topic to this rosbag2 (MCAP) directory')
    run.add_argument('--duration', type=float, help='simulated seconds (default: scenario)')
    run.add_argument('--realtime', action='store_true', help='pace to the wall clock')
    run.add_argument('--external', metavar='uav1[,uav3,...]',
                     help="UAVs flown by your own controller nodes: ours are not started for "
                          "them and the simulator waits for yours (docs/external_controller.md)")
    run.add_argument('--startup-timeout', type=float, metavar='S',
                     help='wall seconds the simulator waits for the other nodes (default 60)')
    run.add_argument('--headless', action='store_true',
                     help='no ROS graph: the same physics and control laws in one process, '
                          'the same bag')
    run.add_argument('--compose', action='store_true',
                     help='every controller node (leader and followers) in one process, one '
                          'executor: the same graph and bag, fewer processes')
    run.add_argument('--live', action='store_true',
                     help='the leader holds its start until a goal (/formation/goal, '
                          '`multilift goal`) or a path (/formation/path) arrives '
                          '(docs/missions.md); winches reel at live rates '
                          '(/uav{i}/winch_cmd, `multilift winch`, docs/cables.md)')
    run.set_defaults(func=cmd_run)
    node = sub.add_parser('node', help='run one node, like `ros2 run`')
    node.add_argument('package')
    node.add_argument('executable')
    node.add_argument('rest', nargs=argparse.REMAINDER)
    node.set_defaults(func=cmd_node)
    topic = sub.add_parser('topic', help='inspect live topics, like `ros2 topic`',
                           add_help=False)
    topic.add_argument('rest', nargs=argparse.REMAINDER)
    topic.set_defaults(func=cmd_topic)
    for name, (_, _, text) in DELEGATED.items():
        delegated = sub.add_parser(name, help=text, add_help=False)
        delegated.add_argument('rest', nargs=argparse.REMAINDER)
        delegated.set_defaults(func=_delegate)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    # plain reference counts for this command's kernels and the processes it starts (nodes,
    # sweep workers): each runs its kernels from one thread (kernels.plain_reference_counts)
    os.environ.setdefault(PLAIN_COUNTS, '1')
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `multilift bag info B | head` ends quietly
    # our Fast DDS profile for every subcommand's participants and the nodes `run` starts
    use_fastdds_profile(LIVE_VIEW_ANNOUNCEMENT if argv[:1] == ['foxglove'] else None)
    # subcommands that parse their own options get them untouched (argparse's REMAINDER would
    # reject a leading option such as `foxglove --port 8765`)
    if argv and argv[0] in (*DELEGATED, 'topic'):
        return build_parser().parse_args([argv[0]]).func(
            argparse.Namespace(command=argv[0], rest=argv[1:]))
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == '__main__':
    sys.exit(main())
