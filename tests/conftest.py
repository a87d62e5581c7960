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
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
SCENARIOS = ROOT / 'scenarios'
LAYERS = {'unit': 'no ROS graph, no node processes (tests/unit/)',
          'ros': 'starts nodes or talks to a ROS graph (tests/ros/)'}
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


@pytest.fixture
def ros_env(monkeypatch) -> dict:
    """An environment on a ROS domain of its own, discovery limited to this machine."""
    domain = str(next(_domains) % 100 + 1)
    monkeypatch.setenv('ROS_DOMAIN_ID', domain)
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return dict(os.environ)
