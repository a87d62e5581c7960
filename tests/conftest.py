"""Shared test fixtures: the repository paths, an isolated ROS environment, the two layers.

Tests live in two layers, each a folder and a marker (set here from the folder):
- `tests/unit/` (marker `unit`): no ROS graph and no processes (tests/unit/conftest.py refuses
  them); physics, scenarios, message definitions, the bag format, plots of synthetic bags, the
  import architecture. Fast: under a minute.
- `tests/ros/` (marker `ros`), the process layer: anything that starts a process or talks to a
  ROS graph: runs of `scripts/multilift run`, the topic and bag tools against live publishers,
  the Foxglove bridge, the launcher, start-up in a new process, the command line, lint.
`scripts/test` runs both; `scripts/test --unit` (or `scripts/test tests/unit`) the fast layer.
"""
from __future__ import annotations

import _posixsubprocess
import contextlib
import itertools
import os
import re
import select
import signal
import subprocess
import time
from pathlib import Path
from typing import Callable, Iterator, TypeVar

import pytest

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
SCENARIOS = ROOT / 'scenarios'


def realistic_scenario(duration: float, **sections):
    """twin_lift_realistic flown `duration` [s], each of `sections` (a top-level key) set to
    its value, or removed where it is None (the estimation tests' variants)."""
    import yaml
    from multilift_sim import scenario as scenario_io
    data = yaml.safe_load((SCENARIOS / 'twin_lift_realistic.yaml').read_text())
    data['simulation']['duration'] = duration
    for name, value in sections.items():
        if value is None:
            data.pop(name, None)
        else:
            data[name] = value
    return scenario_io.loads(yaml.safe_dump(data))


LAYERS = {'unit': 'no ROS graph, no processes (tests/unit/)',
          'ros': 'starts processes or talks to a ROS graph (tests/ros/)'}
T = TypeVar('T')
# ROS domains: each pytest process (pytest-xdist worker gwK of W, or the one process) draws
# from a band of its own, so concurrent workers never share a domain; every test that starts a
# graph takes its domain from next_domain() (the one allocator)
# 1..101: higher domains' ports fall in Linux's ephemeral range (ROS 2's domain ID guide)
DOMAIN_BANDS = range(1, 102)
_worker = int(os.environ.get('PYTEST_XDIST_WORKER', 'gw0')[2:])
_workers = int(os.environ.get('PYTEST_XDIST_WORKER_COUNT', '1'))
_band = DOMAIN_BANDS[_worker * len(DOMAIN_BANDS) // _workers:
                     (_worker + 1) * len(DOMAIN_BANDS) // _workers]
_domains = itertools.count(int(os.environ.get('ROS_DOMAIN_ID', '77')))


def pytest_configure(config) -> None:
    for name, what in LAYERS.items():
        config.addinivalue_line('markers', f'{name}: {what}')


def _refuse_process(*args, **kwargs):
    raise AssertionError('tests/unit starts no processes: a test that needs one belongs in '
                         'tests/ros (the process layer)')


@pytest.fixture(scope='module', autouse=True)
def unit_layer_starts_no_process(request):
    """In tests/unit, starting a process (subprocess, fork, spawn, multiprocessing) fails the
    test. Module-wide, so a module's own fixtures are covered too (autouse fixtures of a scope
    come first)."""
    if Path(str(request.path)).resolve().relative_to(TESTS).parts[0] != 'unit':
        yield
        return
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(subprocess.Popen, '_execute_child', _refuse_process)
        patch.setattr(_posixsubprocess, 'fork_exec', _refuse_process)  # multiprocessing's spawn
        for name in ('fork', 'forkpty', 'posix_spawn', 'posix_spawnp', 'system', 'execv',
                     'execve'):
            if hasattr(os, name):
                patch.setattr(os, name, _refuse_process)
        yield


def pytest_sessionstart(session) -> None:
    """Fast DDS's shared-memory files of processes killed earlier (this suite's SIGKILL tests
    of a previous run included) are removed before any test starts a node, as `multilift run`
    does (multilift_sim.ros.shared_memory)."""
    from multilift_sim.ros.shared_memory import remove_stale_files
    remove_stale_files()
    session.config.semaphores_before = _semaphores()


def _semaphores() -> set[str]:
    """multiprocessing's named semaphores in /dev/shm (sem.mp-*): removed by their process's
    resource tracker when it ends; one left is a process that did not end (issue 37: a
    fresh-clone run once left 12)."""
    shm = Path('/dev/shm')
    return {p.name for p in shm.glob('sem.mp-*')} if shm.is_dir() else set()


def pytest_sessionfinish(session, exitstatus) -> None:
    """The session fails when its processes left multiprocessing semaphores behind (checked
    once, by the controlling pytest process, after every worker ended)."""
    if hasattr(session.config, 'workerinput'):  # an xdist worker: its controller checks
        return
    left = sorted(_semaphores() - getattr(session.config, 'semaphores_before', set()))
    if left:
        reporter = session.config.pluginmanager.get_plugin('terminalreporter')
        if reporter is not None:
            reporter.write_line(f'error: the tests left {len(left)} multiprocessing semaphores '
                                f'in /dev/shm: {", ".join(left)}', red=True)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


# The longest test files (a minute or more of wall time each) first: pytest-xdist hands a
# worker one file at a time in this order, so none of them is left to run alone at the end.
LONGEST_FIRST = ('test_killed_runs.py', 'test_formation_missions.py', 'test_compose.py',
                 'test_end_to_end.py', 'test_robustness.py')


def pytest_collection_modifyitems(config, items) -> None:
    """Mark every test with its layer, the folder it lives in (`-m unit`, `-m ros`); the
    LONGEST_FIRST files first (the order within a file kept)."""
    def rank(item) -> int:
        name = Path(str(item.fspath)).name
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)
    items.sort(key=rank)
    for item in items:
        layer = Path(str(item.fspath)).resolve().relative_to(TESTS).parts[0]
        if layer in LAYERS:
            item.add_marker(getattr(pytest.mark, layer))


