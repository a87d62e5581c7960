"""Elastic cables (`cable_model: elastic`, issue 32 item 4) against mechanics worked out here:
the snap load of a payload dropped from slack under a held UAV (energy: m g (h + x) = k x^2 / 2),
a held bounce's frequency and energy over 10 s, the payload's path converging to the rigid
cables' as the ropes stiffen, the summary's rope figures and bad rope keys."""
from __future__ import annotations

import math
import sys

import numpy as np
import pytest
import yaml

from conftest import ROOT, SCENARIOS
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.simulation import FormationSimulator

sys.path.insert(0, str(ROOT / 'benchmarks'))
import elastic_convergence  # noqa: E402  (the sweep's functions, benchmarks/)

G = 9.81
HELD_MASS = 1e5   # [kg]: a UAV this heavy is held (the payload's pull moves it by 1e-5 of
#                   the stretch; the relative motion's reduced mass is m_p's to 4e-6)


def _held_drop(stiffness: float, drop: float, duration: float):
    """single_lift's payload (0.4 kg) on a rope of k = stiffness [N/m], no damping and no drag,
    under a UAV of HELD_MASS whose four rotors lift the whole weight (so the UAV stays where
    it is), released at rest straight below it, `drop` [m] short of the rope's rest length:
    (scenario, simulator)."""
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data.update(cable_model='elastic', cable={'stiffness': stiffness, 'damping': 0.0})
    data['vehicle'].update(mass=HELD_MASS, rotor_speed_max=2000.0,   # hovers near 1000 rad/s
                           thrust_coefficient=HELD_MASS * G / (4 * 1000.0 ** 2))
    data['payload'].update(drag_coefficient=0.0, alpha_deg=0.0, beta_deg=0.0)
    data['control'].update(mode='constant_rotor_speed', constant_rotor_speed=1000.0)
    data['simulation'].update(duration=duration, physics_rate=2000.0, control_rate=2000.0)
    data.pop('gusts', None)
    s = scenario_io.loads(yaml.safe_dump(data))
    sim = FormationSimulator(s)
    layout = StateLayout(1)
    x = sim.state
    uav = layout.uav_positions(x)[0]
    p = layout.payload_position(x)
    start = uav + (s.uavs[0].cable_length - drop) * (p - uav) / np.linalg.norm(p - uav)
    layout.payload_position(x)[:] = start
    sim.state = x
    return s, sim


def test_a_payload_dropped_from_slack_feels_the_snap_load():
    """Held UAV, no damping, no drag: the payload falls h slack, then stretches the rope by x
    until m g (h + x) = k x^2 / 2, so the peak tension is k x = m g (1 + sqrt(1 + 2 k h /
    (m g))); the rope's tension from the state (k (L - l)) at 2 kHz (omega dt = 0.035: the
    sampled peak within 2e-4 of the true one) and the summary's peak tension within 1 %."""
    k, h = 500.0, 0.5
    s, sim = _held_drop(k, h, duration=1.0)
    m = s.payload.mass
    vehicle = s.uavs[0].vehicle
    lift = 4 * vehicle.thrust_coefficient * 1000.0 ** 2    # [N]
    speed = 1000.0 * math.sqrt((HELD_MASS + m) * G / lift)  # the whole weight lifted
    speeds, flags = [np.full(4, speed)], [np.zeros(4, dtype=bool)]
    layout, length = StateLayout(1), s.uavs[0].cable_length
    uav_start = layout.uav_positions(sim.state)[0].copy()
    tensions = []
    while not sim.finished:
        x = sim.state
        stretch = np.linalg.norm(layout.payload_position(x) - layout.uav_positions(x)[0]) - length
        tensions.append(k * max(stretch, 0.0))
        sim.advance(speeds, flags)
    expected = m * G * (1 + math.sqrt(1 + 2 * k * h / (m * G)))   # [N]: 48.4 N
    assert max(tensions) == pytest.approx(expected, rel=0.01)
    assert sim.stats.rope_figures['peak_tension'][0] == pytest.approx(expected, rel=0.01)
    assert sim.stats.rope_figures['max_stretch'][0] == pytest.approx(expected / k, rel=0.01)
    moved = np.linalg.norm(layout.uav_positions(sim.state)[0] - uav_start)
    assert moved < 1e-4 * expected / k   # the UAV held
    slack_until = math.sqrt(2 * h / G)   # [s]: it falls freely until then
    first_taut = next(i for i, t in enumerate(tensions) if t > 0.0) / 2000.0
    assert first_taut == pytest.approx(slack_until, abs=1e-3)


