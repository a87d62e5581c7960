"""What a new process does at start-up, and the command line's answers to bad input: the tests
that start a Python process or `scripts/multilift` (tests/unit starts none). Moved here from
the unit files of the code they test (kernels, compiled laws, architecture, scenario, plots)."""
from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
import yaml

from conftest import ROOT, SCENARIOS


# -- the kernels and the control laws in a new process (tests/unit/test_kernels.py,
# test_compiled_laws.py hold them equal in this one) ----------------------------------------------
def _a_tick_in_a_new_process(kernel: str, then: str) -> str:
    """A twin-lift tick in a new Python process (MULTILIFT_KERNEL=kernel), then the code
    `then` (sim, np, sys and kernels in scope): what it printed; the process must succeed."""
    code = ('import sys, numpy as np\n'
            'from multilift_sim import kernels, scenario\n'
            'from multilift_sim.simulation import FormationSimulator\n'
            'sim = FormationSimulator(scenario.load("twin_lift"))\n'
            'sim.advance([np.full(4, 1500.0)] * 2, [np.zeros(4, bool)] * 2)\n' + then)
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         timeout=120, env={**os.environ, 'MULTILIFT_KERNEL': kernel})
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_loading_the_kernel_leaves_scipy_and_coverage_unimported_and_importable():
    """Just in time: numba's BLAS probe is kept from importing scipy and its coverage hook
    from importing coverage (start-up costs); both still import afterwards, and the kernel
    still integrates."""
    out = _a_tick_in_a_new_process(
        'jit', 'assert kernels.enabled()\n'
               'print("scipy" in sys.modules, "coverage" in sys.modules)\n'
               'import scipy.linalg, coverage\n'
               'print(scipy.linalg.solve(np.eye(2), np.ones(2)).tolist(),\n'
               '      callable(coverage.Coverage))\n')
    assert out.split('\n')[:2] == ['False False', '[1.0, 1.0] True']


def test_setup_filled_numba_s_cache_so_a_new_process_loads_and_does_not_compile():
    """scripts/setup compiled the kernels into numba's on-disk cache (the supported way that
    replaced pycc: multilift_sim.kernels): a new process's tick (the simulator's
    physics.tick.advance) and engine step load them."""
    out = _a_tick_in_a_new_process(
        'auto', 'from multilift_control.engine import Engine\n'
                'from multilift_control.engine.tick import run_ticks\n'
                'law = kernels.compiled_module("multilift_sim.physics.tick").advance\n'
                'engine = Engine(scenario.load("twin_lift"))\n'
                'engine.step(3)\n'
                'print(kernels.enabled(), sim.t > 0, engine.memory.tick[0],\n'
                '      [len(f.stats.cache_hits) > 0 and not f.stats.cache_misses\n'
                '       for f in (law, run_ticks)])\n')
    assert out.split() == ['True', 'True', '3', '[True,', 'True]']


@pytest.mark.parametrize('setting,expected', [(None, 'auto just-in-time'),
                                              ('jit', 'jit just-in-time'),
                                              ('python', 'python uncompiled')])
def test_controller_nodes_load_the_compiled_laws_unless_told(setting, expected):
    """A controller node (`prepare_node_laws`) loads the compiled laws from numba's cache
    before it answers, unless MULTILIFT_KERNEL=python says to run them uncompiled."""
    code = ('import os, sys\n'
            'from multilift_control.runtime import ControllerRuntime, prepare_node_laws\n'
            'from multilift_sim import kernels, scenario\n'
            's = scenario.load("twin_lift")\n'
            'prepare_node_laws(s, 1)\n'
            'law = ControllerRuntime(s, 1).follower._answer\n'
            'kind = ("uncompiled" if not hasattr(law, "py_func") else\n'
            '        "just-in-time" if len(law.signatures) > 0 else "not loaded")\n'
            'print(kernels.mode(), kind)\n')
    env = {k: v for k, v in os.environ.items() if k != 'MULTILIFT_KERNEL'}
    if setting is not None:
        env['MULTILIFT_KERNEL'] = setting
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         timeout=300, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == expected.split()


# -- a headless run loads no ROS (tests/unit/test_architecture.py: the imports) ------------------
def test_a_headless_run_without_a_bag_loads_no_rclpy():
    code = ('import sys\n'
            'from multilift_tools.cli import main\n'
            "code = main(['run', 'single_lift_swing', '--headless', '--duration', '0.5'])\n"
            "loaded = sorted(m for m in sys.modules if m.split('.')[0] == 'rclpy' or "
            "m.split('.')[0].endswith('_msgs'))\n"
            "print('EXIT', code, 'LOADED', ','.join(loaded) or '-')\n")
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         timeout=300, cwd=ROOT)
    assert out.returncode == 0, out.stderr[-2000:]
    match = re.search(r'^EXIT (\S+) LOADED (\S+)$', out.stdout, re.MULTILINE)
    assert match, out.stdout[-2000:]
    assert match.groups() == ('0', '-'), f'headless run loaded {match.group(2)}'
    assert 'single_lift_swing: 0.5 s simulated' in out.stdout


# -- bad input on the command line ---------------------------------------------------------------
def test_missing_bag_from_the_command_line_has_no_traceback(tmp_path):
    code = ('import sys; from multilift_tools.figures import plot_main; '
            'sys.exit(plot_main(sys.argv[1:]))')
    done = subprocess.run([sys.executable, '-c', code, str(tmp_path / 'gone')],
                          capture_output=True, text=True, env=dict(os.environ), timeout=120)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [f'error: bag not found: {tmp_path / "gone"}']


def test_cli_bad_scenario_is_one_line_exit_2(tmp_path):
    bad = tmp_path / 'bad.yaml'
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['vehicle']['mass'] = -1.0
    bad.write_text(yaml.safe_dump(data))
    out = subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', str(bad)],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().splitlines() == [
        f'error: {bad}: vehicle.mass: -1.0 must be > 0']
    assert 'Traceback' not in out.stderr


def test_cli_unknown_scenario_lists_known():
    out = subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', 'no_such_thing'],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert 'unknown scenario' in out.stderr and 'single_lift' in out.stderr


@pytest.mark.parametrize('duration', ['0.001', '0', '-1', 'nan'])
def test_cli_duration_shorter_than_a_control_period_is_one_line_exit_2(duration):
    out = subprocess.run([str(ROOT / 'scripts' / 'multilift'), 'run', 'single_lift',
                          '--headless', '--duration', duration],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().splitlines() == [
        f'error: --duration: {float(duration)!r} must be at least one control period '
        '(1/control_rate = 0.01 s)']