@pytest.fixture(scope='module')
def twin():
    """(the twin_lift scenario, a snapshot 30 ticks after its start at uneven hover speeds:
    tilted and swinging, off the symmetric start) for message and marker tests."""
    import numpy as np
    from multilift_sim import scenario as scenario_io
    from multilift_sim.simulation import FormationSimulator
    scenario = scenario_io.load('twin_lift')
    simulator = FormationSimulator(scenario)
    hover = [np.array([1500.0, 1490.0, 1500.0, 1510.0]) for _ in scenario.uavs]
    for _ in range(30):
        simulator.advance(hover, [np.zeros(u.vehicle.n_rotors, bool) for u in scenario.uavs])
    return scenario, simulator.snapshot()


def next_domain() -> int:
    """A ROS domain no earlier test of this pytest process used and no other worker of the
    session uses (round robin over this process's band of DOMAIN_BANDS)."""
    return _band[next(_domains) % len(_band)]


@pytest.fixture
def multilift_domain(monkeypatch) -> int:
    """multilift_tools.testing's fixture of that name, on a domain of next_domain()'s (this
    suite runs in parallel workers: a domain from the pid, as the plugin draws it, could be
    another worker's)."""
    domain = next_domain()
    monkeypatch.setenv('ROS_DOMAIN_ID', str(domain))
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return domain


@pytest.fixture(autouse=True)
def restored_environ():
    """os.environ after each test restored to what it was before, whatever the test or the code
    it calls set there directly. Autouse, so it is set up before and torn down after the
    test's own fixtures, monkeypatch included. (use_fastdds_profile names its profile in
    os.environ: left behind in a pytest worker, it gave the worker's later runs rmw's shared
    memory and no live view.)"""
    saved = dict(os.environ)
    yield os.environ
    if dict(os.environ) != saved:
        os.environ.clear()
        os.environ.update(saved)


@pytest.fixture
def ros_env(monkeypatch) -> dict:
    """An environment on a ROS domain of its own, discovery limited to this machine."""
    domain = str(next_domain())
    monkeypatch.setenv('ROS_DOMAIN_ID', domain)
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return dict(os.environ)


def raw_messages(bag: Path) -> dict[str, list[bytes]]:
    """Every topic's messages in a bag directory (its one MCAP file, finished or not), as CDR
    bytes in log time order."""
    from mcap.reader import make_reader
    [path] = bag.glob('*.mcap')
    messages: dict[str, list[bytes]] = {}
    with open(path, 'rb') as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=True):
            messages.setdefault(channel.topic, []).append(message.data)
    return messages


