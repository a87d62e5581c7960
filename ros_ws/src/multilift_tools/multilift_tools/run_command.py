"""`multilift run SCENARIO`: the simulator, the controllers (one process each, or composed)
and the recorder started as separate processes, watched and stopped together
(`launcher.Supervisor`), or with --headless the same run in this process; the exit codes of
cli.py's docstring.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from multilift_sim import scenario as scenario_io
from multilift_sim.ros.shared_memory import remove_before_start
from multilift_sim.topics import (ATTITUDE_SETPOINT, FORMATION_ERROR, REFERENCE, ROTOR_CMD,
                                   parse_external, scenario_topics)
from multilift_tools.launcher import Child, Supervisor, find_executable
from multilift_tools.run_summary import Progress, print_summary, read_summaries


def ros_args(params: dict) -> list[str]:
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
    if external and not scenario.controlled:
        print(f'error: --external: uav{external[0]}\'s motion is prescribed '
              f'(uavs[{external[0] - 1}].trajectory): it has no controller', file=sys.stderr)
        return 2
    if args.headless:
        if args.compose:
            print('error: --compose puts the controller nodes in one process; --headless starts '
                  'no node (nothing to compose)', file=sys.stderr)
            return 2
        if external:
            print('error: --external needs the ROS graph (not --headless)', file=sys.stderr)
            return 2
        if args.live:
            print('error: --live reads goals from the ROS graph (not --headless)',
                  file=sys.stderr)
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
        controllers = _controller_children(scenario, external, args.compose, common, work,
                                           args.live)
    except FileNotFoundError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    sim_params = dict(common, realtime=args.realtime, progress_file=str(work / 'progress'))
    if args.live:  # the simulator reads live reel rates (/uav{i}/winch_cmd)
        sim_params['live'] = True
    if external:
        sim_params['external'] = ','.join(f'uav{i}' for i in external)
    if args.startup_timeout is not None:
        sim_params['startup_timeout'] = float(args.startup_timeout)
    if args.duration is not None:
        sim_params['duration'] = float(args.duration)
    children = [Child('sim_node', [str(sim_exe), *ros_args(sim_params)],
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
                  scenario_topics(scenario, live=args.live) if name not in ours]
        recorder = Child('recorder_node', [str(recorder_exe), *ros_args(
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
    print_summary(scenario.name, read_summaries(summary_dir, scenario), bag, scenario)
    if warnings:
        print(f'logs: {work}', file=sys.stderr)
    else:
        shutil.rmtree(work, ignore_errors=True)
    return 0


def _controller_children(scenario, external: list[int], compose: bool, common: dict,
                         work: Path, live: bool = False) -> list[Child]:
    """The processes of the controllers of every UAV but the external ones: a leader_node and
    a follower_node each, or with `compose` one controllers_node holding them all; `live`: the
    leader reads live goals (its `live` parameter)."""
    ours = [i for i in range(1, scenario.n_uavs + 1) if i not in external] \
        if scenario.controlled else []  # every UAV's motion prescribed: no controller
    if compose:
        if not ours:
            return []
        argv = [str(find_executable('multilift_control', 'controllers_node')),
                common['scenario'], '--summary-dir', common['summary_dir']]
        argv += (['--record'] if common['record'] else []) + (['--live'] if live else []) + (
            ['--external', ','.join(f'uav{i}' for i in external)] if external else [])
        return [Child(f'controllers ({_uav_ranges(ours)})', argv, work / 'controllers_node.log',
                      'controller')]
    children = []
    for i in ours:
        if i == 1:
            argv = [str(find_executable('multilift_control', 'leader_node')),
                    *ros_args(dict(common, live=True) if live else common)]
            children.append(Child('leader_node', argv, work / 'leader_node.log', 'controller'))
        else:
            argv = [str(find_executable('multilift_control', 'follower_node')),
                    *ros_args(dict(common, uav_index=i)), '-r', f'__node:=follower{i}']
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
    print_summary(scenario.name, run.summary(), bag, scenario)
    return 0
