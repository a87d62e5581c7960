"""`run --compose`: every controller node of a run in one process (controllers_node: one rclpy
context, one executor) gives the run of one process per node: the same graph, the same bag."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import psutil
import pytest

from conftest import ROOT, next_domain, raw_messages, wait_until_simulated
from multilift_tools.bagdata import load_run

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
EXECUTABLES = ('sim_node', 'recorder_node', 'leader_node', 'follower_node', 'controllers_node')


def ros_env() -> dict:
    return dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')


def executable(process: psutil.Process) -> str | None:
    """Which of our node executables a process runs (python SCRIPT ...), or None."""
    try:
        names = [Path(arg).name for arg in process.cmdline()[:2]]
    except psutil.Error:
        return None
    return next((name for name in EXECUTABLES if name in names), None)


def run_and_watch(args: list[str], env: dict, log: Path) -> Counter:
    """Run `multilift ARGS` to its end (exit code 0 asserted); how many processes of each of
    our node executables it started (its children, looked at until it exits)."""
    seen: dict[int, str] = {}
    with open(log, 'w') as out:
        launcher = psutil.Popen([MULTILIFT, *args], env=env, stdout=out,
                                stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        deadline = time.monotonic() + 600
        while launcher.poll() is None:
            assert time.monotonic() < deadline, f'{args} still running after 600 s'
            try:
                children = launcher.children(recursive=True)
            except psutil.Error:
                children = []
            for child in children:
                if child.pid not in seen and (name := executable(child)) is not None:
                    seen[child.pid] = name
            time.sleep(0.05)
    assert launcher.returncode == 0, log.read_text()[-3000:]
    return Counter(seen.values())


@dataclass
class Runs:
    scenario: str
    separate: Path      # the bags
    compose: Path
    processes: dict     # mode -> Counter of executables


# the V of three: a leader and two followers in the composed process (the twin-lift's one
# follower is a case of it)
@pytest.fixture(scope='module', params=['multi_lift'])
def runs(request, tmp_path_factory) -> Runs:
    """The scenario's first 3 s with --bag, one process per node and composed."""
    root = tmp_path_factory.mktemp(request.param)
    env = ros_env()
    processes = {}
    for mode in ('separate', 'compose'):
        args = ['run', request.param, '--duration', '3', '--bag', str(root / mode)]
        processes[mode] = run_and_watch(args + (['--compose'] if mode == 'compose' else []),
                                        env, root / f'{mode}.log')
    return Runs(request.param, root / 'separate', root / 'compose', processes)


def test_one_process_holds_every_controller(runs):
    n = {'twin_lift': 2, 'multi_lift': 3}[runs.scenario]
    assert runs.processes['separate'] == Counter(
        sim_node=1, recorder_node=1, leader_node=1, follower_node=n - 1)
    assert runs.processes['compose'] == Counter(sim_node=1, recorder_node=1, controllers_node=1)


def test_same_topics_and_counts(runs):
    separate, compose = raw_messages(runs.separate), raw_messages(runs.compose)
    assert {t: len(m) for t, m in compose.items()} == {t: len(m) for t, m in separate.items()}
    assert len(compose['/uav2/rotor_cmd']) == 300 and len(compose['/uav1/odom']) == 301


def test_same_trajectories(runs):
    separate, compose = load_run(runs.separate), load_run(runs.compose)
    assert np.array_equal(separate.t, compose.t)
    assert np.abs(separate.uav_positions() - compose.uav_positions()).max() < 1e-9
    assert np.abs(separate.payload_position() - compose.payload_position()).max() < 1e-9
    for i in range(1, separate.n_uavs + 1):
        assert np.abs(separate.rotor_speeds(i) - compose.rotor_speeds(i)).max() < 1e-9
    for i in separate.followers:
        assert np.abs(separate.formation_errors(i) - compose.formation_errors(i)).max() < 1e-9
    assert np.abs(separate.tensions() - compose.tensions()).max() < 1e-9
    assert np.ptp(compose.uav_positions()[0][:, 2]) > 0.1  # the formation moved


