"""The run supervisor (multilift_tools.launcher) with plain Python children standing in for the
nodes: the order it stops them in, what it reports, and the warnings it passes on."""
from __future__ import annotations

import signal
import sys

from multilift_tools.launcher import Child, Supervisor

WAIT_FOR_SIGINT = '''
import signal, sys, time
signal.signal(signal.SIGINT, lambda *a: sys.exit(0))
print('warning: probe: a line to pass on', flush=True)
time.sleep(60)
'''
DEAF = '''
import signal, time
signal.signal(signal.SIGINT, signal.SIG_IGN)
signal.signal(signal.SIGTERM, signal.SIG_IGN)
time.sleep(60)
'''


def _child(tmp_path, name: str, role: str, code: str) -> Child:
    return Child(name, [sys.executable, '-c', code], tmp_path / f'{name}.log', role)


def test_a_finished_simulator_stops_the_controllers_and_the_run_is_finished(tmp_path):
    sim = _child(tmp_path, 'sim_node', 'sim', 'import time; time.sleep(0.5)')
    controller = _child(tmp_path, 'leader_node', 'controller', WAIT_FOR_SIGINT)
    outcome, dead = Supervisor([sim, controller]).run()
    assert (outcome, dead) == ('finished', None)
    assert controller.returncode() == 0
    assert controller.warnings() == ['warning: probe: a line to pass on']
    assert sim.warnings() == []


def test_a_controller_deaf_to_sigint_and_sigterm_is_killed_and_named(tmp_path, monkeypatch):
    monkeypatch.setattr(Supervisor, 'stop', _quick_stop(Supervisor.stop))
    sim = _child(tmp_path, 'sim_node', 'sim', 'import time; time.sleep(0.5)')
    deaf = _child(tmp_path, 'follower_node (uav2)', 'controller', DEAF)
    outcome, dead = Supervisor([sim, deaf]).run()
    assert outcome == 'died' and dead is deaf
    assert deaf.returncode() == -signal.SIGKILL


def _quick_stop(stop):
    def quick(self, *roles, timeout=10.0):
        return stop(self, *roles, timeout=0.5)
    return quick


HANGS_IN_TEARDOWN = '''
import faulthandler, re, signal, sys, time
stopping = []
signal.signal(signal.SIGINT, lambda *a: stopping.append(1))
while not stopping:
    time.sleep(0.01)
%s
faulthandler.dump_traceback_later(0.3, exit=True)  # what TeardownGuard arms
re.match(r'(a+)+$', 'a' * 64 + 'b')                # a teardown that never returns, GIL held
'''


def test_a_teardown_cut_short_after_the_work_is_a_warning_not_a_death(tmp_path):
    sim = _child(tmp_path, 'sim_node', 'sim', 'import time; time.sleep(0.5)')
    controller = _child(tmp_path, 'leader_node', 'controller', HANGS_IN_TEARDOWN % '')
    outcome, dead = Supervisor([sim, controller]).run()
    assert (outcome, dead) == ('finished', None)
    assert controller.returncode() == 1 and controller.teardown_cut_short()
    assert controller.warnings() == [
        'warning: its teardown hung holding the GIL and was cut short by its watchdog after '
        'its messages were flushed (stacks in its log)']


def test_a_node_that_failed_stays_failed_whatever_its_teardown(tmp_path):
    sim = _child(tmp_path, 'sim_node', 'sim', 'import time; time.sleep(0.5)')
    failed = _child(tmp_path, 'leader_node', 'controller', HANGS_IN_TEARDOWN % (
        "print('error: no answer', file=sys.stderr, flush=True)"))
    outcome, dead = Supervisor([sim, failed]).run()
    assert outcome == 'died' and dead is failed and not failed.teardown_cut_short()
