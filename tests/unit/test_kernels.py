"""The physics (multilift_sim.physics), compiled by numba, against its own source run by Python
(`kernels.uncompiled`): the solve, an RK4 control period through a gust, and the slack path
with a cable snapping taut within the step give the same bits. MULTILIFT_KERNEL=python runs
the uncompiled functions, to the same bits; the array slots tile their rows."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.physics import layout
from multilift_sim.simulation import FormationSimulator
from multilift_sim.slack import SlackCableModel

numba = pytest.importorskip('numba')

from multilift_sim.physics.formation_dae import integrate_period, solve  # noqa: E402
from multilift_sim.physics.slack_cables import integrate_period as slack_period  # noqa: E402


def _swinging(name: str, ticks: int = 5):
    """A simulator of scenario `name` after `ticks` ticks of uneven hover (swinging, tilted),
    its payload and UAVs then moved into the first gust's centre (drag through a gust)."""
    simulator = FormationSimulator(scenario_io.load(name))
    hover = [np.array([1500.0, 1490.0, 1500.0, 1510.0]) for _ in simulator.scenario.uavs]
    idle = [np.zeros(u.vehicle.n_rotors, bool) for u in simulator.scenario.uavs]
    for _ in range(ticks):
        simulator.advance(hover, idle)
    state = simulator.state.copy()
    if simulator.scenario.gusts:
        layout = simulator.model.layout
        shift = np.r_[np.asarray(simulator.scenario.gusts[0].center)
                      - layout.payload_position(state)[:2], 0.0]
        layout.uav_positions(state)[:] += shift
        layout.payload_position(state)[:] += shift
    rng = np.random.default_rng(3)
    speeds = [1500.0 + 20.0 * rng.standard_normal(u.vehicle.n_rotors)
              for u in simulator.scenario.uavs]
    return simulator, state, simulator.model.wrenches(speeds)


def _constants(model):
    return model._uavs, model._gusts, model._formation


@pytest.mark.parametrize('name', ['twin_lift', 'circle3', 'v5'])
def test_the_solve_compiled_is_its_source_bit_for_bit(name):
    simulator, x, wrenches = _swinging(name)
    model, n = simulator.model, simulator.n
    for taut in (np.ones(n, bool), np.arange(n) % 2 == 0):  # every cable, then some slack
        results = []
        for function in (solve, kernels.uncompiled(solve)):
            acc, multipliers = np.empty(x.size - model.layout.n_coordinates), np.empty(n)
            function(x, wrenches, *_constants(model), taut, acc, multipliers,
                     np.empty((n, layout.CABLE_COLUMNS)))
            results.append((acc, multipliers))
        (acc, multipliers), (acc_python, multipliers_python) = results
        assert np.array_equal(acc, acc_python) and np.array_equal(multipliers,
                                                                  multipliers_python)
        assert np.all(multipliers[~taut] == 0.0) and np.all(multipliers[taut] != 0.0)
        assert model._gusts.shape[0] == 0 or np.any(acc != 0.0)


@pytest.mark.parametrize('name', ['twin_lift', 'circle3', 'v5'])
def test_a_control_period_compiled_is_its_source_bit_for_bit(name, monkeypatch):
    simulator, x, wrenches = _swinging(name)
    model, taut = simulator.model, np.ones(simulator.n, bool)
    compiled = integrate_period(x, wrenches, *_constants(model), taut, simulator.dt, 10)
    python = kernels.uncompiled(integrate_period)(x, wrenches, *_constants(model), taut,
                                                  simulator.dt, 10)
    for a, b in zip(compiled, python):
        assert np.array_equal(a, b)
    assert np.any(compiled[0] != x)  # it moved
    # the model's own choice, MULTILIFT_KERNEL when it is made: the same bits either way
    speeds = [np.full(u.vehicle.n_rotors, 1520.0) for u in simulator.scenario.uavs]
    periods = {}
    for mode in ('jit', 'python'):
        monkeypatch.setenv('MULTILIFT_KERNEL', mode)
        assert kernels.enabled() == (mode == 'jit')
        made = type(model)(model.params)
        periods[mode] = made.integrate(x, speeds, simulator.dt, 3)
        # read once, when made: a later change of the variable does not reach it
        monkeypatch.setenv('MULTILIFT_KERNEL', 'jit' if mode == 'python' else 'python')
        made.integrate(x, speeds, simulator.dt, 1)
        compiled = isinstance(made._physics()['solve'], numba.core.dispatcher.Dispatcher)
        assert compiled == (mode == 'jit')
    for field in ('state', 'cable_tension', 'constraint', 'constraint_rate'):
        assert np.array_equal(getattr(periods['jit'], field), getattr(periods['python'], field))


