"""Runs that never trip over each other: every process of 20 runs on 20 domains is killed
(SIGKILL, mid-flight, the bag open), as a day of interrupted test suites and crashed sessions
leaves a machine; the next run's bag still has every topic and a live view forwards all of it.
None of the killed processes had Fast DDS's shared memory open, so they left none behind (our
participants use UDP only: multilift_sim.ros.fastdds; anyone else's stale files are removed at
`run` and `foxglove` start: multilift_sim.ros.shared_memory)."""
from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

import psutil

from conftest import ROOT, next_domain, wait_until_simulated
from multilift_sim.topics import run_topics
from test_foxglove_live import bridge, recorded_counts, ros_env, run_and_check  # noqa: F401

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
KILLED_RUNS = 20


def _shared_memory_in_use(process: psutil.Process) -> list[str]:
    """The Fast DDS files in /dev/shm the process has mapped or open."""
    try:
        maps = Path(f'/proc/{process.pid}/maps').read_text()
        fds = [os.readlink(fd) for fd in Path(f'/proc/{process.pid}/fd').iterdir()]
    except (OSError, psutil.Error):
        return []
    return sorted({line.split()[-1] for line in maps.splitlines() if '/dev/shm/fastrtps' in line}
                  | {fd for fd in fds if fd.startswith('/dev/shm/fastrtps')})


def _kill_every_process_of(run: subprocess.Popen) -> int:
    """SIGKILL the run's nodes (children in sessions of their own) and the run itself at once,
    as a crash would, once it is checked that none of them uses Fast DDS's shared memory; the
    number of processes killed."""
    family = psutil.Process(run.pid).children(recursive=True)
    for process in family:
        assert _shared_memory_in_use(process) == [], process.cmdline()
    for process in family:
        try:
            process.send_signal(signal.SIGKILL)
        except psutil.NoSuchProcess:
            pass
    run.send_signal(signal.SIGKILL)
    run.wait(timeout=30)
    psutil.wait_procs(family, timeout=30)
    return len(family) + 1


def test_after_twenty_killed_runs_a_run_records_every_topic_and_is_forwarded(
        bridge, ros_env, tmp_path):  # noqa: F811 - fixtures
    # domains of their own: never the live view's (it would forward a killed run's messages;
    # seen once in CI when the session's domain counter reached the bridge's)
    domains = [d for d in (next_domain() for _ in range(KILLED_RUNS + 1))
               if d != int(ros_env['ROS_DOMAIN_ID'])][:KILLED_RUNS]
    for k, domain in enumerate(domains):
        env = dict(os.environ, ROS_DOMAIN_ID=str(domain),
                   ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
        log = tmp_path / f'killed{k}.log'
        with open(log, 'w') as stderr:
            run = subprocess.Popen([MULTILIFT, 'run', 'single_lift', '--duration', '60', '--bag',
                                    str(tmp_path / f'killed{k}')], env=env, text=True,
                                   stdout=subprocess.PIPE, stderr=stderr)
        try:
            wait_until_simulated(run, 0.2)  # every node up, messages flowing, the bag open
        except AssertionError as error:
            raise AssertionError(f'run {k}: {error}\n{log.read_text()[-3000:]}') from None
        # the command, the simulator, the leader and the recorder
        assert _kill_every_process_of(run) == 4
    client, log, process = bridge
    run_and_check(client, log, process, ros_env, tmp_path / 'bag', 'twin_lift', 3.0, [])
    counts = recorded_counts(tmp_path / 'bag')
    assert sorted(counts) == sorted(topic for topic, _ in run_topics(2))
    assert counts['/uav2/rotor_cmd'] == 300 and counts['/payload/odom'] == 301
