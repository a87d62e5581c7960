#!/usr/bin/env python3
"""Speed of multilift against rotorpy's quadrotor, in one run on one machine.

    scripts/setup && source scripts/env.sh && python benchmarks/compare.py
        [--out benchmarks/results.md] [--quick] [--full] [--skip-rotorpy] [--skip-ros]
        [--no-profile] [--domain 11]

Runs, in this process tree and one after the other:
- rotorpy 3.0.0: its `Multirotor` (Crazyflie parameters) under its default `SE3Control`,
  hovering (`HoverTraj`) for 120 s at its default 100 Hz (scipy RK45 per step);
- the headless core (`multilift_control.headless.run_headless`: physics + every controller in
  one process) on `single_lift`, `twin_lift` and "V" formations of n = 3, 10, 30, 100 built in
  memory from `scenarios/multi_lift.yaml` with formation.n changed (cables lengthened where
  the V is wider than 10.26 m cables reach: `v_formation`);
- the physics core alone (`FormationSimulator.advance` at hover rotor speeds) for the cost of
  one RK4 step against n;
- the ROS stack in lockstep (`scripts/multilift run ... --bag`, recorder on) for n = 1, 2, 3, 10,
  timed by sim_node's own wall clock (BAG/summary.json);
- cProfile of the headless twin-lift and of the ROS twin-lift's nodes.
It prints simulated seconds per wall second (and per CPU second) for each, the ratio to rotorpy,
the cost per control tick against n, the top costs, and writes them to benchmarks/results.md.
Text below the "notes" marker of an existing results file is kept.
"""
from __future__ import annotations

import os

# One BLAS thread per process unless the caller says otherwise: the matrices here are at most
# a few hundred wide, and on a shared 2-core machine OpenBLAS's second thread made the n = 100
# RK4 step 12 times slower (12 ms instead of 0.94 ms). Set before numpy is imported.
BLAS_THREADS_SET_HERE = 'OPENBLAS_NUM_THREADS' not in os.environ
for _var in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_var, '1')

import argparse  # noqa: E402 - after the BLAS thread setting
import cProfile
import datetime
import io
import json
import math
import platform
import pstats
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import yaml

from multilift_control.headless import hover_speeds, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_geometry import nominal_positions
from multilift_tools.launcher import Child, Supervisor, find_executable
from multilift_sim.simulation import FormationSimulator, SimulationStopped

ROOT = Path(__file__).resolve().parents[1]


def compile_ahead() -> None:
    """The kernels scripts/setup leaves to their first use (the engine's, the learning calls':
    scripts/compile_kernels.py) compiled into numba's cache before anything is timed, so a
    whole command's figure is its run from the cache, as a second run's is, not its first
    use's compile (about 60 CPU s, once). Seconds when the cache holds them already."""
    subprocess.run([sys.executable, str(ROOT / 'scripts' / 'compile_kernels.py'),
                    'engine_start', 'engine', 'learning'],
                   env=dict(os.environ, MULTILIFT_KERNEL='jit'), check=True)


SEED_CABLE = 10.26            # Table 4.2 cable length [m]
NOTES_MARKER = '<!-- notes: compare.py keeps everything below this line -->'
TARGETS = {  # what the issue asks, simulated s per wall s
    'headless twin_lift': 100.0,
    'ros twin_lift': 5.0,
    'ros V n=10': 1.0,
}


# ------------------------------------------------------------------------------------ scenarios
def v_formation_data(n: int, base: str = 'multi_lift') -> tuple[dict, float]:
    """YAML data of scenarios/<base>.yaml with formation.n = n, and the cable length used [m].

    The V keeps d = 4 m and gamma = 30 deg. Equal cables must reach from every UAV to the
    payload below the formation's centroid; when the seed's 10.26 m do not, every cable becomes
    twice the widest horizontal span rounded up to the metre (cables at most 30 deg from the
    vertical).
    """
    data = yaml.safe_load((ROOT / 'scenarios' / f'{base}.yaml').read_text())
    f = data['formation']
    data['formation'] = dict(f, n=n)
    data['name'] = f'v{n}'
    uavs = nominal_positions('v', n, np.zeros(3), (), float(f['distance']),
                             math.radians(float(f['half_angle_deg'])))
    span = float(np.linalg.norm(uavs[:, :2] - uavs[:, :2].mean(axis=0), axis=1).max())
    length = float(data['cable_length'])
    if span >= length:
        length = float(math.ceil(2.0 * span))
        data['cable_length'] = length
    return data, length


