"""A kernel asked for by two processes at once is compiled by one of them (scripts/setup leaves
the engine's and the learning calls' kernels to their first use, which parallel test workers
and a run's nodes may reach together): the second waits on the kernel's lock
(`multilift_sim.kernels`, `fcntl.flock` beside its cache index) and loads what the first
saved. Checked by numba's own compile events in each process, with the first one held inside
its compile until the second is seen blocked on the lock in /proc/locks."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from conftest import wait_for

pytest.importorskip('numba')

KERNEL = '''
from multilift_sim.kernels import jit


@jit
def weighted_sum(values, weight):
    total = 0.0
    for value in values:
        total += weight * value
    return total
'''

# a process that calls the kernel and prints how many times numba compiled it here; with GATE
# set, its compile waits (inside numba's compile, the kernel's lock held) for that file
CALLER = '''
import os, sys, time
sys.path.insert(0, sys.argv[1])
from multilift_sim import kernels  # numba's cache folder set before numba reads it
import numpy as np
from numba.core import event
compiled = []


class Listener(event.Listener):
    def on_start(self, ev):
        if ev.data['dispatcher'].py_func.__name__ != 'weighted_sum':
            return
        compiled.append(1)
        gate = os.environ.get('GATE')
        if gate:
            open(gate + '.compiling', 'w').close()
            while not os.path.exists(gate):
                time.sleep(0.02)

    def on_end(self, ev):
        pass


event.register('numba:compile', Listener())
from toy_kernel import weighted_sum
assert weighted_sum(np.arange(4.0), 2.0) == 12.0
print('compiled', len(compiled))
'''


def _blocked_on_a_lock(pid: int) -> bool:
    """Whether process `pid` waits for a file lock (a '->' line of /proc/locks)."""
    return any(line.split()[1] == '->' and line.split()[5] == str(pid)
               for line in Path('/proc/locks').read_text().splitlines()
               if len(line.split()) > 5)


def test_a_kernel_two_processes_ask_for_at_once_is_compiled_once(tmp_path):
    (tmp_path / 'toy_kernel.py').write_text(KERNEL)
    (tmp_path / 'caller.py').write_text(textwrap.dedent(CALLER))
    gate = tmp_path / 'gate'
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / 'cache'), MULTILIFT_KERNEL='jit')
    command = [sys.executable, str(tmp_path / 'caller.py'), str(tmp_path)]
    first = subprocess.Popen(command, env=dict(env, GATE=str(gate)), stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
    second = None
    try:
        wait_for(lambda: (tmp_path / 'gate.compiling').exists() or first.poll() is not None,
                 120, 'the first process to start compiling')
        assert first.poll() is None, first.communicate()[0]
        second = subprocess.Popen(command, env=env, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, text=True)
        # without the lock the second would compile the kernel itself and exit meanwhile
        wait_for(lambda: _blocked_on_a_lock(second.pid) or second.poll() is not None, 120,
                 'the second process to wait for the kernel\'s lock')
        assert second.poll() is None, second.communicate()[0]
        gate.touch()  # the first compiles, saves and lets the lock go
        first_out, _ = first.communicate(timeout=120)
        second_out, _ = second.communicate(timeout=120)
    finally:
        gate.touch()
        for process in (first, second):
            if process is not None and process.poll() is None:
                process.kill()
    assert first.returncode == 0 and 'compiled 1' in first_out, first_out
    assert second.returncode == 0 and 'compiled 0' in second_out, second_out  # loaded
