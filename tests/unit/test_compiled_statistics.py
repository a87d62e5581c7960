"""The run statistics' compiled functions (multilift_sim.statistics.swing, .accumulators)
against their uncompiled run (`kernels.uncompiled`: the same source in Python): over
randomized inputs every function gives the same bits and leaves the same accumulators; the
swing's hypot is CPython's math.hypot bit for bit; the classes over the arrays keep their
figures (what the swing computes is tested in test_statistics.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from multilift_sim import kernels
from multilift_sim.formation_params import StateLayout
from multilift_sim.physics.layout import REEL_COLUMNS, UAV_COLUMNS
from multilift_sim.statistics import (FormationErrorStatistics, RunStatistics,
                                      TrackingStatistics, accumulators, figures, swing)
from multilift_sim.statistics.layout import (CHECK_QUATERNION, CHECK_G, CHECK_G_DOT,
                                             CHECK_NON_FINITE, CHECK_OK, PEAK_SIZE,
                                             QUATERNION_NORM_TOLERANCE, RUN_SWING, run_size)

pytest.importorskip('numba')


def _equal(a, b) -> bool:
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(map(_equal, a, b))
    if a is None or b is None:
        return a is b
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


def _both(function, *args):
    """(compiled result, its arrays after), (uncompiled result, its arrays after): each run
    on its own copies of the arrays."""
    runs = []
    for run in (function, kernels.uncompiled(function)):
        copies = tuple(a.copy() if isinstance(a, np.ndarray) else a for a in args)
        runs.append((run(*copies), copies))
    return runs


def _same(function, *args):
    (compiled, after_c), (python, after_p) = _both(function, *args)
    assert _equal(compiled, python), (function.__name__, compiled, python)
    for a, b in zip(after_c, after_p):
        if isinstance(a, np.ndarray):
            assert _equal(a, b), (function.__name__, a, b)
    return compiled


def _formation(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """UAVs (n, 3) [m] above a point and cables (n,) that reach it, some only just."""
    uavs = np.column_stack([rng.uniform(-2, 2, (n, 2)), rng.uniform(3, 5, n)])
    below = uavs.mean(axis=0) - [0.0, 0.0, rng.uniform(0.5, 2.0)]
    lengths = np.linalg.norm(uavs - below, axis=1) + rng.uniform(0.0, 0.3, n)
    return uavs, lengths


def test_hypot2_is_cpythons_math_hypot_bit_for_bit():
    rng = np.random.default_rng(0)
    values = rng.normal(size=(20000, 2)) * 10.0 ** rng.uniform(-12, 3, (20000, 2))
    special = [(0.0, 0.0), (-0.0, 2.0), (3.0, 4.0), (5e-324, 1e-323), (1e-310, 3e-311),
               (math.inf, math.nan), (math.nan, 1.0), (1e300, 1e300), (-math.inf, 1.0)]
    hypot2 = swing.hypot2
    for x, y in [tuple(v) for v in values.tolist()] + special:
        expected = math.hypot(x, y)
        assert _equal(hypot2(x, y), expected), (x, y)
    for x, y in special + [tuple(v) for v in values[:500].tolist()]:
        assert _equal(kernels.uncompiled(hypot2)(x, y), math.hypot(x, y)), (x, y)


@pytest.mark.parametrize('n', [1, 2, 3, 5, 10])
def test_the_swing_compiled_and_uncompiled_agree(n):
    rng = np.random.default_rng(n)
    for _ in range(40):
        uavs, lengths = _formation(rng, n)
        payload = uavs.mean(axis=0) + rng.normal(0.0, 0.3, 3)
        _same(swing.equilibrium_point, uavs, lengths)
        found = _same(swing.swing_at, uavs, payload, lengths)
        assert math.isfinite(found)
        # the payload right at its rest place: no swing
        rest = figures.equilibrium_payload_position(uavs, lengths)
        assert figures.payload_swing_at(uavs, rest, lengths) == 0.0
    # a strided view of a state, as run_check passes it
    state = rng.normal(size=6 * n + 3)
    state[:6 * n].reshape(n, 6)[:, :3] = uavs
    view = state[:6 * n].reshape(n, 6)[:, :3]
    assert _same(swing.swing_at, view, payload, lengths) == swing.swing_at(uavs, payload,
                                                                           lengths)


def test_cables_that_cannot_meet_give_nan_either_way():
    apart = np.array([(0.0, 0.0, 5.0), (10.0, 0.0, 5.0), (5.0, 8.0, 5.0)])
    for uavs in (apart[:2], apart):
        lengths = np.full(len(uavs), 2.0)
        assert all(map(math.isnan, _same(swing.equilibrium_point, uavs, lengths)))
        assert math.isnan(_same(swing.swing_at, uavs, np.zeros(3), lengths))
    assert figures.equilibrium_payload_position(apart, [2, 2, 2]) is None


def test_the_sphere_candidates_and_the_active_set_agree():
    rng = np.random.default_rng(7)
    for _ in range(300):
        c = rng.uniform(-2, 2, (3, 3))
        r = rng.uniform(0.5, 3.0, 3)
        _same(swing.sphere_pair_lowest, *c[0], r[0], *c[1], r[1])
        _same(swing.sphere_triple_lowest, *c[0], r[0], *c[1], r[1], *c[2], r[2])
    # a vertical axis and coincident centres
    _same(swing.sphere_pair_lowest, 0.0, 0.0, 1.0, 2.0, 0.0, 0.0, 2.0, 2.5)
    _same(swing.sphere_triple_lowest, 0.0, 0.0, 1.0, 2.0, 0.0, 0.0, 1.0, 2.0, 1.0, 0.0, 0.0, 2.0)
    uavs, lengths = _formation(rng, 8)
    members = np.array([0, 2, 3, 5, 7, 0, 0, 0], dtype=np.int64)
    _same(swing.lowest_in, uavs, lengths, members, 5)
    _same(swing.lowest_of_two, uavs[:2], lengths[:2])
    # a NaN cable: last into the working set, first out of the argmax
    lengths[3] = math.nan
    _same(swing.equilibrium_point, uavs, lengths)


def _accumulators(rng: np.random.Generator, n: int) -> np.ndarray:
    run = np.abs(rng.normal(size=run_size(n)))
    run[2], run[3] = math.inf, -math.inf   # RUN_MIN_TENSION, RUN_MAX_TENSION as at the start
    return run


@pytest.mark.parametrize('n', [1, 2, 3, 5, 10])
def test_the_accumulators_compiled_and_uncompiled_agree(n):
    rng = np.random.default_rng(100 + n)
    run = _accumulators(rng, n)
    for _ in range(20):
        _same(accumulators.run_add_commands, run, rng.uniform(-3000, 3000, (n, 4)),
              rng.random((n, 4)) < 0.2, 0.01)
        tension = rng.normal(3.0, 2.0, n)
        tension[rng.integers(n)] = rng.choice([math.nan, 5.0])
        _same(accumulators.run_add_tensions, run, tension)
        _same(accumulators.run_add_ropes, run, rng.normal(size=StateLayout(n).size),
              rng.uniform(0.5, 2.0, n), tension)
        _same(accumulators.run_add_chains, run,
              rng.normal(size=StateLayout(n, chain_nodes=4).size),
              rng.normal(size=(n, UAV_COLUMNS)), 4, rng.uniform(0.5, 2.0, n), tension)
        _same(accumulators.run_add_reel, run, rng.uniform(0.5, 2.0, (n, REEL_COLUMNS)),
              rng.uniform(0.5, 2.0, n))
        _same(accumulators.run_add_slack, run, rng.random(n) < 0.5, 0.01)
        _same(accumulators.run_add_gust_speed, run, float(rng.choice([math.nan, 0.3, 2.0])))
        _same(accumulators.peak_rms_add, run, RUN_SWING, float(rng.uniform(0, 2)))
    tracking = np.abs(rng.normal(size=PEAK_SIZE))
    formation = np.abs(rng.normal(size=3))
    for m in (0, 1, 3, 2 * n):
        _same(accumulators.tracking_add, tracking, rng.normal(size=3), rng.normal(size=3))
        _same(accumulators.formation_error_add, formation, rng.normal(size=m))


@pytest.mark.parametrize('n', [1, 2, 3, 5, 10])
def test_the_check_compiled_and_uncompiled_agree(n):
    rng = np.random.default_rng(200 + n)
    uavs, lengths = _formation(rng, n)
    layout = StateLayout(n)
    state = rng.normal(size=layout.size)
    layout.uav_positions(state)[:] = uavs
    layout.set_uav_euler(state, rng.normal(0.0, 0.3, (n, 3)))  # attitudes a UAV flies
    layout.payload_position(state)[:] = uavs.mean(axis=0) - [0.0, 0.0, 1.0]
    seen = set()
    for tick in range(160):
        run = _accumulators(rng, n)
        g = rng.normal(0.0, 2e-3 if tick % 2 else 1e-4, n)
        g_dot = rng.normal(0.0, 1e-2, n)
        taut = rng.random(n) < 0.8
        x = state.copy()
        tumbling = int(rng.integers(n))
        if tick % 7 == 6:
            x[rng.integers(len(x))] = rng.choice([math.nan, math.inf])
        elif tick % 11 == 10:  # a UAV's quaternion off unit length, either way
            layout.uav_quaternions(x)[tumbling] *= 1.0 + rng.choice([-1.0, 1.0]) * rng.uniform(
                2.0 * QUATERNION_NORM_TOLERANCE, 0.5)
        elif tick % 5 == 4:  # pitched through 90 deg and beyond: an attitude like any other
            layout.set_uav_euler(x, [[0.0, math.pi / 2.0 + 0.3, 0.1]] * n)
        status, cable = _same(accumulators.run_check, run, x, g, g_dot, taut, 2e-3, 2e-2,
                              tick * 0.01, tick, 1 if n <= 2 else 10, lengths)
        seen.add(status)
        if status in (CHECK_G, CHECK_G_DOT):
            values = np.abs(g if status == CHECK_G else g_dot) * taut
            assert cable == int(np.argmax(values))
        if tick % 11 == 10 and tick % 7 != 6:
            assert (status, cable) == (CHECK_QUATERNION, tumbling)
        elif tick % 5 == 4 and tick % 7 != 6:
            assert status != CHECK_QUATERNION
    assert seen == {CHECK_OK, CHECK_NON_FINITE, CHECK_QUATERNION, CHECK_G, CHECK_G_DOT}


def test_the_classes_read_their_arrays():
    stats = RunStatistics(2)
    stats.add_commands([1000.0, 2100.0], [np.zeros(4, bool), np.array([0, 1, 0, 0], bool)],
                       0.01)
    stats.add_commands(np.array([[1500.0, -1400.0, 0, 0], [900.0, 0, 0, 0]]),
                       [np.zeros(4, bool)] * 2, 0.01)
    stats.add_commands([np.full(6, 1600.0), np.full(4, 100.0)],        # rotor counts differ
                       [np.zeros(6, bool), np.array([0, 0, 0, 1], bool)], 0.01)
    stats.add_tensions(np.array([3.0, 1.5]))
    stats.add_tensions(np.array([4.0, 2.0]))
    stats.add_slack(np.array([True, False]), 0.01)
    stats.add_gust_speed(0.4)
    assert stats.max_rotor_speed == [1600.0, 2100.0]
    assert stats.saturated_time == [0.0, 0.01 + 0.01]
    assert stats.slack_time == [0.0, 0.01]
    assert stats.least_thrust_margin == [None, None]  # no allocation given: add_commands alone
    assert (stats.min_tension, stats.max_tension, stats.max_gust_speed) == (1.5, 4.0, 0.4)
    assert list(stats.as_dict()) == [
        'n_uavs', 'max_abs_constraint', 'max_abs_constraint_rate', 'max_rotor_speed',
        'saturated_time', 'least_thrust_margin', 'min_tension', 'max_tension', 'simulated_time',
        'max_gust_speed', 'slack_time', 'max_payload_swing', 'rms_payload_swing', 'swing_from',
        'compressed_time']
    tracking = TrackingStatistics()
    for error in (3.0, 4.0):
        tracking.add([error, 0.0, 0.0], [0.0, 0.0, 0.0])
    assert tracking.as_dict() == {'max_tracking_error': 4.0,
                                  'rms_tracking_error': math.sqrt(12.5),
                                  'answered_states': 2}
    formation = FormationErrorStatistics()
    formation.add(np.array([3.0, -4.0]))
    formation.add(np.zeros(0))
    assert formation.as_dict() == {'max_abs_formation_error': 4.0,
                                   'mean_formation_error_norm': 2.5, 'answered_states': 2}