def with_duration(scenario, duration: float | None):
    if duration is None:
        return scenario
    return replace(scenario, simulation=replace(scenario.simulation, duration=duration))


# ------------------------------------------------------------------------------------ results
@dataclass
class Result:
    kind: str                  # 'rotorpy', 'headless', 'physics', 'ros'
    name: str
    n: int
    simulated: float           # [s]
    wall: float                # [s]
    cpu: float                 # [s], every process of the run
    ticks: int = 0
    note: str = ''
    extra: dict = field(default_factory=dict)

    @property
    def rate(self) -> float:
        return self.simulated / self.wall if self.wall > 0 else math.nan

    @property
    def cpu_rate(self) -> float:
        return self.simulated / self.cpu if self.cpu > 0 else math.nan


def machine() -> dict:
    model = platform.processor() or platform.machine()
    try:
        for line in Path('/proc/cpuinfo').read_text().splitlines():
            if line.startswith('model name'):
                model = line.split(':', 1)[1].strip()
                break
    except OSError:
        pass
    return {'cpu': model, 'cores': os.cpu_count(), 'python': platform.python_version(),
            'numpy': np.__version__, 'load': os.getloadavg(),
            'blas': f'OPENBLAS_NUM_THREADS={os.environ["OPENBLAS_NUM_THREADS"]}'
                    + (' (set by compare.py)' if BLAS_THREADS_SET_HERE else ' (from the caller)')}


def say(text: str) -> None:
    print(text, flush=True)


# ------------------------------------------------------------------------------------ runners
def run_rotorpy(seconds: float) -> Result:
    """rotorpy's Crazyflie under its SE3 controller, hovering, at its default 100 Hz."""
    from rotorpy.controllers.quadrotor_control import SE3Control
    from rotorpy.environments import Environment
    from rotorpy.trajectories.hover_traj import HoverTraj
    from rotorpy.vehicles.crazyflie_params import quad_params
    from rotorpy.vehicles.multirotor import Multirotor
    env = Environment(vehicle=Multirotor(quad_params), controller=SE3Control(quad_params),
                      trajectory=HoverTraj(), sim_rate=100)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    out = env.run(t_final=seconds, use_mocap=False, terminate=False, plot=False,
                  animate_bool=False, verbose=False)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    simulated = float(out['time'][-1])
    ok = np.all(np.isfinite(out['state']['x'])) and np.abs(out['state']['x'][-1]).max() < 0.1
    return Result('rotorpy', 'rotorpy hover (Crazyflie, SE3Control, 100 Hz)', 1, simulated,
                  wall, cpu, ticks=len(out['time']) - 1,
                  note=f'{out["exit"].name}' + ('' if ok else ', did NOT hold the hover'))


def run_headless_case(name: str, scenario, n: int) -> Result:
    wall0, cpu0 = time.perf_counter(), time.process_time()
    note = ''
    try:
        sim = run_headless(scenario).simulator
        simulated = sim.t
        ticks = sim.tick
    except SimulationStopped as exc:
        note = f'stopped: {exc}'
        simulated, ticks = math.nan, 0
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    if not note:
        note = f'max abs(g) {sim.stats.max_abs_constraint:.2g} m^2'
    return Result('headless', name, n, simulated, wall, cpu, ticks=ticks, note=note)


def run_physics_case(name: str, scenario, n: int, seconds: float) -> Result:
    """The formation DAE alone at hover rotor speeds (no controller)."""
    scenario = with_duration(scenario, seconds)
    sim = FormationSimulator(scenario)
    speeds = hover_speeds(scenario)
    flags = [np.zeros(s.shape, dtype=bool) for s in speeds]
    wall0, cpu0 = time.perf_counter(), time.process_time()
    while not sim.finished:
        sim.advance(speeds, flags)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    steps = sim.tick * sim.steps_per_tick
    return Result('physics', name, n, sim.t, wall, cpu, ticks=sim.tick,
                  extra={'rk4_steps': steps})