def test_same_summaries(runs):
    separate, compose = (json.loads((bag / 'summary.json').read_text())
                         for bag in (runs.separate, runs.compose))
    assert set(compose) == set(separate)
    for part in set(compose) - {'sim'}:  # the controllers' figures; the simulator's wall differs
        assert compose[part] == separate[part], part


def test_compose_with_headless_is_exit_2():
    out = subprocess.run([MULTILIFT, 'run', 'twin_lift', '--headless', '--compose'],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert 'error: --compose' in out.stderr and 'nothing to compose' in out.stderr


# lists the graph's nodes once every controller of a V of three is in it
GRAPH_PROBE = """
import sys, time
import rclpy
rclpy.init()
node = rclpy.create_node('graph_probe')
wanted = {'sim', 'recorder', 'leader', 'follower2', 'follower3'}
deadline = time.monotonic() + 60
while not wanted <= {name for name, _ in node.get_node_names_and_namespaces()}:
    assert time.monotonic() < deadline, node.get_node_names_and_namespaces()
    rclpy.spin_once(node, timeout_sec=0.1)
for name in sorted(wanted - {'sim', 'recorder'}):
    topics = sorted(t for t, _ in node.get_publisher_names_and_types_by_node(name, '/')
                    if t.startswith('/uav'))
    print(name, ' '.join(topics))
"""


def test_the_graph_is_the_same_and_a_killed_composed_process_is_named(tmp_path):
    """The nodes keep their names and topics in one process; killing it ends the run, with
    the controllers it held named."""
    env = ros_env()
    run = subprocess.Popen([MULTILIFT, 'run', 'multi_lift', '--compose', '--bag',
                            str(tmp_path / 'bag')], env=env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        wait_until_simulated(run, 0.5)
        probe = subprocess.run([sys.executable, '-c', GRAPH_PROBE], env=env,
                               capture_output=True, text=True, timeout=120)
        assert probe.returncode == 0, probe.stderr
        assert probe.stdout.splitlines() == [
            'follower2 /uav2/attitude_setpoint /uav2/formation_error /uav2/rotor_cmd',
            'follower3 /uav3/attitude_setpoint /uav3/formation_error /uav3/rotor_cmd',
            'leader /uav1/attitude_setpoint /uav1/reference /uav1/rotor_cmd']
        [composed] = [p for p in psutil.Process(run.pid).children(recursive=True)
                      if executable(p) == 'controllers_node']
        composed.kill()
        _, err = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
            run.wait(timeout=30)
    assert run.returncode == 1, err
    assert 'error: controllers (uav1..uav3) stopped (killed by SIGKILL)' in err
    assert (tmp_path / 'bag' / 'metadata.yaml').is_file()  # the recorder closed the bag


def test_an_external_uav_is_not_in_the_composed_process(tmp_path):
    """`--compose --external uav1`: the composed process holds the followers only; the leader
    is the test's own leader_node, and the run is whole."""
    env = ros_env()
    bag = tmp_path / 'bag'
    run = subprocess.Popen([MULTILIFT, 'run', 'multi_lift', '--compose', '--external', 'uav1',
                            '--duration', '1', '--bag', str(bag)], env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True)
    with open(tmp_path / 'leader.log', 'w') as log:
        leader = subprocess.Popen([MULTILIFT, 'node', 'multilift_control', 'leader_node',
                                   '--ros-args', '-p', 'scenario:=multi_lift'], env=env,
                                  stdout=log, stderr=subprocess.STDOUT,
                                  stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        out, err = run.communicate(timeout=300)
        assert run.returncode == 0, err + (tmp_path / 'leader.log').read_text()
    finally:
        os.killpg(leader.pid, signal.SIGINT)
        leader.wait(timeout=30)
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
            run.wait(timeout=30)
    recorded = raw_messages(bag)
    assert (len(recorded['/uav1/rotor_cmd']) == len(recorded['/uav3/rotor_cmd'])
            == len(recorded['/formation/snapshot']) == 100)
    assert 'uav3 formation' in out
