"""Load shares (issue 35, multilift_sim.analysis.loads; `multilift loads`) against statics
worked out here, and the run summary's least thrust margin against an open-loop run whose
thrust is known in closed form."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

from multilift_control.headless import fly
from multilift_control.laws import runnable
from multilift_control.laws.rigid_statics import hang_body
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.equilibrium import scenario_configuration
from multilift_sim.analysis.loads import QuasiStatic, _hang, hover_loads
from multilift_tools.loads_cli import loads_main

from conftest import ROOT


def _largest(vehicle) -> float:
    return vehicle.n_rotors * vehicle.thrust_coefficient * vehicle.rotor_speed_max ** 2


def test_a_single_lift_carries_its_payload_s_weight_and_leans_into_an_acceleration():
    s = scenario_io.load('single_lift')
    g, m, m_p = s.simulation.gravity, s.uavs[0].vehicle.mass, s.payload.mass
    hover = hover_loads(s)
    assert hover.tensions[0] == pytest.approx(m_p * g, rel=1e-9)
    assert hover.thrusts[0] == pytest.approx((m + m_p) * g, rel=1e-9)
    assert hover.margins[0] == pytest.approx(1 - (m + m_p) * g / _largest(s.uavs[0].vehicle))
    a = 2.0  # [m/s^2] along x: the payload swings back until the cable carries m_p |g e_z + a|
    shares = QuasiStatic(s).loads((a, 0.0, 0.0))
    assert shares.tensions[0] == pytest.approx(m_p * math.hypot(g, a), rel=1e-9)
    assert shares.thrusts[0] == pytest.approx((m + m_p) * math.hypot(g, a), rel=1e-9)


def test_a_twin_lift_s_cables_share_as_their_angle_says():
    s = scenario_io.load('twin_lift')
    hover = hover_loads(s)
    uavs, _ = scenario_configuration(s)  # where the formation hangs at rest
    half_span = 0.5 * np.linalg.norm(uavs[1, :2] - uavs[0, :2])
    cos_angle = math.sqrt(1 - (half_span / s.uavs[0].cable_length) ** 2)
    expected = s.payload.mass * s.simulation.gravity / (2 * cos_angle)
    np.testing.assert_allclose(hover.tensions, [expected, expected], rtol=1e-9)
    # across the UAVs' line the payload swings about it and both cables carry more alike;
    # along it the cable ahead of the acceleration takes the larger share
    line = (uavs[1] - uavs[0]) / np.linalg.norm(uavs[1] - uavs[0])
    across = np.cross([0.0, 0.0, 1.0], line)
    statics = QuasiStatic(s)
    sideways = statics.loads(1.5 * across)
    factor = math.hypot(s.simulation.gravity, 1.5) / s.simulation.gravity
    np.testing.assert_allclose(sideways.tensions, hover.tensions * factor, rtol=1e-9)
    ahead = statics.loads(1.5 * line)   # toward uav2: uav2's cable pulls the payload along
    assert ahead.tensions[1] > hover.tensions[1] > ahead.tensions[0] > 0


def test_the_hang_is_the_lowest_point_the_cables_reach():
    """Against brute force: the circle where two cables reach, sampled finely."""
    rng = np.random.default_rng(4)
    uavs = np.array([[0.0, 0.0, 0.0], [3.0, 1.0, 0.4]])
    lengths = np.array([2.5, 2.8])
    for _ in range(20):
        load = np.array([*rng.normal(0, 3, 2), rng.uniform(2, 10)])
        down = -load / np.linalg.norm(load)
        p = _hang(uavs, np.zeros(3), lengths, load)
        np.testing.assert_allclose(np.linalg.norm(p - uavs, axis=1), lengths, rtol=1e-9)
        axis = (uavs[1] - uavs[0]) / np.linalg.norm(uavs[1] - uavs[0])
        distance = np.linalg.norm(uavs[1] - uavs[0])
        along = (distance ** 2 + lengths[0] ** 2 - lengths[1] ** 2) / (2 * distance)
        radius = math.sqrt(lengths[0] ** 2 - along ** 2)
        e1 = np.cross(axis, [0.0, 0.0, 1.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(axis, e1)
        angles = np.linspace(0, 2 * np.pi, 200_000, endpoint=False)
        ring = uavs[0] + along * axis + radius * (np.outer(np.cos(angles), e1)
                                                  + np.outer(np.sin(angles), e2))
        assert down @ p >= (ring @ down).max() - 1e-9


def test_the_summary_s_least_thrust_margin_is_the_open_loop_thrust_s():
    """single_lift_swing holds every rotor at the speed that balances the weight: its thrust
    margin is 1 - (omega / omega_max)^2 at every tick."""
    s = scenario_io.load('single_lift_swing').with_duration(2.0)
    vehicle = s.uavs[0].vehicle
    omega = math.sqrt((vehicle.mass + s.payload.mass) * s.simulation.gravity
                      / (vehicle.n_rotors * vehicle.thrust_coefficient))
    margin = fly(s).summary()['sim']['least_thrust_margin']
    assert margin == [pytest.approx(1 - (omega / vehicle.rotor_speed_max) ** 2, rel=1e-12)]


def test_the_command_prints_and_writes_the_figures(tmp_path, capsys):
    out = tmp_path / 'loads.json'
    assert loads_main(['twin_lift', '--json', str(out)]) == 0
    figures = json.loads(out.read_text())
    hover = hover_loads(scenario_io.load('twin_lift'))
    np.testing.assert_allclose(figures['hover']['thrust_margin'], hover.margins)
    assert all(m <= h + 1e-12 for m, h in zip(figures['mission']['least_thrust_margin'],
                                               hover.margins))
    assert 'least margin' in capsys.readouterr().out
    assert loads_main(['no_such_scenario']) == 2
    assert 'unknown scenario' in capsys.readouterr().err
    assert loads_main(['box_lift']) == 0  # a rigid body: its hover and its mission
    assert capsys.readouterr().out.count('least margin') == 4
    off_centre = yaml.safe_load((ROOT / 'scenarios' / 'twin_lift.yaml').read_text())
    for uav in off_centre['uavs']:
        uav['attach_point'] = [0.0, 0.0, -0.08]  # a UAV held off its centre would tilt
    path = tmp_path / 'off_centre.yaml'
    path.write_text(yaml.safe_dump(off_centre))
    assert loads_main([str(path)]) == 0
    assert 'hover loads only' in capsys.readouterr().out


@pytest.mark.parametrize('name', ['beam_lift', 'box_lift', 'v3_box_mixed'])
def test_a_rigid_body_at_rest_quasi_statically_is_its_hover(name):
    """Two solvers of a rigid body's rest: the quasi-static one (laws.rigid_statics, Newton
    on its rows from the body level) and the hover's (analysis.equilibrium's start pose, the
    least potential by SLSQP where the body tilts, then Eq. 2.73's rows)."""
    s = scenario_io.load(name)
    hover = hover_loads(s)
    at_rest = QuasiStatic(s, runnable(hang_body)).loads(np.zeros(3))
    np.testing.assert_allclose(at_rest.tensions, hover.tensions, rtol=1e-9)
    np.testing.assert_allclose(at_rest.thrusts, hover.thrusts, rtol=1e-9)


def test_a_beam_s_cables_share_as_a_twin_lift_s():
    """A beam held by its ends, which lie on its centre's line: across the UAVs' line the
    whole formation swings about it and both cables carry |g e_z + a| / g of their hover
    tension (as a point payload's, above); along it the cable ahead pulls more."""
    s = scenario_io.load('beam_lift')
    hover = hover_loads(s)
    uavs, _ = scenario_configuration(s)
    line = (uavs[1] - uavs[0]) / np.linalg.norm(uavs[1] - uavs[0])
    statics = QuasiStatic(s, runnable(hang_body))
    sideways = statics.loads(1.5 * np.cross([0.0, 0.0, 1.0], line))
    factor = math.hypot(s.simulation.gravity, 1.5) / s.simulation.gravity
    np.testing.assert_allclose(sideways.tensions, hover.tensions * factor, rtol=1e-9)
    ahead = statics.loads(1.5 * line)
    assert ahead.tensions[1] > hover.tensions[1] > ahead.tensions[0] > 0
    with pytest.raises(ValueError, match='statics'):
        QuasiStatic(s)  # a rigid body's needs its statics passed in