def _ros_env(domain: int) -> dict:
    return dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_ros_case(name: str, scenario_arg: str, n: int, duration: float | None, domain: int,
                 workdir: Path) -> Result:
    bag = workdir / f'bag_{name.replace(" ", "_").replace("=", "")}'
    argv = [str(ROOT / 'scripts' / 'multilift'), 'run', scenario_arg, '--bag', str(bag)]
    if duration is not None:
        argv += ['--duration', f'{duration:g}']
    cpu0, wall0 = _children_cpu(), time.perf_counter()
    out = subprocess.run(argv, env=_ros_env(domain), capture_output=True, text=True,
                         timeout=3600)
    cpu, total_wall = _children_cpu() - cpu0, time.perf_counter() - wall0
    if out.returncode != 0:
        return Result('ros', name, n, math.nan, total_wall, cpu,
                      note=f'exit {out.returncode}: {out.stderr.strip()[-300:]}')
    sim = json.loads((bag / 'summary.json').read_text())['sim']
    return Result('ros', name, n, float(sim['simulated_time']), float(sim['wall_time']), cpu,
                  ticks=int(round(sim['simulated_time'] * 100)),
                  note=f'{total_wall:.0f} s wall for the whole command (start-up, bag close; '
                       'the CPU figure includes start-up)')


# ------------------------------------------------------------------------------------ profiles
# where a lockstep tick goes in the nodes (cumulative time of these, when present)
STAGES = ('run', 'publish_state', 'wait_for_commands', 'publish_formation', 'advance',
          'snapshot', 'on_odometry', 'on_command', 'try_answer')


def top_costs(stats: pstats.Stats, count: int = 8) -> list[tuple[str, float, float, int]]:
    """[(function, own seconds, cumulative seconds, calls)]: the `count` largest by own time,
    then the node stages of STAGES by cumulative time (own time shown as-is)."""
    rows, stages = [], []
    for (filename, line, func), (_, calls, own, cum, _) in stats.stats.items():
        short = f'{Path(filename).name}:{line}({func})' if filename != '~' else func
        rows.append((short, own, cum, calls))
        node_file = Path(filename).name in ('sim_node.py', 'leader_node.py',
                                            'follower_node.py', 'simulation.py')
        if node_file and func in STAGES:
            stages.append((short, own, cum, calls))
    rows.sort(key=lambda r: -r[1])
    top = rows[:count]
    stages.sort(key=lambda r: -r[2])
    return top + [r for r in stages if r not in top]


def profile_headless(scenario, seconds: float) -> tuple[float, list]:
    scenario = with_duration(scenario, seconds)
    profiler = cProfile.Profile()
    profiler.enable()
    run_headless(scenario)
    profiler.disable()
    stats = pstats.Stats(profiler, stream=io.StringIO())
    return stats.total_tt, top_costs(stats)


def profile_ros(scenario_name: str, seconds: float, domain: int, workdir: Path) -> dict:
    """The twin-lift's sim_node, leader_node and follower_node each under cProfile."""
    from multilift_tools.run_command import ros_args
    scenario = scenario_io.load(scenario_name)
    path = str(scenario_io.resolve(scenario_name).resolve())
    summary = workdir / 'profile_summary'
    common = {'scenario': path, 'record': False, 'summary_dir': str(summary)}
    py = [sys.executable, '-m', 'cProfile', '-o']
    parts = {'sim_node': (find_executable('multilift_sim', 'sim_node'),
                          dict(common, duration=float(seconds)), 'sim', []),
             'leader_node': (find_executable('multilift_control', 'leader_node'), common,
                             'controller', [])}
    for i in range(2, scenario.n_uavs + 1):
        parts[f'follower_node_uav{i}'] = (find_executable('multilift_control', 'follower_node'),
                                          dict(common, uav_index=i), 'controller',
                                          ['-r', f'__node:=follower{i}'])
    children = [Child(label, [*py, str(workdir / f'{label}.prof'), str(exe),
                              *ros_args(params), *extra],
                      workdir / f'{label}.log', role)
                for label, (exe, params, role, extra) in parts.items()]
    old = os.environ.copy()
    os.environ.update(_ros_env(domain))
    try:
        outcome, dead = Supervisor(children).run()
    finally:
        os.environ.clear()
        os.environ.update(old)
    out = {'outcome': outcome if dead is None else f'{outcome}: {dead.name}'}
    sim = json.loads((summary / 'sim.json').read_text()) if (summary / 'sim.json').is_file() \
        else {}
    out['rate'] = sim.get('simulated_time', math.nan) / sim.get('wall_time', math.nan) \
        if sim else math.nan
    for label in parts:
        prof = workdir / f'{label}.prof'
        if prof.is_file():
            stats = pstats.Stats(str(prof), stream=io.StringIO())
            out[label] = (stats.total_tt, top_costs(stats))
    return out