def _snapping_in_free_space():
    """A slack single lift, no gravity, rotors off: UAV and payload fly apart and the cable
    reaches its length 0.4 ms into a 1 ms step. (model, state, wrenches, the snap time)"""
    scenario = scenario_io.load('single_lift_swing')
    model = SlackCableModel(dataclasses.replace(scenario.formation_params(), gravity=0.0))
    length = model.cable_lengths[0]
    r_uav, v_uav = np.array([0.2, -0.1, 3.0]), np.array([-0.4, 0.3, 0.1])
    d0, w0 = np.array([0.3, -0.2, -0.5]), np.array([2.4, 0.4, -1.6])
    a, b, c = w0 @ w0, 2.0 * d0 @ w0, d0 @ d0 - length ** 2   # |d0 + w0 t| = l
    t_snap = (-b + np.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)
    start = t_snap - 4e-4                                       # free flight to there
    x = model.layout.pack([r_uav + v_uav * start], [np.zeros(3)],
                          r_uav + d0 + (v_uav + w0) * start, [v_uav], None, v_uav + w0)
    return model, x, model.wrenches([np.zeros(4)]), 4e-4


def test_the_slack_path_with_a_snap_in_the_step_compiled_is_its_source_bit_for_bit(
        monkeypatch):
    model, x, wrenches, t_snap = _snapping_in_free_space()
    results = []
    for function in (slack_period, kernels.uncompiled(slack_period)):
        taut = np.zeros(1, bool)
        results.append((function(x, wrenches, *_constants(model), taut, np.zeros(1, bool),
                                 1e-3, 2), taut))
    (compiled, taut), (python, taut_python) = results
    for a, b in zip(compiled, python):
        assert np.array_equal(a, b)
    assert taut[0] and taut_python[0]  # it snapped taut
    state, _, g, g_dot = compiled
    # on its length (the event located, the positions projected), not separating
    assert abs(g[0]) < 1e-12 * model.cable_lengths[0] ** 2 and abs(g_dot[0]) < 1e-9
    # a model made under MULTILIFT_KERNEL=python: the same bits
    monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
    python_model = type(model)(model.params)
    python_model.taut = False
    assert np.array_equal(python_model.integrate(x, [np.zeros(4)], 1e-3, 2).state, state)


def test_uncompiled_runs_the_same_source_in_python_all_the_way_down():
    """kernels.uncompiled: the reference is the compiled function's own source run by Python,
    and so are the compiled functions it calls, across modules (no compiled code underneath
    it); kernels.runnable picks by MULTILIFT_KERNEL."""
    reference = kernels.uncompiled(slack_period)
    assert reference.__code__ is slack_period.py_func.__code__
    step = reference.__globals__['slack_step']
    rk4 = step.__globals__['rk4_step']
    inner = rk4.__globals__['solve']
    assert inner.__code__ is solve.py_func.__code__
    for function in (step, rk4, inner, inner.__globals__['cable_multipliers']):
        assert not isinstance(function, numba.core.dispatcher.Dispatcher)
    # the modules' own functions are untouched
    assert isinstance(solve, numba.core.dispatcher.Dispatcher)


def test_runnable_follows_the_kernel_variable(monkeypatch):
    monkeypatch.setenv('MULTILIFT_KERNEL', 'jit')
    assert kernels.runnable(solve) is solve
    monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
    python = kernels.runnable(solve)
    assert python.__code__ is solve.py_func.__code__
    assert not isinstance(python, numba.core.dispatcher.Dispatcher)


