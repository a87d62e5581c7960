"""Shared test fixtures: the repository paths, an isolated ROS environment, the two layers.

Tests live in two layers, each a folder and a marker (set here from the folder):
- `tests/unit/` (marker `unit`): no ROS graph and no node processes; physics, scenarios, message
  definitions, the bag format, plots of synthetic bags, the import architecture, lint. Fast.
- `tests/ros/` (marker `ros`): anything that starts nodes or talks to a ROS graph: runs of
  `scripts/multilift run`, the topic and bag tools against live publishers, the Foxglove bridge.
`scripts/test` runs both; `scripts/test --unit` (or `scripts/test tests/unit`) the fast layer.
"""
from __future__ import annotations

import itertools
import os
import re
import select
import subprocess
import time
from pathlib import Path
from typing import Callable, TypeVar

import pytest

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
SCENARIOS = ROOT / 'scenarios'
LAYERS = {'unit': 'no ROS graph, no node processes (tests/unit/)',
          'ros': 'starts nodes or talks to a ROS graph (tests/ros/)'}
T = TypeVar('T')
_domains = itertools.count(int(os.environ.get('ROS_DOMAIN_ID', '77')) % 50 + 20)


def pytest_configure(config) -> None:
    for name, what in LAYERS.items():
        config.addinivalue_line('markers', f'{name}: {what}')


def pytest_collection_modifyitems(config, items) -> None:
    """Mark every test with its layer, the folder it lives in (`-m unit`, `-m ros`)."""
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


@pytest.fixture
def ros_env(monkeypatch) -> dict:
    """An environment on a ROS domain of its own, discovery limited to this machine."""
    domain = str(next(_domains) % 100 + 1)
    monkeypatch.setenv('ROS_DOMAIN_ID', domain)
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return dict(os.environ)


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