# ------------------------------------------------------------------------------------ report
def fmt(value: float, digits: int = 1) -> str:
    return '-' if value is None or not math.isfinite(value) else f'{value:.{digits}f}'


def slope(ns: list[int], costs: list[float]) -> float:
    """Least-squares exponent k of cost ~ n^k."""
    if len(ns) < 2:
        return math.nan
    return float(np.polyfit(np.log(ns), np.log(costs), 1)[0])


def report(info: dict, results: list[Result], profiles: dict, started: str,
           load_end: tuple, args) -> str:
    ref = next((r for r in results if r.kind == 'rotorpy' and math.isfinite(r.rate)), None)
    lines = ['# multilift speed against rotorpy (`benchmarks/compare.py`)', '',
             f'Measured {started} by `python benchmarks/compare.py'
             f'{" " + " ".join(args) if args else ""}`.', '',
             f'- machine: {info["cpu"]}, {info["cores"]} cores, Python {info["python"]}, '
             f'numpy {info["numpy"]}, {info["blas"]}',
             f'- load average at start {", ".join(f"{v:.2f}" for v in info["load"])}, at end '
             f'{", ".join(f"{v:.2f}" for v in load_end)} (above ~1 other work shared the '
             'cores: wall-time figures are then low; the CPU-time column is less affected)',
             '- "sim s / wall s": simulated seconds per wall second; "sim s / CPU s": per second '
             'of CPU used by every process of the run; "x rotorpy": ratio of the wall figures',
             '']
    lines += ['## Simulated seconds per wall second', '',
              '| run | n | simulated [s] | wall [s] | sim s / wall s | sim s / CPU s | '
              'x rotorpy | note |', '| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |']
    for r in results:
        if r.kind == 'physics':
            continue
        ratio = r.rate / ref.rate if ref else math.nan
        lines.append(f'| {r.kind}: {r.name} | {r.n} | {fmt(r.simulated)} | {fmt(r.wall, 2)} | '
                     f'{fmt(r.rate, 2)} | {fmt(r.cpu_rate, 2)} | {fmt(ratio, 2)} | {r.note} |')
    lines += ['', '## Targets', '', '| target | measured | verdict |', '| --- | ---: | --- |']
    by_name = {f'{r.kind} {r.name}': r for r in results}
    for key, goal in TARGETS.items():
        r = by_name.get(key)
        if r is None or not math.isfinite(r.rate):
            lines.append(f'| {key} >= {goal:g}x real time | not run | - |')
            continue
        verdict = 'met' if r.rate >= goal else f'MISSED by {goal / r.rate:.1f}x ' \
            f'({r.rate:.2f} of {goal:g})'
        lines.append(f'| {key} >= {goal:g}x real time | {r.rate:.2f}x | {verdict} |')
    headless = [r for r in results if r.kind == 'headless' and r.ticks > 0]
    physics = [r for r in results if r.kind == 'physics']
    lines += ['', '## Cost per step against n', '',
              'Headless: wall time of one 10 ms control tick (snapshot, every controller, two '
              'RK4 steps of 5 ms, the checks). Physics: one RK4 step of the formation DAE alone '
              '(plus its share of the per-tick checks).', '',
              '| n | headless [us/tick] | headless [us/tick/UAV] | physics [us/RK4 step] | '
              'physics [us/step/UAV] |', '| ---: | ---: | ---: | ---: | ---: |']
    per_tick = {r.n: 1e6 * r.wall / r.ticks for r in headless if r.name.startswith('V')
                or r.n <= 2}
    per_step = {r.n: 1e6 * r.wall / r.extra['rk4_steps'] for r in physics}
    for n in sorted(set(per_tick) | set(per_step)):
        t = per_tick.get(n, math.nan)
        s = per_step.get(n, math.nan)
        lines.append(f'| {n} | {fmt(t, 0)} | {fmt(t / n, 1)} | {fmt(s, 1)} | {fmt(s / n, 2)} |')
    big = [n for n in sorted(per_tick) if n >= 10]
    big_p = [n for n in sorted(per_step) if n >= 10]
    lines += ['', f'Fitted exponent k of cost ~ n^k for n >= 10: headless tick '
              f'{fmt(slope(big, [per_tick[n] for n in big]), 2)}, physics step '
              f'{fmt(slope(big_p, [per_step[n] for n in big_p]), 2)} (1 = O(n)).', '']
    if profiles:
        lines += ['## Where the time goes (cProfile, own time)', '']
        for label, (total, rows) in profiles.items():
            lines += [f'### {label} ({total:.2f} s profiled)', '',
                      'The largest own times, then the node stages by cumulative time. '
                      'rclpy\'s `spin_once` own time includes the time blocked waiting for '
                      'the next message.', '',
                      '| function | own [s] | share | cumulative [s] | calls |',
                      '| --- | ---: | ---: | ---: | ---: |']
            for func, own, cum, calls in rows:
                lines.append(f'| `{func}` | {own:.3f} | {100 * own / total:.0f} % | {cum:.3f} '
                             f'| {calls} |')
            lines.append('')
    return '\n'.join(lines) + '\n'


