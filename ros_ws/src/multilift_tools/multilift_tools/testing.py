"""pytest fixtures for testing your own nodes against a multilift run (a pytest plugin: the
`multilift_tools` package registers it, so the fixtures are there in any test once the
workspace is sourced).

`multilift_domain`: a ROS domain of the test's own, discovery limited to this machine, set in
the test's environment (so `rclpy.init()` in the test and every process it starts use it):
MULTILIFT_TEST_DOMAIN if set, else one drawn from the pid in 70-99.

`multilift_run`: starts `multilift run SCENARIO [--external ...] [--bag ...]` in that domain and
gives a `ScenarioRun` (`.wait()`, `.output()`, `.bag`; `headless=True`: `run --headless`, no
ROS graph); every run still going is stopped at the end of the test (the bag is closed)::

    def test_my_leader(multilift_run, tmp_path):
        run = multilift_run('single_lift', external='uav1', duration=2.0,
                            bag=tmp_path / 'bag')
        leader = subprocess.Popen(['ros2', 'run', 'my_pkg', 'my_leader'])  # same domain
        assert run.wait(timeout=120) == 0, run.output()
        leader.terminate()
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

STOP_TIMEOUT = 30.0  # [s] a stopped run has to close its bag and exit


class ScenarioRun:
    """One `multilift run` process (see the module docstring)."""

    def __init__(self, argv: list[str], env: dict, log_path: Path, bag: Path | None) -> None:
        self.argv, self.bag, self.log_path = argv, bag, log_path
        self._log = open(log_path, 'w+')
        self.process = subprocess.Popen(argv, env=env, stdout=self._log,
                                        stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                        start_new_session=True)

    def output(self) -> str:
        """What the run printed so far (stdout and stderr)."""
        self._log.flush()
        return self.log_path.read_text()

    def wait_for_output(self, text: str, timeout: float = 60.0) -> str:
        """Wait until the run printed `text`; AssertionError if it exits or times out first."""
        deadline = time.monotonic() + timeout
        while text not in self.output():
            assert self.process.poll() is None, \
                f'the run exited ({self.process.returncode}) before printing {text!r}:\n' \
                f'{self.output()}'
            assert time.monotonic() < deadline, f'no {text!r} after {timeout} s:\n' \
                                                f'{self.output()}'
            time.sleep(0.1)
        return self.output()

    def wait(self, timeout: float = 300.0) -> int:
        """The run's exit code once it ended (0: finished)."""
        return self.process.wait(timeout=timeout)

    def stop(self) -> int:
        """Ctrl-C the run (it stops its nodes and closes the bag); its exit code."""
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGINT)
            try:
                self.process.wait(timeout=STOP_TIMEOUT)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait(timeout=10)
        self._log.close()
        return self.process.returncode


@pytest.fixture
def multilift_domain(monkeypatch) -> int:
    """A ROS domain of this test's own (see the module docstring), set in os.environ."""
    given = os.environ.get('MULTILIFT_TEST_DOMAIN')
    domain = int(given) if given else 70 + os.getpid() % 30
    monkeypatch.setenv('ROS_DOMAIN_ID', str(domain))
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return domain


@pytest.fixture
def multilift_run(multilift_domain, tmp_path):
    """A function starting `multilift run` (see the module docstring)."""
    runs: list[ScenarioRun] = []

    def start(scenario: str, external: str | list[str] | None = None,
              duration: float | None = None, bag: str | Path | None = None,
              realtime: bool = False, startup_timeout: float | None = None,
              headless: bool = False) -> ScenarioRun:
        argv = [sys.executable, '-m', 'multilift_tools.cli', 'run', str(scenario)]
        if external:
            argv += ['--external', external if isinstance(external, str) else ','.join(external)]
        if duration is not None:
            argv += ['--duration', str(duration)]
        if bag is not None:
            argv += ['--bag', str(bag)]
        if realtime:
            argv.append('--realtime')
        if headless:
            argv.append('--headless')
        if startup_timeout is not None:
            argv += ['--startup-timeout', str(startup_timeout)]
        env = dict(os.environ, PYTHONUNBUFFERED='1')
        run = ScenarioRun(argv, env, tmp_path / f'multilift_run{len(runs) + 1}.log',
                          None if bag is None else Path(bag))
        runs.append(run)
        return run

    yield start
    for run in runs:
        run.stop()
