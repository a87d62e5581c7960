"""`multilift modal`'s text: no 'largest' of an empty set of near-zero modes, and the cables'
vertical drop and each swing's effective length g/omega^2, which say why a held box swings at
2.94 s and not at 2 pi sqrt(l/g) (modal_cli.rigid_line, cable_drops, suspension_lines)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.modal import scenario_modal_analysis
from multilift_tools.modal_cli import cable_drops, modal_report, rigid_line


@pytest.fixture(scope='module')
def held_box():
    return scenario_modal_analysis(scenario_io.load('box_lift'), hold_uavs=True)


def test_no_near_zero_modes_is_said_without_a_largest(held_box):
    assert held_box.rigid_count == 0
    line = rigid_line(held_box)
    assert 'none' in line and 'largest' not in line
    report = modal_report(held_box, 'box_lift')
    assert 'largest 0.0e+00' not in report


def test_near_zero_modes_still_name_their_largest():
    analysis = scenario_modal_analysis(scenario_io.load('twin_lift'))
    assert analysis.rigid_count > 0
    assert 'largest' in rigid_line(analysis) and f'{analysis.rigid_count} eigenvalues' in \
        rigid_line(analysis)


def test_the_held_box_hangs_by_its_cables_vertical_drop(held_box):
    drops = cable_drops(held_box)
    # independently: each corner b_i (level box at rest) under its UAV's centre
    scenario = scenario_io.load('box_lift')
    lengths = np.array([u.cable_length for u in scenario.uavs])
    assert np.all(drops < lengths - 0.1) and np.allclose(drops, drops[0], rtol=0, atol=1e-9)
    x = held_box.equilibrium.state
    from multilift_sim.formation_params import StateLayout
    layout = StateLayout(4, True)
    horizontal = (layout.uav_positions(x)[:, :2] - layout.payload_position(x)[:2]
                  - np.array(scenario.payload.attach_points)[:, :2])
    assert np.allclose(np.hypot(*horizontal.T) ** 2 + drops ** 2, lengths ** 2, rtol=1e-9)
    report = modal_report(held_box, 'box_lift')
    g = 9.81
    for k in held_box.pendulum_modes:
        assert f'{g / held_box.eigenvalues[k].imag ** 2:.3f}' in report
    assert f'{2 * math.pi * math.sqrt(drops[0] / g):.4f} s' in report
    assert 'splay out from the body' in report


def test_a_swing_across_parallel_cables_is_a_pendulum_of_the_vertical_drop():
    """The held beam across its cables' plane: g/omega^2 = h to 1e-6 (a check of h)."""
    analysis = scenario_modal_analysis(scenario_io.load('beam_lift'), hold_uavs=True)
    h = float(cable_drops(analysis)[0])
    effective = [9.81 / analysis.eigenvalues[k].imag ** 2 for k in analysis.pendulum_modes]
    assert min(abs(v - h) for v in effective) < 1e-6 * h
    assert h < 4.0 - 0.1