@pytest.mark.parametrize('prefix, columns, widths', [
    ('UAV_', 'UAV_COLUMNS', {'UAV_INV_INERTIA': 3, 'UAV_GYRO': 3, 'UAV_PAYLOAD_ATTACH': 3,
                             'UAV_ATTACH': 3}),
    ('GUST_', 'GUST_COLUMNS', {'GUST_CENTER': 2, 'GUST_DIRECTION': 3}),
    ('BODY_', 'BODY_ATTITUDE', {'BODY_QUATERNION': 4, 'BODY_RATES': 3}),
    ('FORMATION_', 'FORMATION_SCALARS', {'FORMATION_WIND': 3, 'FORMATION_PAYLOAD_INERTIA': 3}),
    ('ACTUATOR_', 'ACTUATOR_COLUMNS', {}),
    ('EVENT_', 'EVENT_COLUMNS', {'EVENT_VELOCITY': 3}),
    ('CABLE_', 'CABLE_COLUMNS', {'CABLE_OFFSET': 3, 'CABLE_THRUST': 3, 'CABLE_MOMENT': 3,
                                 'CABLE_PAYLOAD_MOMENT': 3}),
    ('WRENCH_', 'WRENCH_COLUMNS', {'WRENCH_TORQUE': 3}),
    ('WORK_', 'WORK_ROWS', {}),
])
def test_layout_slots_tile_their_rows(prefix, columns, widths):
    """Every slot of a row is named once: the named slots (with their widths) cover
    0 .. columns - 1 without overlap."""
    names = [name for name in vars(layout) if name.startswith(prefix) and name != columns
             and name != 'UAV_COORDINATES' and isinstance(getattr(layout, name), int)]
    covered = sorted(getattr(layout, name) + k for name in names
                     for k in range(widths.get(name, 1)))
    assert covered == list(range(getattr(layout, columns)))


def test_the_state_layout_is_the_slots():
    from multilift_sim.formation_params import StateLayout
    state = StateLayout(3)
    x = np.arange(state.size, dtype=float)
    assert state.n_coordinates == layout.n_coordinates(3) == 12
    assert state.size == layout.attitude_slot(3) == 24 + 21
    assert state.payload_position(x)[0] == layout.payload_slot(3) == 9
    assert state.uav_positions(x)[2, 0] == layout.uav_slot(2) == 6
    assert state.uav_velocities(x)[1, 0] == 12 + layout.uav_slot(1) + layout.POSITION
    assert state.uav_quaternions(x)[2, 0] == layout.uav_attitude_slot(3, 2) == 24 + 14
    assert state.uav_body_rates(x)[0, 0] == 24 + layout.BODY_RATES
    rigid = StateLayout(3, rigid_payload=True)
    assert rigid.size == 45 + layout.BODY_ATTITUDE
    assert rigid.payload_quaternion(np.arange(rigid.size, dtype=float))[0] == 45


def test_cache_dir_is_under_the_users_cache_and_named_by_the_kernels_sources(tmp_path,
                                                                           monkeypatch):
    """numba's cache of these kernels: a folder named by a digest of every kernel package's
    sources, so an edited kernel (numba compiles callees into their callers, but checks a
    cached function against its own file only) never serves a caller's stale code."""
    import os
    import shutil
    from pathlib import Path

    directory = Path(os.environ['NUMBA_CACHE_DIR'])
    assert directory.parent.parts[-2:] == ('multilift', 'numba')
    assert directory.name == kernels._sources_digest()
    # another copy of the sources earlier on sys.path, with one law edited: another digest
    import sys
    first = next(Path(entry or '.') / 'multilift_control' for entry in sys.path
                 if (Path(entry or '.') / 'multilift_control' / '__init__.py').is_file())
    copy = tmp_path / 'multilift_control'
    shutil.copytree(first, copy)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert kernels._sources_digest() == directory.name  # the same sources
    (copy / 'laws' / 'mixer.py').write_text((copy / 'laws' / 'mixer.py').read_text() + '\n')
    assert kernels._sources_digest() != directory.name