def write_results(path: Path, text: str) -> None:
    notes = ''
    if path.is_file():
        old = path.read_text()
        if NOTES_MARKER in old:
            notes = old.split(NOTES_MARKER, 1)[1]
    path.write_text(text + '\n' + NOTES_MARKER + (notes or '\n'))


# ------------------------------------------------------------------------------------ main
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--out', default=str(ROOT / 'benchmarks' / 'results.md'))
    parser.add_argument('--quick', action='store_true',
                        help='short runs everywhere (a smoke test, not a measurement)')
    parser.add_argument('--full', action='store_true',
                        help='the whole 120 s mission for every headless n and ROS n = 10')
    parser.add_argument('--skip-rotorpy', action='store_true')
    parser.add_argument('--skip-ros', action='store_true')
    parser.add_argument('--no-profile', action='store_true')
    parser.add_argument('--domain', type=int, default=int(os.environ.get('COMPARE_DOMAIN', 11)),
                        help='ROS_DOMAIN_ID of the ROS runs (default 11)')
    args = parser.parse_args(argv)
    shown_args = [a for a in (argv if argv is not None else sys.argv[1:])]
    info = machine()
    started = datetime.datetime.now().strftime('%Y-%m-%d %H:%M')
    say(f'{info["cpu"]}, {info["cores"]} cores, Python {info["python"]}, numpy {info["numpy"]}, '
        f'load {info["load"][0]:.2f}')
    mission = 10.0 if args.quick else 120.0
    # simulated seconds per headless V run: the mission unless it would take long
    v_seconds = {3: mission, 10: mission, 30: mission if args.full else min(mission, 30.0),
                 100: mission if args.full else min(mission, 10.0)}
    ros_cases = [('single_lift', 'single_lift', 1, None), ('twin_lift', 'twin_lift', 2, None),
                 ('multi_lift (V n=3)', 'multi_lift', 3, None),
                 ('V n=10', 'v10', 10, None if args.full else 10.0)]
    results: list[Result] = []

    def show(r: Result) -> None:
        ref = next((x for x in results if x.kind == 'rotorpy'), None)
        ratio = f', {r.rate / ref.rate:6.2f}x rotorpy' if ref and r is not ref else ''
        say(f'{r.kind:8s} {r.name:46s} n={r.n:3d} {fmt(r.simulated):>6s} s sim in '
            f'{fmt(r.wall, 2):>7s} s wall: {fmt(r.rate, 2):>7s} sim s/wall s '
            f'({fmt(r.cpu_rate, 2)} per CPU s){ratio}  {r.note}')

    if not args.skip_rotorpy:
        results.append(run_rotorpy(mission))
        show(results[-1])
    for name in ('single_lift', 'twin_lift'):
        sc = with_duration(scenario_io.load(name), mission)
        results.append(run_headless_case(name, sc, sc.n_uavs))
        show(results[-1])
    scenarios = {}
    for n in (3, 10, 30, 100):
        data, length = v_formation_data(n)
        scenarios[n] = (data, length)
        sc = scenario_io.loads(yaml.safe_dump(data), f'multi_lift.yaml with formation.n = {n}')
        cable = '' if length == SEED_CABLE else f', cables {length:g} m'
        results.append(run_headless_case(f'V n={n}{cable}', with_duration(sc, v_seconds[n]),
                                         n))
        show(results[-1])
    for n in (1, 2, 3, 10, 30, 100):
        if n in scenarios:
            data = scenarios[n][0]
            sc = scenario_io.loads(yaml.safe_dump(data), f'v{n}')
        else:
            sc = scenario_io.load({1: 'single_lift', 2: 'twin_lift'}[n])
        results.append(run_physics_case(f'physics n={n}', sc, n, 2.0 if args.quick else 5.0))
        say(f'physics  n={n:3d}: {1e6 * results[-1].wall / results[-1].extra["rk4_steps"]:8.1f} '
            f'us per RK4 step ({results[-1].rate:.1f} sim s / wall s)')
    profiles: dict = {}
    with tempfile.TemporaryDirectory(prefix='multilift-compare-') as tmp:
        workdir = Path(tmp)
        if not args.skip_ros:
            (workdir / 'v10.yaml').write_text(yaml.safe_dump(scenarios[10][0]))
            for name, arg, n, duration in ros_cases:
                scenario_arg = str(workdir / 'v10.yaml') if arg == 'v10' else arg
                if args.quick:
                    duration = 5.0
                results.append(run_ros_case(name, scenario_arg, n, duration, args.domain,
                                            workdir))
                show(results[-1])
        if not args.no_profile:
            say('profiling the headless twin-lift (10 s)')
            profiles['headless twin_lift, 10 s simulated'] = profile_headless(
                scenario_io.load('twin_lift'), 10.0)
            if not args.skip_ros:
                say('profiling the ROS twin-lift nodes (10 s)')
                ros = profile_ros('twin_lift', 5.0 if args.quick else 10.0, args.domain,
                                  workdir)
                say(f'  {ros["outcome"]}, {fmt(ros["rate"], 2)} sim s / wall s under cProfile')
                for label in ('sim_node', 'leader_node', 'follower_node_uav2'):
                    if label in ros:
                        profiles[f'ROS twin_lift {label} (under cProfile: '
                                 f'{fmt(ros["rate"], 2)} sim s / wall s)'] = ros[label]
                say('profiling the ROS V n=10 nodes (3 s)')
                ros = profile_ros(str(workdir / 'v10.yaml'), 3.0, args.domain, workdir)
                say(f'  {ros["outcome"]}, {fmt(ros["rate"], 2)} sim s / wall s under cProfile')
                for label in ('sim_node', 'follower_node_uav2'):
                    if label in ros:
                        profiles[f'ROS V n=10 {label} (under cProfile: '
                                 f'{fmt(ros["rate"], 2)} sim s / wall s)'] = ros[label]
    for label, (total, rows) in profiles.items():
        say(f'top costs, {label}:')
        for func, own, cum, calls in rows[:5]:
            say(f'  {100 * own / total:4.0f} %  {own:7.3f} s own  {func}  ({calls} calls)')
    headless = [r for r in results if r.kind == 'headless' and r.ticks > 0]
    for r in headless:
        say(f'per tick: {r.name:32s} {1e6 * r.wall / r.ticks:9.0f} us '
            f'({1e6 * r.wall / r.ticks / r.n:7.1f} us per UAV)')
    text = report(info, results, profiles, started, os.getloadavg(), shown_args)
    out = Path(args.out)
    write_results(out, text)
    say(f'written: {out}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
