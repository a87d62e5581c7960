"""The layers of the tests (tests/conftest.py): the unit layer refuses processes."""
from __future__ import annotations

import multiprocessing
import os
import subprocess

import pytest

REFUSED = 'tests/unit starts no processes'


def test_a_process_started_in_the_unit_layer_fails_the_test():
    with pytest.raises(AssertionError, match=REFUSED):
        subprocess.run(['true'])
    with pytest.raises(AssertionError, match=REFUSED):
        os.fork()
    with pytest.raises(AssertionError, match=REFUSED):
        multiprocessing.get_context('spawn').Process(target=print).start()
