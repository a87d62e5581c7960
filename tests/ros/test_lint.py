"""Lint as part of the tests (as ros2/examples ship flake8 tests): pyflakes and pycodestyle
over the packages, tests and benchmarks, line length 100 (.flake8)."""
from __future__ import annotations

import subprocess
import sys

from conftest import ROOT


def test_flake8_is_clean():
    out = subprocess.run([sys.executable, '-m', 'flake8', 'ros_ws/src', 'tests', 'benchmarks'],
                         cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
