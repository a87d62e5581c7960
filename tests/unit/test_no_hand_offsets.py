"""The formation state's offsets are named once (issue 31, "each fact once"): numpy code reads
x through `formation_params.StateLayout`'s views, the compiled functions through
`physics.state_slots` (physics.layout's own functions, compiled). A hand-written offset into
the state or its rows (`6 * n`, `12 * n + 3`, `reshape(n, 6)`, `UAV_COORDINATES * i`, ...)
anywhere else under ros_ws/src fails here, naming the file and line."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from multilift_sim.formation_params import StateLayout
from multilift_sim.physics import layout, state_slots

SOURCES = Path(__file__).resolve().parents[2] / 'ros_ws' / 'src'

# the modules that name the offsets (and one with a state of its own)
ALLOWED = {
    'multilift_sim/multilift_sim/physics/layout.py',        # the slots' one table
    'multilift_sim/multilift_sim/physics/state_slots.py',   # its functions, compiled
    'multilift_sim/multilift_sim/formation_params.py',      # StateLayout, the numpy views
    # the seed's reduced single-lift model: its own 8 coordinates (N_COORDINATES), not x
    'multilift_sim/multilift_sim/analysis/reduced_model.py',
}

# (what it is, the pattern, a line it must catch)
HAND_OFFSETS = (
    ('a UAV block or q_f length by hand', r'(?<![\w.\-])(6|12)\s*\*\s*\(?\s*[A-Za-z_]',
     'payload = 6 * a.uavs.shape[1]'),
    ('a UAV block by hand', r'\b(n|i|n_uavs)\s*\*\s*6\b', 'x[n*6]'),
    ('the block size multiplied by hand (layout.uav_slot, payload_slot)',
     r'\bUAV_COORDINATES\s*\*', 'x[UAV_COORDINATES * i + EULER]'),
    ('q_f\'s length composed by hand (layout.n_coordinates)', r'\+\s*PAYLOAD_COORDINATES\b',
     'nq = p + PAYLOAD_COORDINATES'),
    ('the UAV blocks reshaped by hand (StateLayout.uav_coordinates)',
     r'reshape\([^)]*\b6\s*\)', 'states[:, :p].reshape(count, n, 6)'),
    ('a rigid payload\'s attitude by hand (layout.attitude_slot)', r'\b2\s*\*\s*\(?\s*nq\b',
     'base = 2 * nq'),
    ('the rates\' payload by hand (StateLayout.payload_velocity)', r'\bnq\s*\+\s*6\b',
     'x[nq + 6 * n]'),
    ('an attitude block by hand (layout.uav_attitude_slot)',
     r'(?<![\w.\-])7\s*\*\s*\(?\s*[A-Za-z_]|\b(BODY|PAYLOAD)_ATTITUDE\s*\*',
     'base = bodies + 7 * i'),
)


def _hits() -> list[str]:
    found = []
    for path in sorted(SOURCES.rglob('*.py')):
        name = path.relative_to(SOURCES).as_posix()
        if name in ALLOWED or '/build/' in name or '/install/' in name:
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split('#', 1)[0]
            for what, pattern, _ in HAND_OFFSETS:
                if re.search(pattern, code):
                    found.append(f'{name}:{number}: {what}: {line.strip()}')
    return found


def test_each_pattern_catches_its_example():
    for what, pattern, example in HAND_OFFSETS:
        assert re.search(pattern, example), what
    assert not any(re.search(pattern, 'tolerance = 1e-6 * omega') for _, pattern, _ in
                   HAND_OFFSETS)


def test_no_hand_written_state_offset_under_ros_ws_src():
    hits = _hits()
    assert not hits, 'hand-written state offsets (use StateLayout or physics.state_slots):\n' \
        + '\n'.join(hits)


@pytest.mark.parametrize('n', [1, 3, 5])
def test_compiled_slots_are_the_layout_functions(n):
    assert state_slots.uav_slot(n - 1) == layout.uav_slot(n - 1)
    assert state_slots.payload_slot(n) == layout.payload_slot(n)
    assert state_slots.rates_slot(n) == layout.n_coordinates(n)
    assert state_slots.uav_attitude_slot(n, n - 1) == layout.uav_attitude_slot(n, n - 1)
    assert state_slots.attitude_slot(n) == layout.attitude_slot(n) == \
        layout.uav_attitude_slot(n, n) == 2 * layout.n_coordinates(n) + 7 * n


@pytest.mark.parametrize('rigid', [False, True])
def test_views_of_a_stack_are_the_views_of_each_state(rigid):
    views = StateLayout(3, rigid)
    stack = np.random.default_rng(7).normal(size=(4, 2, views.size))
    for name in ('coordinates', 'rates', 'uav_attitudes', 'uav_quaternions', 'uav_body_rates',
                 'uav_positions', 'payload_position', 'uav_velocities',
                 'payload_velocity') + (('payload_quaternion', 'payload_body_rates')
                                        if rigid else ()):
        view = getattr(views, name)
        for k in range(4):
            for j in range(2):
                np.testing.assert_array_equal(view(stack)[k, j], view(stack[k, j]))
    x = stack[0, 0].copy()
    views.uav_body_rates(x)[1] = (0.1, 0.2, 0.3)   # a view: writes reach x
    assert tuple(x[layout.uav_attitude_slot(3, 1) + layout.BODY_RATES:][:3]) == (0.1, 0.2, 0.3)
    angles = np.array([[0.1, -1.2, 3.0], [2.0, 0.4, -0.5], [-3.0, 1.5, 0.2]])
    views.set_uav_euler(stack, np.broadcast_to(angles, (4, 2, 3, 3)))  # stored as quaternions
    np.testing.assert_allclose(views.uav_euler(stack), np.broadcast_to(angles, (4, 2, 3, 3)),
                               rtol=0, atol=1e-12)
