"""The compiled float kernel (multilift_sim.kernels, numba) against the pure-Python float kernel
of FormationModel, the reference: a control period from a swinging, tilted state through the
gusts gives the same numbers (bit for bit here; 1e-12 is what the test demands), and
MULTILIFT_KERNEL=python switches the compiled one off. Compiled ahead of time (scripts/setup)
and just in time, the kernel and the control laws give the same bits; the ahead-of-time build
loads without numba and refuses arguments of the wrong type."""
from __future__ import annotations

import json

import numpy as np
import pytest

from multilift_control.cascade import COMPILED_LAWS
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


AHEAD_OF_TIME = (kernels.PHYSICS, COMPILED_LAWS)


@pytest.mark.parametrize('name', ['twin_lift', 'circle3', 'v5'])
def test_ahead_of_time_equals_just_in_time_bit_for_bit(name, monkeypatch):
    """The physics over a control period, and a headless run (physics and control laws)."""
    from multilift_control.headless import run_headless
    import dataclasses
    simulator = _swinging(name, ticks=5)
    speeds = [np.full(u.vehicle.n_rotors, 1520.0) for u in simulator.scenario.uavs]
    scenario = simulator.scenario
    short = dataclasses.replace(scenario, simulation=dataclasses.replace(
        scenario.simulation, duration=3.0))
    results = {}
    for mode in ('aot', 'jit'):
        monkeypatch.setenv('MULTILIFT_KERNEL', mode)
        assert kernels.enabled()
        period = simulator.model.integrate(simulator.state, speeds, simulator.dt, 10)
        run = run_headless(short)
        summary = run.summary()
        summary['sim'].pop('wall_time', None)
        results[mode] = (period.state, period.cable_tension, run.simulator.state,
                         json.dumps(summary, sort_keys=True, default=str))
    aot, jit = results['aot'], results['jit']
    for a, b in zip(aot[:3], jit[:3]):
        assert np.array_equal(a, b)
    assert aot[3] == jit[3]
    assert np.any(results['aot'][2] != simulator.state)  # the run moved


def test_an_argument_of_the_wrong_type_is_a_type_error_not_a_crash():
    compiled = kernels.load_ahead_of_time(kernels.PHYSICS)
    assert compiled is not None
    simulator = FormationSimulator(scenario_io.load('twin_lift'))
    constants = kernels.model_constants(simulator.model)
    x = np.ascontiguousarray(simulator.state, dtype=np.float64)
    wrenches = np.zeros((2, 6))
    state, *_ = compiled.integrate_period(*constants, x, wrenches, 0.001, 2)
    assert state.shape == x.shape and np.all(np.isfinite(state))
    wide = np.repeat(x, 2)
    for bad, words in ((x.astype(np.float32), 'float32'), (wide[::2], 'strided'),
                       (x.tolist(), 'list')):
        with pytest.raises(TypeError, match=f'argument 9 must be a C-contiguous 1-d float64 '
                                            f'array, got .*{words}'):
            compiled.integrate_period(*constants, bad, wrenches, 0.001, 2)
    # the laws write their memory: a read-only one is refused
    laws = kernels.load_ahead_of_time(COMPILED_LAWS)
    frozen = np.zeros(4)
    frozen.flags.writeable = False
    with pytest.raises(TypeError, match='argument 3 must be a C-contiguous writable 1-d '
                                        'float64 array, got a C-contiguous read-only'):
        laws.cascade_update(np.zeros(24), np.zeros((4, 4)), np.zeros(4), frozen, 0.0,
                            *[np.zeros(3)] * 7, 0.0)


def test_the_ahead_of_time_build_is_named_by_its_source(tmp_path, monkeypatch):
    """A changed source is never served the old build: the files' names hash the source."""
    module = tmp_path / 'aot_naming_probe.py'
    module.write_text('A = 1\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    first = kernels.ahead_of_time_files('aot_naming_probe')
    assert first == kernels.ahead_of_time_files('aot_naming_probe')
    module.write_text('A = 2\n')
    second = kernels.ahead_of_time_files('aot_naming_probe')
    assert first[0] != second[0] and first[1] != second[1]
    assert first[0].parent == kernels.AHEAD_OF_TIME_DIR


def test_uncompiled_runs_the_same_source_in_python_all_the_way_down():
    """kernels.uncompiled: the reference is the compiled function's own source run by Python,
    and so are the compiled functions it calls (no compiled code underneath it)."""
    import numba

    from multilift_sim import _numba_kernel
    reference = kernels.uncompiled(_numba_kernel.integrate_period)
    assert not hasattr(reference, 'py_func')
    assert reference.__code__ is _numba_kernel.integrate_period.py_func.__code__
    solve = reference.__globals__['solve']
    assert solve.__code__ is _numba_kernel.solve.py_func.__code__
    assert not isinstance(solve, numba.core.dispatcher.Dispatcher)
    assert not isinstance(solve.__globals__['force_per_mass'], numba.core.dispatcher.Dispatcher)
    # the module's own functions are untouched
    assert isinstance(_numba_kernel.solve, numba.core.dispatcher.Dispatcher)
    simulator = _swinging('twin_lift', ticks=2)
    constants = kernels.model_constants(simulator.model)
    wrenches = simulator.model.wrenches([np.full(4, 1500.0)] * simulator.n)
    compiled = _numba_kernel.integrate_period(*constants, simulator.state, wrenches,
                                              simulator.dt, 3)
    python = reference(*constants, simulator.state, wrenches, simulator.dt, 3)
    for a, b in zip(compiled, python):
        assert np.array_equal(a, b)  # the same operations in the same order: the same bits
