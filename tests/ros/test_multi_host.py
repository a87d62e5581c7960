"""Controllers on another host (docs/deployment.md): the simulator and the recorder in one
network namespace, our controller nodes in another, a veth pair between them (10.77.0.1/24 and
10.77.0.2/24), so discovery and data have to cross that link: no loopback reaches the other
side. Every side runs Fast DDS with our profile (UDP only: multilift_sim.ros.fastdds), so no
message can take the shared memory (/dev/shm) both namespaces see, and the veth's byte
counters show the data crossed. Lockstep makes the link irrelevant to the result: the bag equals
the one-host run's, topic by topic, message for message. Discovery is Fast DDS's multicast
(ROS_AUTOMATIC_DISCOVERY_RANGE SUBNET, SPDP multicast routed onto the veth): our follower alone
(`--external uav2`, the case of the issue), then our leader and follower (`--external uav1,uav2`).

Needs root and `ip netns` (skipped otherwise, saying which).
"""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

from conftest import ROOT, next_domain, raw_messages
from multilift_sim.ros.fastdds import FASTDDS_PROFILE

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
DEPLOYMENT = ROOT / 'docs' / 'deployment.md'
SCENARIO = 'twin_lift'
DURATION = '5'
RUN_TIMEOUT = 300.0  # [s] wall, a loaded machine included
DOMAIN = str(next_domain())
SIM_ADDRESS, CONTROLLER_ADDRESS = '10.77.0.1', '10.77.0.2'
DEVICES = ('mlsim0', 'mlctl0')  # the veth's ends, each inside its namespace
PROFILE_VARIABLES = ('FASTRTPS_DEFAULT_PROFILES_FILE', 'FASTDDS_DEFAULT_PROFILES_FILE',
                     'FASTDDS_BUILTIN_TRANSPORTS', 'ROS_STATIC_PEERS')


