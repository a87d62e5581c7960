"""The compiled float kernel (multilift_sim.kernels, numba) against the pure-Python float kernel
of FormationModel, the reference: a control period from a swinging, tilted state through the
gusts gives the same numbers (bit for bit here; 1e-12 is what the test demands), and
MULTILIFT_KERNEL=python switches the compiled one off."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator

pytest.importorskip('numba')


def _swinging(name: str, ticks: int = 40):
    simulator = FormationSimulator(scenario_io.load(name))
    hover = [np.array([1500.0, 1490.0, 1500.0, 1510.0]) for _ in simulator.scenario.uavs]
    idle = [np.zeros(u.vehicle.n_rotors, bool) for u in simulator.scenario.uavs]
    for _ in range(ticks):
        simulator.advance(hover, idle)
    return simulator


@pytest.mark.parametrize('name', ['twin_lift', 'circle3', 'v5'])
def test_compiled_equals_pure(name, monkeypatch):
    simulator = _swinging(name, ticks=5)
    model = simulator.model
    assert model.uses_float_kernel
    rng = np.random.default_rng(3)
    speeds = [1500.0 + 20.0 * rng.standard_normal(u.vehicle.n_rotors)
              for u in simulator.scenario.uavs]
    # through a gust: the payload moved into the first gust's centre
    state = simulator.state.copy()
    if simulator.scenario.gusts:
        n = simulator.n
        shift = np.r_[np.asarray(simulator.scenario.gusts[0].center) - state[6 * n:6 * n + 2],
                      0.0]
        state[:6 * n].reshape(n, 6)[:, :3] += shift
        state[6 * n:6 * n + 3] += shift
    monkeypatch.setenv('MULTILIFT_KERNEL', 'auto')
    assert kernels.enabled()
    compiled = model.integrate(state, speeds, simulator.dt, 10)
    monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
    assert not kernels.enabled()
    pure = model.integrate(state, speeds, simulator.dt, 10)
    for field in ('state', 'cable_tension', 'constraint', 'constraint_rate'):
        a, b = getattr(compiled, field), getattr(pure, field)
        assert a.shape == b.shape
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12), field
    assert np.any(compiled.state != state)  # it moved


def test_cache_dir_is_writable_and_under_the_users_cache():
    import os
    from pathlib import Path
    directory = Path(os.environ['NUMBA_CACHE_DIR'])
    assert directory.parts[-2:] == ('multilift', 'numba')


def test_loading_the_kernel_leaves_scipy_and_coverage_unimported_and_importable():
    """numba's BLAS probe is kept from importing scipy and its coverage hook from importing
    coverage (start-up costs); both still import afterwards, and the kernel still
    integrates."""
    code = ('import sys, numpy as np\n'
            'from multilift_sim import kernels, scenario\n'
            'from multilift_sim.simulation import FormationSimulator\n'
            'assert kernels.enabled()\n'
            'sim = FormationSimulator(scenario.load("twin_lift"))\n'
            'sim.advance([np.full(4, 1500.0)] * 2, [np.zeros(4, bool)] * 2)\n'
            'print("scipy" in sys.modules, "coverage" in sys.modules)\n'
            'import scipy.linalg, coverage\n'
            'print(scipy.linalg.solve(np.eye(2), np.ones(2)).tolist(),\n'
            '      callable(coverage.Coverage))\n')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         timeout=120, env={**os.environ, 'MULTILIFT_KERNEL': 'auto'})
    assert out.returncode == 0, out.stderr
    assert out.stdout.split('\n')[:2] == ['False False', '[1.0, 1.0] True']
