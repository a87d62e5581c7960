"""Elastic cables (`cable_model: elastic`, issue 32, physics.elastic_cables) against mechanics
worked out here: a rope's static stretch, the two-body oscillation of a single lift falling
freely, the energy of an undamped rope, and the validation of the stepping a stiff rope needs."""
from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import fly, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout

G = 9.81


def _single_lift(stiffness: float, damping: float = 0.0, duration: float = 20.0,
                 **simulation) -> scenario_io.Scenario:
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['cable_model'] = 'elastic'
    data['cable'] = {'stiffness': stiffness, 'damping': damping}
    data['simulation'].update(duration=duration, **simulation)
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': duration}]
    return scenario_io.loads(yaml.safe_dump(data))


def _stretch(scenario, x: np.ndarray) -> float:
    layout = StateLayout(1)
    return float(np.linalg.norm(layout.payload_position(x) - layout.uav_positions(x)[0])
                 - scenario.uavs[0].cable_length)


def test_a_hovering_rope_stretches_by_the_payload_s_weight():
    s = _single_lift(stiffness=500.0, damping=5.0)
    run = fly(s)
    expected = s.payload.mass * G / 500.0    # [m]: T = m_p g = k stretch
    assert _stretch(s, run.engine.state[0]) == pytest.approx(expected, rel=1e-4)
    tension = run.summary()['sim']['max_tension']
    assert tension == pytest.approx(s.payload.mass * G, rel=0.05)  # the hover, swing included


def test_a_falling_single_lift_oscillates_at_the_two_body_frequency():
    """Rotors all but off (1 rad/s: 7e-6 N) from the start: in free fall gravity drops out of
    the relative motion, so the stretch x obeys x'' = -k (1/m + 1/m_p) x from x(0) = m_p g / k
    at rest (the static stretch it starts at), x(t) = x(0) cos(omega t) until the rope goes
    slack at a quarter period."""
    k = 200.0
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data.update(cable_model='elastic', cable={'stiffness': k})
    data['control'].update(mode='constant_rotor_speed', constant_rotor_speed=1.0)  # ~0
    data['payload']['drag_coefficient'] = 0.0
    data['simulation'].update(duration=0.06, physics_rate=1000.0, control_rate=1000.0)
    s = scenario_io.loads(yaml.safe_dump(data))
    m, m_p = s.uavs[0].vehicle.mass, s.payload.mass
    omega = math.sqrt(k * (1 / m + 1 / m_p))
    assert 0.06 < math.pi / (2 * omega)    # still stretched at the end
    stretches = []
    run_headless(s, on_tick=lambda sim, *_: stretches.append(_stretch(s, sim.state)))
    t = np.arange(len(stretches)) / 1000.0
    x0 = m_p * G / k
    np.testing.assert_allclose(stretches, x0 * np.cos(omega * t), atol=1e-9 + 1e-6 * x0)


def test_an_undamped_rope_keeps_the_energy_of_a_free_fall():
    """Rotors all but off, no drag, no rope damping: kinetic + gravitational + the rope's elastic
    energy stays what it was (RK4 at omega h = 0.12: to 1e-6 relative over 0.5 s, slack
    phases included)."""
    k = 300.0
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data.update(cable_model='elastic', cable={'stiffness': k})
    data['control'].update(mode='constant_rotor_speed', constant_rotor_speed=1.0)  # ~0
    data['payload'].update(drag_coefficient=0.0, alpha_deg=20.0)
    data['simulation'].update(duration=0.5, physics_rate=400.0, control_rate=100.0)
    s = scenario_io.loads(yaml.safe_dump(data))
    m, m_p, length = s.uavs[0].vehicle.mass, s.payload.mass, s.uavs[0].cable_length
    layout = StateLayout(1)

    def energy(x: np.ndarray) -> float:
        r, p = layout.uav_positions(x)[0], layout.payload_position(x)
        v, w = layout.uav_velocities(x)[0], layout.payload_velocity(x)
        stretch = max(np.linalg.norm(p - r) - length, 0.0)
        return float(0.5 * m * v @ v + 0.5 * m_p * w @ w + G * (m * r[2] + m_p * p[2])
                     + 0.5 * k * stretch ** 2)

    energies = []
    run_headless(s, on_tick=lambda sim, *_: energies.append(energy(sim.state)))
    scale = m_p * G * length  # [J]
    assert np.ptp(energies) < 1e-6 * scale
    assert len(energies) == 51


def test_a_stiff_rope_needs_its_sub_steps():
    with pytest.raises(scenario_io.ScenarioError,
                       match=r'simulation\.substeps: 1 steps the elastic cables at omega h = '
                             r'[\d.]+ .* set simulation\.substeps >= (\d+)'):
        _single_lift(stiffness=2e4)
    try:
        _single_lift(stiffness=2e4)
    except scenario_io.ScenarioError as exc:
        needed = int(str(exc).split('substeps >= ')[1].split(' ')[0])
    s = _single_lift(stiffness=2e4, substeps=needed, duration=2.0)
    x = fly(s).engine.state[0]
    assert _stretch(s, x) == pytest.approx(s.payload.mass * G / 2e4, rel=0.02)
    with pytest.raises(scenario_io.ScenarioError, match='axial_stiffness.*goes without'):
        data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
        data.update(cable_model='elastic', cable={'stiffness': 1.0, 'axial_stiffness': 2.0})
        scenario_io.loads(yaml.safe_dump(data))
    with pytest.raises(scenario_io.ScenarioError, match='cable.*needs cable_model: elastic'):
        data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
        data['cable'] = {'stiffness': 1.0}
        scenario_io.loads(yaml.safe_dump(data))


def test_engine_and_simulator_fly_an_elastic_twin_lift_alike():
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    data.update(cable_model='elastic', cable={'axial_stiffness': 2.0e4, 'damping': 10.0})
    data['simulation'].update(duration=8.0, substeps=2)
    s = scenario_io.loads(yaml.safe_dump(data))
    assert s.uavs[0].cable_stiffness == pytest.approx(2.0e4 / s.uavs[0].cable_length)
    engine, simulator = fly(s), run_headless(s)
    np.testing.assert_array_equal(engine.engine.state[0], simulator.simulator.state)
    assert engine.engine.memory.status[0] == 1  # finished
