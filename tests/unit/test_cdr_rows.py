"""`pack_rows` (K messages of a packer's layout at once, numpy) against the packer's own
`pack` / `pack_row` of each message (struct, tests/unit/test_cdr.py holds those to rclpy): the
same bytes row by row, for every packer the headless bag writes in blocks, on random values
(negative, large and tiny floats, random flags, times across second boundaries)."""
from __future__ import annotations

import numpy as np
import pytest

from multilift_sim.wire import cdr, cdr_scene, msgvalues

K = 9


@pytest.fixture
def rng():
    return np.random.default_rng(31)


@pytest.fixture
def t_ns(rng):
    return np.sort(rng.integers(0, 400 * 10**9, K)) // 10 * 10


def _floats(rng, *shape):
    return rng.normal(size=shape) * 10.0 ** rng.integers(-12, 12, size=shape)


def _rows(packed: np.ndarray) -> list[bytes]:
    assert packed.dtype == np.uint8 and packed.shape[0] == K
    return [row.tobytes() for row in packed]


def test_stamps_are_stamp(t_ns):
    sec, nanosec = msgvalues.stamps(t_ns)
    assert list(zip(sec.tolist(), nanosec.tolist())) == [msgvalues.stamp(int(t)) for t in t_ns]


def test_clock_float64_and_stamped(rng, t_ns):
    clock, value = cdr.Clock(), cdr.Float64()
    assert _rows(clock.pack_rows(t_ns)) == [clock.pack(int(t)) for t in t_ns]
    values = _floats(rng, K)
    assert _rows(value.pack_rows(values)) == [value.pack(float(v)) for v in values]
    for packer, width in ((cdr.Vector3Stamped(), 3), (cdr.AttitudeSetpoint('uav2/base_link'), 4),
                          (cdr.TrackingReference(), 9)):
        values = _floats(rng, K, width)
        assert _rows(packer.pack_rows(t_ns, values)) == \
            [packer.pack(int(t), *v) for t, v in zip(t_ns, values.tolist())]


@pytest.mark.parametrize('covariance', [False, True])
def test_odometry(rng, t_ns, covariance):
    packer = cdr.Odometry('uav3/base_link', covariance=covariance)
    rows = _floats(rng, K, 85 if covariance else 13)
    assert _rows(packer.pack_rows(t_ns, rows)) == \
        [packer.pack_row(int(t), row) for t, row in zip(t_ns, rows.tolist())]


@pytest.mark.parametrize('n', [1, 2, 5])
def test_formation_state_errors_and_rotor_commands(rng, t_ns, n):
    state = cdr.formation_state(n)
    tension, g, g_dot = (_floats(rng, K, n) for _ in range(3))
    taut = rng.random((K, n)) < 0.5
    assert _rows(state.pack_rows(t_ns, tension, g, g_dot, taut)) == [
        state.pack(int(t), *(a.tolist() for a in values))
        for t, *values in zip(t_ns, tension, g, g_dot, taut)]
    errors = cdr.virtual_constraint_error(n + 1)
    error, rate = _floats(rng, K, n + 1), _floats(rng, K, n + 1)
    assert _rows(errors.pack_rows(t_ns, error, rate)) == [
        errors.pack(int(t), e.tolist(), r.tolist()) for t, e, r in zip(t_ns, error, rate)]
    command = cdr.RotorCommand(2 * n + 2, 'uav1/base_link')
    speeds, saturated = _floats(rng, K, 2 * n + 2), rng.random((K, 2 * n + 2)) < 0.3
    assert _rows(command.pack_rows(t_ns, speeds, saturated)) == [
        command.pack(int(t), s.tolist(), f.tolist()) for t, s, f in zip(t_ns, speeds, saturated)]


@pytest.mark.parametrize('counts', [[4], [4, 6], [6, 4, 4]])
def test_formation_snapshot(rng, t_ns, counts):
    packer, n = cdr.FormationSnapshot(counts), len(counts)
    for previous in (0, sum(counts)):
        rows = _floats(rng, K, 12 * n + 6 + previous)
        assert _rows(packer.pack_rows(t_ns, rows, previous)) == \
            [packer.pack_row(int(t), row, previous) for t, row in zip(t_ns, rows.tolist())]
    with pytest.raises(ValueError, match='rotor speeds'):
        packer.pack_rows(t_ns, rows[:, 1:], sum(counts))


def test_tf_message_with_attach_points(rng, t_ns):
    children = ['uav1/base_link', 'uav2/base_link', 'payload', 'payload/attach1']
    packer = cdr_scene.TFMessage(children, parents=['world'] * 3 + ['payload'])
    translations, rotations = _floats(rng, K, 4, 3), _floats(rng, K, 4, 4)
    assert _rows(packer.pack_rows(t_ns, translations, rotations)) == [
        packer.pack(int(t), a.tolist(), b.tolist())
        for t, a, b in zip(t_ns, translations, rotations)]
