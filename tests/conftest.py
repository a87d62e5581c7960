"""Shared test fixtures: the repository paths and an isolated ROS environment."""
from __future__ import annotations

import itertools
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / 'scenarios'
_domains = itertools.count(int(os.environ.get('ROS_DOMAIN_ID', '77')) % 50 + 20)


@pytest.fixture
def ros_env(monkeypatch) -> dict:
    """An environment on a ROS domain of its own, discovery limited to this machine."""
    domain = str(next(_domains) % 100 + 1)
    monkeypatch.setenv('ROS_DOMAIN_ID', domain)
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return dict(os.environ)
