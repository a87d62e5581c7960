"""Per-call costs of the headless bag and the float kernel, in CPU time (time.process_time, best
of several repeats, so other processes on the machine disturb it little):

- per message: rclpy (build the message with multilift_sim.ros.messages / markers, then
  rclpy.serialization.serialize_message) against multilift_sim.wire.cdr (pack from the same values);
- per RK4 step (twin_lift, n = 2): the pure-Python float kernel against the compiled one;
- a new process importing the compiled kernel from numba's cache and making its first call;
- a headless twin_lift run with and without the bag, per tick;
- the bag's share of a whole engine-flown mission (`--bag-only`, issue 31's "--bag at least
  65x"): CPU of `multilift_control.headless.fly` (what `run --headless` does) and of
  `record_headless` (what `run --headless --bag` does), best of 3 each, and the bag's messages
  a second of its extra CPU (packing and writing, in blocks of ticks: BagWriter.write_block).

Run: source scripts/env.sh && python benchmarks/headless_bag.py [--seconds 20]
     source scripts/env.sh && python benchmarks/headless_bag.py --bag-only [--scenario twin_lift]
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def best_us(fn, number: int, repeat: int = 5) -> float:
    """Best per-call CPU time [us] of `fn()` over `repeat` rounds of `number` calls."""
    best = float('inf')
    for _ in range(repeat):
        start = time.process_time()
        for _ in range(number):
            fn()
        best = min(best, time.process_time() - start)
    return best / number * 1e6


def messages_table() -> None:
    from rclpy.serialization import serialize_message

    from multilift_sim.wire import cdr, cdr_scene, msgvalues
    from multilift_sim import scenario as scenario_io
    from multilift_sim.ros import messages
    from multilift_sim.ros.markers import formation_markers
    from multilift_sim.wire.scene import FormationScene
    from multilift_sim.simulation import FormationSimulator

    scenario = scenario_io.load('twin_lift')
    sim = FormationSimulator(scenario)
    snap = sim.snapshot()
    uav = snap.uavs[0]
    t_ns = 1_230_000_000
    tension, g, g_dot = sim.cable_state([np.full(4, 1500.0)] * 2)
    speeds = [np.full(4, 1500.0), np.full(4, 1490.0)]
    odom = cdr.Odometry('uav1/base_link')
    state = cdr.formation_state(2)
    snapshot = cdr.FormationSnapshot([4, 4])
    clock = cdr.Clock()
    scene = FormationScene(scenario)
    markers = cdr_scene.MarkerArray(scene.specs)

    def pack_markers():
        scene.update([u.position for u in snap.uavs], [u.euler for u in snap.uavs],
                     snap.payload_position, tension)
        return markers.pack(t_ns)

    rows = [
        ('Clock', lambda: serialize_message(messages.clock(t_ns)),
         lambda: clock.pack(t_ns)),
        ('Odometry (uav)', lambda: serialize_message(messages.uav_odometry(t_ns, 1, uav)),
         lambda: odom.pack(t_ns, *msgvalues.odometry(uav.position, uav.velocity,
                                                      uav.orientation, uav.body_velocity,
                                                      uav.body_rates))),
        ('FormationState (n=2)',
         lambda: serialize_message(messages.formation_state(t_ns, tension, g, g_dot)),
         lambda: state.pack(t_ns, tension.tolist(), g.tolist(), g_dot.tolist(), [True] * 2)),
        ('FormationSnapshot (n=2)',
         lambda: serialize_message(messages.formation_snapshot(snap, speeds, [4, 4])),
         lambda: snapshot.pack(t_ns, *msgvalues.formation_snapshot(snap, speeds))),
        ('MarkerArray (n=2, 2 gusts)',
         lambda: serialize_message(formation_markers(snap, tension, scenario, t_ns)),
         pack_markers),
    ]
    print('per message, build + serialize [us]       rclpy      cdr   ratio')
    for name, slow, fast in rows:
        number = 200 if 'Marker' in name else 2000
        a, b = best_us(slow, number), best_us(fast, number)
        print(f'  {name:36s} {a:9.1f} {b:8.2f} {a / b:7.1f}x')


def kernel_table() -> None:
    from multilift_sim import kernels
    from multilift_sim import scenario as scenario_io
    from multilift_sim.simulation import FormationSimulator

    sim = FormationSimulator(scenario_io.load('twin_lift'))
    speeds = [np.full(4, 1500.0), np.full(4, 1490.0)]
    model, x, dt = sim.model, sim.state, sim.dt
    steps = sim.steps_per_tick
    print(f'RK4 step, twin_lift (n=2) [us]  ({steps} steps per call of integrate)')
    for mode in ('python', 'auto'):
        os.environ['MULTILIFT_KERNEL'] = mode
        if mode == 'auto' and not kernels.enabled():
            print('  compiled: numba not installed')
            continue
        model.integrate(x, speeds, dt, steps)  # compile / load
        per_call = best_us(lambda: model.integrate(x, speeds, dt, steps), 200)
        print(f'  {"pure Python" if mode == "python" else "compiled (numba)":20s} '
              f'{per_call / steps:8.2f} per step, {per_call:8.1f} per control period')
    os.environ.pop('MULTILIFT_KERNEL')
    code = ('import time; t0 = time.process_time(); w0 = time.perf_counter()\n'
            'import numpy as np\n'
            'from multilift_sim import kernels\n'
            'from multilift_sim import scenario as s\n'
            'from multilift_sim.simulation import FormationSimulator\n'
            'sim = FormationSimulator(s.load("twin_lift"))\n'
            't1 = time.process_time(); w1 = time.perf_counter()\n'
            'sim.model.integrate(sim.state, [np.full(4, 1500.0)] * 2, sim.dt, 1)\n'
            'print(time.process_time() - t1, time.perf_counter() - w1)')
    for label in ('first (cache may be cold)', 'cached'):
        out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                             check=True).stdout.split()
        print(f'  new process, numba import + first integrate, {label}: '
              f'{float(out[0]):.2f} s CPU, {float(out[1]):.2f} s wall')


def run_table(seconds: float) -> None:
    from multilift_control.headless import run_headless
    from multilift_sim import scenario as scenario_io
    from multilift_tools.headless_bag import record_headless

    scenario = scenario_io.load('twin_lift')
    scenario = dataclasses.replace(scenario, simulation=dataclasses.replace(
        scenario.simulation, duration=seconds))
    ticks = scenario.simulation.tick_count + 1
    print(f'headless twin_lift, {seconds:g} s simulated ({ticks} ticks) [us per tick, CPU]; '
          'the kernel is the physics and the control laws')
    for kernel in ('python', 'auto'):
        os.environ['MULTILIFT_KERNEL'] = kernel
        start = time.process_time()
        run_headless(scenario)
        plain = time.process_time() - start
        with tempfile.TemporaryDirectory() as tmp:
            start = time.process_time()
            record_headless(scenario, Path(tmp) / 'bag')
            bagged = time.process_time() - start
        print(f'  kernel {kernel:7s} no bag {plain / ticks * 1e6:8.1f}   '
              f'with bag {bagged / ticks * 1e6:8.1f}   (bag {(bagged - plain) / ticks * 1e6:.1f}'
              f'; {seconds / plain:.0f}x / {seconds / bagged:.0f}x real time CPU)')
    os.environ.pop('MULTILIFT_KERNEL')


def bag_table(name: str, repeat: int = 3) -> None:
    from multilift_control.headless import fly
    from multilift_sim import scenario as scenario_io
    from multilift_tools.headless_bag import record_headless

    scenario = scenario_io.load(name)
    fly(scenario)  # kernels loaded, caches warm
    plain = bagged = float('inf')
    messages = 0
    for _ in range(repeat):
        start = time.process_time()
        fly(scenario)
        plain = min(plain, time.process_time() - start)
        with tempfile.TemporaryDirectory() as tmp:
            start = time.process_time()
            record_headless(scenario, Path(tmp) / 'bag')
            bagged = min(bagged, time.process_time() - start)
            text = (Path(tmp) / 'bag' / 'metadata.yaml').read_text()
            messages = int(text.split('message_count: ', 1)[1].split()[0])
    share = bagged - plain
    print(f'{name}, {scenario.simulation.duration:g} s simulated, CPU best of {repeat} '
          f'(load {os.getloadavg()[0]:.2f}): fly {plain:.3f} s, record_headless {bagged:.3f} s,'
          f' the bag {share:.3f} s for {messages} messages: {messages / share:,.0f} messages/s')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seconds', type=float, default=20.0,
                        help='simulated seconds of the headless runs (default 20)')
    parser.add_argument('--bag-only', action='store_true',
                        help="only the bag's share of a whole mission (the last table)")
    parser.add_argument('--scenario', default='twin_lift',
                        help='the mission of --bag-only (default twin_lift, 120 s)')
    args = parser.parse_args()
    if args.bag_only:
        bag_table(args.scenario)
        return
    messages_table()
    kernel_table()
    run_table(args.seconds)


if __name__ == '__main__':
    main()