def _ip(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(['ip', *args], capture_output=True, text=True, timeout=30)


def _netns_unavailable() -> str | None:
    if os.geteuid() != 0:
        return 'needs root: creates network namespaces and a veth pair (ip netns)'
    if shutil.which('ip') is None:
        return 'no `ip` command (iproute2) for network namespaces'
    probe = _ip('netns', 'list')
    if probe.returncode != 0:
        return f'`ip netns` unavailable: {probe.stderr.strip()}'
    return None


_UNAVAILABLE = _netns_unavailable()
pytestmark = pytest.mark.skipif(_UNAVAILABLE is not None, reason=_UNAVAILABLE or '')


@dataclass
class Link:
    """Two namespaces joined by a veth: `sim` (SIM_ADDRESS) and `controllers`
    (CONTROLLER_ADDRESS)."""
    sim: str
    controllers: str

    def controller_bytes(self) -> tuple[int, int]:
        """(received, sent) bytes of the controllers' end of the veth so far."""
        path = f'/sys/class/net/{DEVICES[1]}/statistics'
        out = subprocess.run(['ip', 'netns', 'exec', self.controllers, 'cat',
                              f'{path}/rx_bytes', f'{path}/tx_bytes'],
                             capture_output=True, text=True, timeout=30, check=True)
        received, sent = (int(v) for v in out.stdout.split())
        return received, sent


@pytest.fixture
def link():
    """A Link, its namespaces deleted afterwards (the veth goes with them); 224.0.0.0/4 is
    routed onto the veth on both sides (Fast DDS's SPDP discovery multicast)."""
    tag = os.getpid()
    link = Link(f'mlsim{tag}', f'mlctl{tag}')
    spaces = (link.sim, link.controllers)
    created = []
    try:
        for space in spaces:
            out = _ip('netns', 'add', space)
            if out.returncode != 0:
                pytest.skip(f'cannot create a network namespace: {out.stderr.strip()}')
            created.append(space)
        steps = [('link', 'add', DEVICES[0], 'netns', link.sim, 'type', 'veth',
                  'peer', 'name', DEVICES[1], 'netns', link.controllers)]
        for space, device, address in zip(spaces, DEVICES, (SIM_ADDRESS, CONTROLLER_ADDRESS)):
            steps += [('-n', space, 'link', 'set', 'lo', 'up'),
                      ('-n', space, 'addr', 'add', f'{address}/24', 'dev', device),
                      ('-n', space, 'link', 'set', device, 'up'),
                      ('-n', space, 'route', 'add', '224.0.0.0/4', 'dev', device)]
        for step in steps:
            out = _ip(*step)
            assert out.returncode == 0, f'ip {" ".join(step)}: {out.stderr}'
        yield link
    finally:
        for space in created:
            _ip('netns', 'delete', space)


def test_the_profile_in_the_deployment_guide_is_ours():
    [xml] = re.findall(r'```xml\n(.*?)```', DEPLOYMENT.read_text(), re.S)
    assert ' '.join(xml.split()) == ' '.join(FASTDDS_PROFILE.split())


@pytest.fixture(scope='module')
def one_host_bag(tmp_path_factory) -> dict[str, list[bytes]]:
    """The same scenario and duration on this host alone, our controllers started by `run`."""
    bag = tmp_path_factory.mktemp('one_host') / 'bag'
    env = dict(os.environ, ROS_DOMAIN_ID=DOMAIN, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    out = subprocess.run([MULTILIFT, 'run', SCENARIO, '--duration', DURATION, '--bag', str(bag)],
                         capture_output=True, text=True, timeout=RUN_TIMEOUT, env=env)
    assert out.returncode == 0, out.stdout + out.stderr
    return raw_messages(bag)


def _stop(process: subprocess.Popen) -> int:
    """Ctrl-C a process group we started (SIGKILL if it does not end); its exit code."""
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGINT)
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait(timeout=10)
    return process.returncode


def fly_across(link: Link, tmp_path: Path, external: str, controllers: dict[str, list[str]]
               ) -> tuple[dict[str, list[bytes]], int, int]:
    """`multilift run SCENARIO --external EXTERNAL --bag` in the simulator's namespace and each
    of `controllers` (log name -> `multilift node` arguments) in the other, our profile (UDP
    only) on both sides; discovery range SUBNET. Returns the bag's messages and the
    bytes the controllers' end of the veth received and sent meanwhile."""
    sim_env = {k: v for k, v in os.environ.items() if k not in PROFILE_VARIABLES}
    sim_env.update(ROS_DOMAIN_ID=DOMAIN, ROS_AUTOMATIC_DISCOVERY_RANGE='SUBNET',
                   PYTHONUNBUFFERED='1')
    controller_env = sim_env  # our processes use our profile (UDP only) on their own
    bag = tmp_path / 'bag'
    logs = {name: tmp_path / f'{name}.log' for name in ['run', *controllers]}
    commands = {'run': ['ip', 'netns', 'exec', link.sim, MULTILIFT, 'run', SCENARIO,
                        '--external', external, '--duration', DURATION, '--bag', str(bag)]}
    for name, args in controllers.items():
        commands[name] = ['ip', 'netns', 'exec', link.controllers, MULTILIFT, 'node',
                          'multilift_control', *args]
    before = link.controller_bytes()
    processes: dict[str, subprocess.Popen] = {}
    try:
        for name, argv in commands.items():
            with open(logs[name], 'w') as log:
                processes[name] = subprocess.Popen(
                    argv, env=sim_env if name == 'run' else controller_env, stdout=log,
                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
        code = processes['run'].wait(timeout=RUN_TIMEOUT)
    finally:
        codes = {name: _stop(process) for name, process in processes.items()}

    def output() -> str:
        return '\n'.join(f'--- {name}:\n{path.read_text()}' for name, path in logs.items())
    assert code == 0, output()
    # the nodes answered until the run ended and stopped cleanly at Ctrl-C
    assert all(c == 0 for c in codes.values()), (codes, output())
    after = link.controller_bytes()
    return raw_messages(bag), after[0] - before[0], after[1] - before[1]


def assert_same_bag(bag: dict[str, list[bytes]], one_host: dict[str, list[bytes]]) -> None:
    assert sorted(bag) == sorted(one_host)
    for topic, messages in one_host.items():
        assert len(bag[topic]) == len(messages), topic
        assert bag[topic] == messages, f'{topic}: the messages differ'


def total(bag: dict[str, list[bytes]], *topics: str) -> int:
    return sum(len(data) for topic in topics for data in bag[topic])


FOLLOWER = ['follower_node', '--ros-args', '-p', f'scenario:={SCENARIO}', '-p', 'uav_index:=2']
LEADER = ['leader_node', '--ros-args', '-p', f'scenario:={SCENARIO}']
FOLLOWER_TOPICS = ('/uav2/rotor_cmd', '/uav2/attitude_setpoint', '/uav2/formation_error')
LEADER_TOPICS = ('/uav1/rotor_cmd', '/uav1/reference', '/uav1/attitude_setpoint')


def test_our_follower_on_another_host_flies_the_one_host_run(link, one_host_bag, tmp_path):
    bag, received, sent = fly_across(link, tmp_path, 'uav2', {'follower': FOLLOWER})
    assert_same_bag(bag, one_host_bag)
    # what the follower read (the snapshot, the leader's command) came over the link, and
    # what it published went back over it (each message with its RTPS, UDP and IP headers)
    assert received > total(bag, '/formation/snapshot', '/uav1/rotor_cmd')
    assert sent > total(bag, *FOLLOWER_TOPICS)


def test_our_leader_and_follower_on_another_host_fly_the_one_host_run(link, one_host_bag,
                                                                      tmp_path):
    bag, received, sent = fly_across(link, tmp_path, 'uav1,uav2',
                                     {'leader': LEADER, 'follower': FOLLOWER})
    assert_same_bag(bag, one_host_bag)
    assert received > total(bag, '/formation/snapshot')
    assert sent > total(bag, *LEADER_TOPICS, *FOLLOWER_TOPICS)