def test_a_held_bounce_keeps_its_frequency_and_energy_for_ten_seconds():
    """Held UAV, no damping, no drag: the payload pulled 5 mm below its rest place (less than
    the static stretch m g / k = 7.8 mm: the rope stays taut) bounces at sqrt(k / m) (its
    zero crossings over 10 s, to 0.1 %), and kinetic + gravitational + elastic energy (the
    held UAV's share and its rotors' constant force's work included) stays within 1e-6 of the
    oscillation's own k A^2 / 2 over the 10 s (RK4 at omega h = 0.018)."""
    k, amplitude = 500.0, 0.005
    s, sim = _held_drop(k, 0.0, duration=10.0)
    m, length = s.payload.mass, s.uavs[0].cable_length
    layout = StateLayout(1)
    x = sim.state
    layout.payload_position(x)[2] -= m * G / k + amplitude   # below the rest length's end
    sim.state = x
    thrust = (HELD_MASS + m) * G   # [N]: the rotors lift the whole weight
    speeds = [np.full(4, math.sqrt(thrust / (4 * s.uavs[0].vehicle.thrust_coefficient)))]
    flags = [np.zeros(4, dtype=bool)]
    energies, heights = [], []
    while True:
        x = sim.state
        r, p = layout.uav_positions(x)[0], layout.payload_position(x)
        v, w = layout.uav_velocities(x)[0], layout.payload_velocity(x)
        stretch = np.linalg.norm(p - r) - length
        energies.append(0.5 * HELD_MASS * v @ v + 0.5 * m * w @ w + m * G * p[2]
                        + (HELD_MASS * G - thrust) * r[2] + 0.5 * k * max(stretch, 0.0) ** 2)
        heights.append(p[2] - r[2])
        if sim.finished:
            break
        sim.advance(speeds, flags)
    assert np.ptp(energies) < 1e-6 * 0.5 * k * amplitude ** 2
    offset = np.array(heights) - np.mean(heights)
    t = np.arange(len(offset)) / 2000.0
    up = np.flatnonzero((offset[:-1] < 0.0) & (offset[1:] >= 0.0))   # upward zero crossings
    crossings = t[up] + (t[up + 1] - t[up]) * -offset[up] / (offset[up + 1] - offset[up])
    period = (crossings[-1] - crossings[0]) / (len(crossings) - 1)  # [s]
    assert 2 * math.pi / period == pytest.approx(math.sqrt(k / m), rel=1e-3)


def test_the_payload_s_path_converges_to_the_rigid_cables_one():
    """twin_lift's whole §4.2 mission (120 s) on undamped ropes of EA = 1e5, 2e5 and 1e6 N
    against the rigid cables: the largest distance between the payloads at the same tick
    shrinks as the ropes stiffen and is within 1 mm from EA = 2e5 N (k = 1.95e4 N/m) on
    (docs/cables.md: the sweep of benchmarks/elastic_convergence.py)."""
    rigid = elastic_convergence.payload_path(elastic_convergence.twin_lift(None))
    gaps = [elastic_convergence.deviation(value, rigid)[0] for value in (1e5, 2e5, 1e6)]
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[0] > 1e-3 > gaps[1]   # the stiffness the docs name: the first within 1 mm


def test_the_summary_gives_each_rope_s_stretch_and_peak_tension():
    """twin_lift_elastic's first 12 s (its release swing): each rope's peak tension is its
    stiffness times its largest stretch (no rope slack, damping 8 N s/m adds the stretch
    rate's share: within 5 %), its largest tension among the run's, engine and simulator
    alike; a rigid run's summary has neither."""
    from multilift_control.headless import fly, run_headless
    data = yaml.safe_load((SCENARIOS / 'twin_lift_elastic.yaml').read_text())
    data['simulation']['duration'] = 12.0
    s = scenario_io.loads(yaml.safe_dump(data))
    headless, engine = run_headless(s).summary()['sim'], fly(s).summary()['sim']
    assert headless['peak_tension'] == engine['peak_tension']
    assert headless['max_stretch'] == engine['max_stretch']
    assert max(headless['peak_tension']) == headless['max_tension']
    for stretch, peak, uav in zip(headless['max_stretch'], headless['peak_tension'], s.uavs):
        assert 0.0 < stretch < 1e-3
        assert peak == pytest.approx(uav.cable_stiffness * stretch, rel=0.05)
    rigid = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    rigid['simulation']['duration'] = 1.0
    assert 'peak_tension' not in fly(scenario_io.loads(yaml.safe_dump(rigid))).summary()['sim']


@pytest.mark.parametrize('cable, uav_cable, message', [
    ({'stiffness': -500.0}, None, r'cable\.stiffness: -500\.0 must be > 0'),
    ({'axial_stiffness': 0.0}, None, r'cable\.axial_stiffness: 0\.0 must be > 0'),
    ({'stiffness': 500.0, 'damping': -1.0}, None, r'cable\.damping: -1\.0 must be >= 0'),
    ({'stiffness': 'stiff'}, None, r'cable\.stiffness: .stiff. must be a number'),
    ({'stiffness': 500.0, 'stretch': 1.0}, None, r'cable.*stretch'),
    ({'stiffness': 500.0}, {'stiffness': -1.0}, r'uavs\[0\]\.cable\.stiffness: -1\.0 must be > 0'),
    ({'damping': 1.0}, None, r'needs stiffness \[N/m\] or axial_stiffness \[N\]'),
])
def test_bad_rope_keys_are_one_line(cable, uav_cable, message):
    """What no rope is (negative or zero stiffness, negative damping, a word, an unknown key,
    a UAV's override, no stiffness at all) is refused in one line naming the key."""
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data.update(cable_model='elastic', cable=cable)
    if uav_cable is not None:
        data['uavs'][0]['cable'] = uav_cable
    with pytest.raises(scenario_io.ScenarioError, match=message) as caught:
        scenario_io.loads(yaml.safe_dump(data))
    assert '\n' not in str(caught.value)