def flown_alike(multilift_run, scenario: str, folder: Path):
    """`scenario` (a name or path) run through ROS (`multilift run --bag`) and headless
    (`--headless --bag`) into `folder`/ros and `folder`/headless; both must exit 0 and agree on
    every UAV's and the payload's position to 1e-9 m at the same stamps. Returns the two runs
    (multilift_tools.bagdata.load_run), ROS first."""
    import sys

    import numpy as np

    from multilift_tools.bagdata import load_run
    bags = folder / 'ros', folder / 'headless'
    run = multilift_run(str(scenario), bag=bags[0], startup_timeout=600)
    assert run.wait(timeout=1200) == 0, run.output()[-2000:]
    headless = subprocess.run([sys.executable, '-m', 'multilift_tools.cli', 'run', str(scenario),
                               '--headless', '--bag', str(bags[1])], capture_output=True,
                              text=True, timeout=1200)
    assert headless.returncode == 0, headless.stderr[-2000:]
    ros, flown = (load_run(bag) for bag in bags)
    assert np.array_equal(ros.t, flown.t)
    assert np.abs(ros.uav_positions() - flown.uav_positions()).max() < 1e-9
    assert np.abs(ros.payload_position() - flown.payload_position()).max() < 1e-9
    return ros, flown


# -- waiting for conditions (tests never wait a fixed time) ----------------------------------------
def wait_for(condition: Callable[[], T], timeout: float, what: str, poll: float = 0.1) -> T:
    """Poll `condition()` until it returns something truthy and return that; after `timeout`
    wall seconds (generous: the machine may be loaded) fail naming `what`."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f'{what}: not within {timeout:g} s')
        time.sleep(poll)


def run_work_dir(process: subprocess.Popen, timeout: float = 60.0) -> Path:
    """The log directory `scripts/multilift run` (started with stdout=PIPE, text=True) names
    in its first line ("... logs in DIR"); the run's progress file is DIR/progress."""
    ready, _, _ = select.select([process.stdout], [], [], timeout)
    assert ready, f'`multilift run` printed nothing within {timeout:g} s'
    line = process.stdout.readline()
    match = re.search(r'logs in (\S+)', line)
    assert match, f'unexpected first line of `multilift run`: {line!r} (exit {process.poll()})'
    return Path(match.group(1))


def simulated_time(work: Path) -> float:
    """Simulated time [s] the simulator of a `multilift run` reached (its progress file), 0.0
    before the first tick."""
    try:
        return float((work / 'progress').read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return 0.0


def wait_until_simulated(process: subprocess.Popen, t: float, timeout: float = 120.0) -> float:
    """Wait until a `multilift run` (stdout=PIPE, text=True) simulated `t` seconds; fail if it
    exits first. Returns the simulated time reached."""
    work = run_work_dir(process)

    def reached() -> float:
        assert process.poll() is None, f'the run exited ({process.returncode}) before t = {t} s'
        now = simulated_time(work)
        return now if now >= t else 0.0
    return wait_for(reached, timeout, f'the run reaching t = {t} s simulated')


@contextlib.contextmanager
def started_run(args: list[str], env: dict) -> Iterator[tuple[subprocess.Popen, Path]]:
    """`scripts/multilift run ARGS` (stdout and stderr piped, text) and its log directory, once
    it simulated past t = 0.1 s; killed with its process group if the body leaves it running."""
    run = subprocess.Popen([str(ROOT / 'scripts' / 'multilift'), 'run', *args], env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True)
    try:
        work = run_work_dir(run)
        wait_for(lambda: simulated_time(work) > 0.1, 120, 'the run started')
        yield run, work
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
            run.wait(timeout=30)


def collide_scenario(on_contact: str) -> dict:
    """A scenario's mapping built to collide (issue 34, tests of contact): cf2_payload flown
    straight along x through a pillar (a cylinder 0.1 m thick) 1 m ahead of the leader, with
    `world.on_contact` as given."""
    import copy

    import yaml
    base = Path(__file__).resolve().parents[1] / 'scenarios' / 'cf2_payload.yaml'
    data = copy.deepcopy(yaml.safe_load(base.read_text()))
    data['name'] = f'collide_{on_contact}'
    data['simulation']['duration'] = 6.0
    data['vehicle']['radius'] = 0.06
    data['payload']['radius'] = 0.02
    data['mission']['waypoints'] = [data['mission']['waypoints'][0],
                                    {'time': 4.0, 'position': [1.8, 0.0, 1.0417424305044158]}]
    data['world'] = {'ground': 0.0, 'on_contact': on_contact, 'obstacles': [
        {'name': 'pillar', 'type': 'cylinder', 'center': [1.0, 0.0, 1.0], 'radius': 0.1,
         'height': 2.0}]}
    return data
