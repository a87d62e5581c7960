"""`scripts/multilift`: the command line of multilift (what ros2cli and launch give elsewhere).

    multilift run SCENARIO [--bag DIR] [--duration S] [--realtime] [--headless | --compose]
                           [--external uav1[,uav3,...]]
    multilift node PKG EXECUTABLE [args...]
    multilift topic list | echo TOPIC [--once] | info TOPIC
    multilift plot BAG [--out DIR] | animate BAG [--out FILE.gif] | compare BAG_A BAG_B
    multilift modal SCENARIO [--out DIR] [--hold-uavs]
    multilift study baumgarte|swing_feedback [--out DIR]
    multilift bag info|play|reindex DIR | foxglove [--port P] | sweep | reproduce

Exit codes: 0 done, 1 the run failed, 2 bad input, 130 interrupted.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path

from multilift_sim import scenario as scenario_io
from multilift_sim.ros.fastdds import LIVE_VIEW_ANNOUNCEMENT, use_fastdds_profile
from multilift_sim.ros.shared_memory import remove_before_start
from multilift_tools.launcher import Child, Supervisor, find_executable
from multilift_sim.topics import (ATTITUDE_SETPOINT, FORMATION_ERROR, REFERENCE, ROTOR_CMD,
                                   parse_external, scenario_topics)


def _ros_args(params: dict) -> list[str]:
    out = ['--ros-args']
    for key, value in params.items():
        if isinstance(value, bool):
            value = 'true' if value else 'false'
        elif isinstance(value, list):
            value = '[' + ','.join(f"'{v}'" for v in value) + ']'
        out += ['-p', f'{key}:={value}']
    return out


def _fresh_bag_dir(bag: Path) -> None:
    """Like rosbag2 the recorder wants a new directory; an old bag there is moved aside."""
    if bag.exists() and any(bag.iterdir()):
        k = 1
        while Path(f'{bag}.{k}').exists():
            k += 1
        bag.rename(f'{bag}.{k}')
        print(f'note: {bag} existed; moved it to {bag}.{k}', file=sys.stderr)
    elif bag.exists():
        bag.rmdir()
    bag.parent.mkdir(parents=True, exist_ok=True)


class Progress:
    """Simulated time and real-time factor, on one terminal line (or a line every 10 %)."""

    def __init__(self, path: Path | None, tty: bool):
        self.path = path
        self.tty = tty
        self.last_decile = -1

    def __call__(self) -> None:
        """Show what the simulator node last wrote to the progress file."""
        try:
            t, t_max, wall = (float(v) for v in self.path.read_text().split())
        except (OSError, ValueError):
            return
        self.show(t, t_max, wall)

    def show(self, t: float, t_max: float, wall: float) -> None:
        """Simulated time t of t_max [s] after `wall` seconds."""
        rtf = t / wall if wall > 0 else 0.0
        if self.tty:
            print(f'\r  t = {t:7.2f} / {t_max:.1f} s   {rtf:5.1f}x real time ',
                  end='', flush=True)
        elif t_max > 0 and int(10 * t / t_max) > self.last_decile:
            self.last_decile = int(10 * t / t_max)
            print(f'  t = {t:.1f} / {t_max:.1f} s   {rtf:.1f}x real time', flush=True)

    def close(self) -> None:
        if self.tty:
            print()


def _read_summaries(summary_dir: Path, scenario) -> dict:
    """What each node of a run left in `summary_dir` (sim, leader, follower2, ...)."""
    data = {}
    parts = ['sim', 'leader'] + [f'follower{i}' for i in range(2, scenario.n_uavs + 1)]
    for part in parts:
        path = summary_dir / f'{part}.json'
        if path.is_file():
            data[part] = json.loads(path.read_text())
    return data


def _summary(name: str, data: dict, bag: Path | None, scenario) -> None:
    """Print the end-of-run summary; with a bag, also leave it as BAG/summary.json."""
    sim = data.get('sim', {})
    lines = []
    if sim:
        wall = sim.get('wall_time') or 0.0
        t = sim.get('simulated_time', 0.0)
        lines.append(f'{name}: {t:.1f} s simulated in {wall:.1f} s wall '
                     f'({t / wall if wall else 0:.1f}x real time)')
        tol = scenario.simulation.constraint_tolerance
        lines.append(f'  max |g|          {sim["max_abs_constraint"]:.3g} m^2 '
                     f'(tolerance {tol:g})')
        lines.append(f'  max |g_dot|      {sim["max_abs_constraint_rate"]:.3g} m^2/s')
        for i, (w, s) in enumerate(zip(sim['max_rotor_speed'], sim['saturated_time'])):
            limit = scenario.uavs[i].vehicle.rotor_speed_max
            lines.append(f'  uav{i + 1} rotors      max {w:.1f} rad/s (limit {limit:g}), '
                         f'saturated {s:.2f} s')
        lines.append(f'  cable tension    {sim["min_tension"]:.2f} .. {sim["max_tension"]:.2f} N')
        if any(sim.get('slack_time', [])):
            lines.append('  slack cables     ' + ', '.join(
                f'cable {i + 1} {s:.2f} s' for i, s in enumerate(sim['slack_time']) if s > 0))
        if 'max_payload_swing' in sim:
            lines.append(f'  payload swing    max {sim["max_payload_swing"]:.3f} m, '
                         f'rms {sim["rms_payload_swing"]:.3f} m (horizontal, from its rest '
                         'place under the UAVs)')
        if scenario.gusts:
            lines.append(f'  peak gust speed met by the payload  {sim["max_gust_speed"]:.2f} m/s')
        if sim.get('seeds'):
            lines.append('  seeds            ' + ', '.join(
                f'{what} {seed}' for what, seed in sim['seeds'].items()))
        for event in sim.get('events', []):
            lines.append(f'  event at {event["time"]:g} s   {event["description"]}')
    control = scenario.control
    if control.input_shaping != 'none' or control.swing_stiffness or control.swing_damping:
        lines.append(f'  payload feedback {control.input_shaping} shaping of the corners, swing '
                     f'k_s {control.swing_stiffness:g}, k_d {control.swing_damping:g}, a_max '
                     f'{control.swing_limit:g} m/s^2 (control.payload_feedback)')
    leader = data.get('leader')
    if leader and leader.get('answered_states'):
        lines.append(f'  leader tracking  max {leader["max_tracking_error"]:.3f} m, '
                     f'rms {leader["rms_tracking_error"]:.3f} m')
    for i in range(2, scenario.n_uavs + 1):
        follower = data.get(f'follower{i}')
        if follower and follower.get('answered_states'):
            # the largest row and the mean norm of its rows: the mean can exceed the max
            lines.append(f'  uav{i} formation  largest |g_vc| row '
                         f'{follower["max_abs_formation_error"]:.3f}, mean |g_vc| '
                         f'{follower["mean_formation_error_norm"]:.3f} (m)')
    if bag is not None:
        lines.append(f'  bag              {bag}')
        (bag / 'summary.json').write_text(json.dumps(data, indent=1, sort_keys=True))
    print('\n'.join(lines))


def cmd_run(args: argparse.Namespace) -> int:
    try:
        scenario = scenario_io.load(args.scenario)
    except scenario_io.ScenarioError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    for warning in scenario.warnings:
        print(f'warning: {warning}', file=sys.stderr)
    if args.startup_timeout is not None and args.startup_timeout <= 0:
        print(f'error: --startup-timeout: {args.startup_timeout} must be > 0', file=sys.stderr)
        return 2
    if args.duration is not None:
        try:
            scenario = scenario.with_duration(args.duration)
        except scenario_io.ScenarioError as exc:
            print(f'error: --{exc}', file=sys.stderr)
            return 2
    try:
        external = parse_external(args.external or '', scenario.n_uavs)
    except ValueError as exc:
        print(f'error: --external: {exc}', file=sys.stderr)
        return 2
    if args.headless:
        if args.compose:
            print('error: --compose puts the controller nodes in one process; --headless starts '
                  'no node (nothing to compose)', file=sys.stderr)
            return 2
        if external:
            print('error: --external needs the ROS graph (not --headless)', file=sys.stderr)
            return 2
        return _run_headless(scenario, None if args.bag is None else Path(args.bag))
    scenario_path = str(scenario_io.resolve(args.scenario).resolve())
    work = Path(tempfile.mkdtemp(prefix=f'multilift-{scenario.name}-'))
    summary_dir = work / 'summary'
    record = args.bag is not None
    bag = Path(args.bag) if record else None
    common = {'scenario': scenario_path, 'record': record, 'summary_dir': str(summary_dir)}
    try:
        sim_exe = find_executable('multilift_sim', 'sim_node')
        recorder_exe = find_executable('multilift_sim', 'recorder_node')
        controllers = _controller_children(scenario, external, args.compose, common, work)
    except FileNotFoundError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    sim_params = dict(common, realtime=args.realtime, progress_file=str(work / 'progress'))
    if external:
        sim_params['external'] = ','.join(f'uav{i}' for i in external)
    if args.startup_timeout is not None:
        sim_params['startup_timeout'] = float(args.startup_timeout)
    if args.duration is not None:
        sim_params['duration'] = float(args.duration)
    children = [Child('sim_node', [str(sim_exe), *_ros_args(sim_params)],
                      work / 'sim_node.log', 'sim'), *controllers]
    recorder: Child | None = None
    if record:
        _fresh_bag_dir(bag)
        # an external controller's topics are recorded as they appear (the recorder records
        # every topic of the graph, with the QoS their publishers offer); the simulator waits
        # for the recorder to hear its rotor commands before t = 0
        ours = {f'/uav{i}/{leaf}' for i in external
                for leaf in (ROTOR_CMD, REFERENCE, ATTITUDE_SETPOINT, FORMATION_ERROR)}
        topics = [f'{name}|{kind}' for name, kind in
                  scenario_topics(scenario) if name not in ours]
        recorder = Child('recorder_node', [str(recorder_exe), *_ros_args(
            {'bag': str(bag), 'topics': topics})], work / 'recorder_node.log', 'recorder')
        children.append(recorder)
    progress = Progress(work / 'progress', sys.stdout.isatty())
    remove_before_start()  # Fast DDS's shared memory of killed processes
    print(f'multilift run {scenario.name}: {scenario.n_uavs} UAV(s), '
          f'{args.duration or scenario.simulation.duration:g} s, logs in {work}', flush=True)
    if external:
        names = ', '.join(f'uav{i}' for i in external)
        print(f'waiting for external controllers of {names} (ROS_DOMAIN_ID '
              f'{os.environ.get("ROS_DOMAIN_ID", "0")}): each reads a state topic '
              '(/uavN/odom, /formation/snapshot, ...) and answers every state with a '
              '/uavN/rotor_cmd of the same stamp', flush=True)
    outcome, dead = Supervisor(children).run(on_tick=progress)
    progress()
    progress.close()
    bag_state = _bag_state(bag, recorder) if bag else ''
    warnings = [f'{child.name}: {line}' for child in children for line in child.warnings()]
    for line in warnings:
        print(line, file=sys.stderr)
    if outcome == 'interrupted':
        print('interrupted: every process stopped' + (f'; {bag_state}' if bag else ''),
              file=sys.stderr)
        if warnings or (bag and not recorder.ended_well()):
            print(f'logs: {work}', file=sys.stderr)
        return 130
    if outcome == 'died':
        print(f'error: {dead.name} stopped ({dead.exit_text()}): {dead.last_error()}',
              file=sys.stderr)
        print('the other processes were stopped' + (f'; {bag_state}' if bag else ''),
              file=sys.stderr)
        print(f'logs: {work}', file=sys.stderr)
        return 1
    _summary(scenario.name, _read_summaries(summary_dir, scenario), bag, scenario)
    if warnings:
        print(f'logs: {work}', file=sys.stderr)
    else:
        shutil.rmtree(work, ignore_errors=True)
    return 0


def _controller_children(scenario, external: list[int], compose: bool, common: dict,
                         work: Path) -> list[Child]:
    """The processes of the controllers of every UAV but the external ones: a leader_node and
    a follower_node each, or with `compose` one controllers_node holding them all."""
    ours = [i for i in range(1, scenario.n_uavs + 1) if i not in external]
    if compose:
        if not ours:
            return []
        argv = [str(find_executable('multilift_control', 'controllers_node')),
                common['scenario'], '--summary-dir', common['summary_dir']]
        argv += (['--record'] if common['record'] else []) + (
            ['--external', ','.join(f'uav{i}' for i in external)] if external else [])
        return [Child(f'controllers ({_uav_ranges(ours)})', argv, work / 'controllers_node.log',
                      'controller')]
    children = []
    for i in ours:
        if i == 1:
            argv = [str(find_executable('multilift_control', 'leader_node')), *_ros_args(common)]
            children.append(Child('leader_node', argv, work / 'leader_node.log', 'controller'))
        else:
            argv = [str(find_executable('multilift_control', 'follower_node')),
                    *_ros_args(dict(common, uav_index=i)), '-r', f'__node:=follower{i}']
            children.append(Child(f'follower_node (uav{i})', argv,
                                  work / f'follower{i}_node.log', 'controller'))
    return children


def _uav_ranges(indices: list[int]) -> str:
    """[1, 2, 3, 5] -> 'uav1..uav3, uav5'."""
    runs: list[list[int]] = []
    for i in indices:
        if runs and runs[-1][-1] == i - 1:
            runs[-1].append(i)
        else:
            runs.append([i])
    return ', '.join(f'uav{r[0]}' + (f'..uav{r[-1]}' if len(r) > 1 else '') for r in runs)


def _bag_state(bag: Path, recorder: Child) -> str:
    """Where the run's bag stands once every process has stopped, in words: closed by the
    recorder, or, when the recorder ended without closing it (killed, crashed), rebuilt from its
    complete chunks as `multilift bag reindex` does, with a warning naming how it ended (what it
    received after its last flush, `flush_period` 1 s at most, is lost)."""
    if (bag / 'metadata.yaml').is_file():
        return f'bag closed at {bag}'
    from multilift_tools.bags.reindex import reindex
    from multilift_tools.bags.summary import BagToolError
    print(f'warning: {recorder.name} ended ({recorder.exit_text()}) without closing the bag '
          f'(its log: {recorder.log_path})', file=sys.stderr)
    try:
        rebuilt = reindex(bag)
    except BagToolError as exc:
        return f'the bag could not be rebuilt: {exc}'
    return (f'bag rebuilt at {bag} from its complete chunks ({rebuilt.messages} messages, '
            f'{rebuilt.duration_ns * 1e-9:.2f} s)')


def _run_headless(scenario, bag: Path | None) -> int:
    """The same scenario, physics and control laws in this process, no ROS graph."""
    # no rclpy and no message types here unless a bag is written (tests/unit/test_architecture.py)
    from multilift_control.headless import fly
    from multilift_sim.simulation import SimulationStopped
    progress = Progress(None, sys.stdout.isatty())
    start = time.monotonic()

    def on_progress(t: float, t_max: float) -> None:
        progress.show(t, t_max, time.monotonic() - start)

    print(f'multilift run {scenario.name} --headless: {scenario.n_uavs} UAV(s), '
          f'{scenario.simulation.duration:g} s', flush=True)
    if bag is not None:
        _fresh_bag_dir(bag)
    try:
        if bag is None:  # the engine: many ticks per compiled call
            run = fly(scenario, on_progress)
        else:
            from multilift_tools.headless_bag import record_headless
            run = record_headless(scenario, bag, on_progress)
    except SimulationStopped as exc:
        progress.close()
        print(f'error: {exc}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        progress.close()
        print('interrupted' + (f'; bag closed at {bag}' if bag else ''), file=sys.stderr)
        return 130
    progress.close()
    _summary(scenario.name, run.summary(), bag, scenario)
    return 0


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
