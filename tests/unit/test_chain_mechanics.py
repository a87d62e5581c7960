"""Heavy cables (`cable_model: chain`, issue 32 items 2 and 4) against mechanics worked out
here, not from the code's outputs: a chain hanging from a held point swings in the continuous
hanging chain's first three modes (Bessel: omega_j = (j_0,j / 2) sqrt(g / L)), a chain held at
both ends hangs on the catenary, a heavy payload on a light chain swings at the rigid
pendulum's period, and the links keep their lengths over the twin_lift_chain mission."""
from __future__ import annotations

import sys

import numpy as np
import pytest

from conftest import ROOT, SCENARIOS
from multilift_control.headless import run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout

sys.path.insert(0, str(ROOT / 'benchmarks'))
import chain_mechanics  # noqa: E402  (the measurements, benchmarks/)


@pytest.mark.parametrize('mode', [1, 2, 3])
def test_a_hanging_chain_swings_in_the_continuous_chain_s_modes(mode):
    """40 links of mu = 0.1 kg/m, L = 2.5 m, the payload one node's mass (40 equal masses,
    the last at the free end), held at the top, displaced 1 mm along the continuous chain's
    mode shape J0(2 omega_j sqrt(z / g)): it swings at omega_j = (j_0,j / 2) sqrt(g / L)
    (1.2024, 2.7600, 4.3269 sqrt(g / L)) within 1 % (`chain_mechanics.hanging_mode`; 25
    links miss mode 3 by more, docs/cables.md)."""
    measured, continuous = chain_mechanics.hanging_mode(mode, 40)
    assert measured == pytest.approx(continuous, rel=0.01)


def test_a_chain_held_at_both_ends_hangs_on_the_catenary():
    """Two held UAVs 4 m apart, each cable 3 m of 20 links, the payload one node's mass: one
    chain of 6 m and 40 equal masses; damped by the air, its lowest point settles on the
    catenary's sag within 1 % (not the rigid cables' V, 0.24 m deeper)."""
    measured, sag, straight = chain_mechanics.catenary(20)
    assert measured == pytest.approx(sag, rel=0.01)
    assert abs(measured - straight) > 0.05 * sag


def test_a_heavy_payload_on_a_light_chain_swings_at_the_pendulum_s_period():
    """A 5 kg payload on 2.5 m of chain (10 links, 25 g) under a held UAV, released 3 deg from
    hanging: its period 2 pi sqrt(l / g) (1 + theta_0^2 / 16) within 0.5 %."""
    period, expected, crossings = chain_mechanics.pendulum()
    assert crossings >= 5
    assert period == pytest.approx(expected, rel=0.005)


def test_a_chain_whirling_in_free_fall_keeps_its_energy_and_folds():
    """No drag, rotors off: a payload thrown sideways at 1 m/s on a 10-link chain at rest
    drags it into a fold (the payload within 0.95 l of the UAV) and whirls about the falling
    UAV; kinetic + gravitational energy of every body (UAV, payload, nodes) stays within 1e-8
    of the throw's m_p v^2 / 2 over 5 s (`chain_mechanics.free_fall_energy`: 3.9e-9)."""
    drift, throw, reach, worst = chain_mechanics.free_fall_energy()
    assert drift < 1e-8 * throw
    assert reach < 0.95 * 2.5
    assert worst < 1e-8


def test_a_chain_held_off_the_uav_s_centre_keeps_its_energy_turning_the_uav():
    """The same throw on a cable held 0.1, 0.05, -0.1 m off the UAV's centre (body FLU): the
    chain's pull turns the UAV (0.07 rad/s), and kinetic (its rotation's 1/2 omega . J omega
    included) + gravitational energy stays within 1e-8 of the throw's over 5 s (3.9e-9)."""
    drift, throw, reach, worst = chain_mechanics.free_fall_energy(
        attach_point=(0.1, 0.05, -0.1))
    assert drift < 1e-8 * throw
    assert worst < 1e-8


def test_a_beam_on_chains_keeps_the_energy_balance():
    """A rigid payload on chains: beam_lift's beam on 10-link chains of 0.05 kg/m, no drag,
    the rotors at a held speed (the UAVs level: a constant lift each): the chains sag from
    straight and the beam swings and turns (uneven lifts, 1900 and 1890 rad/s); over 5 s the
    energy of every body (the beam's rotation included) changes by the rotors' work
    F_i (z_i(t) - z_i(0)) to 1e-8 of that work (`chain_mechanics.beam_energy`: 1.2e-12)."""
    mismatch, change, turn, worst = chain_mechanics.beam_energy()
    assert change > 1.0          # [J]: the rotors do work
    assert turn > 0.1            # [rad/s]: the beam turns
    assert mismatch < 1e-8 * change
    assert worst < 1e-8


def test_the_links_keep_their_lengths_over_the_twin_lift_chain_mission():
    """twin_lift_chain flies its whole mission (120 s) with every link within the constraint
    tolerance: each cable's worst |g_ik| = ||d_ik|^2 - (l / N)^2| at every tick, measured from
    the state here, below 1e-6 of the link's s^2 (and the run's own max |g| below the
    tolerance); the chain sags below the straight cable and carries its weight."""
    s = scenario_io.load(SCENARIOS / 'twin_lift_chain.yaml')
    links = s.cable['links']
    layout = StateLayout(2, chain_nodes=links - 1)
    worst, sag = [0.0], [0.0]
    link_sq = (s.uavs[0].cable_length / links) ** 2

    def each(sim, *_):
        x = sim.state
        for i in range(2):
            points = np.vstack([layout.uav_positions(x)[i], layout.chain_positions(x)[i],
                                layout.payload_position(x)])
            d = np.diff(points, axis=0)
            worst[0] = max(worst[0], float(np.max(np.abs((d * d).sum(axis=1) - link_sq))))
            chord = points[-1] - points[0]
            middle = points[links // 2] - (points[0] + chord / 2)
            sag[0] = max(sag[0], float(np.linalg.norm(np.cross(middle, chord))
                                       / np.linalg.norm(chord)))

    run = run_headless(s, on_tick=each)
    assert worst[0] < 1e-6 * link_sq
    assert run.simulator.stats.max_abs_constraint < s.simulation.constraint_tolerance
    assert sag[0] > 0.01   # [m]: the cable's middle off its chord


def test_a_payload_on_elastic_links_bounces_at_the_discrete_chain_s_frequency():
    """10 elastic links (the whole cable k = 2 kN/m: each link 20 kN/m) of 50 g under a held
    UAV, a 2 kg payload pushed down from its static stretch: it bounces at the lowest
    eigenfrequency of the chain's own stiffness and mass matrices (nodes and payload, the UAV
    fixed; 31.498 rad/s against k / m_p's 31.6) within 1e-4 (measured 4.7e-7)."""
    measured, expected = chain_mechanics.elastic_bounce()
    assert measured == pytest.approx(expected, rel=1e-4)
    assert abs(expected - (2000.0 / 2.0) ** 0.5) > 0.05   # the chain's mass counts


def test_a_chain_on_elastic_links_whirling_in_free_fall_keeps_its_energy():
    """The free-falling whirl on elastic links (the whole cable 5 kN/m, no damping, no drag):
    kinetic + gravitational + the links' elastic energy N k / 2 stretch^2 stays within 1e-5
    of the throw's over 5 s at 28 sub-steps (5.8e-6; the fold snaps the links, exciting their
    fast modes: 6.2e-5 at the 14 sub-steps the validation asks for at least, docs/cables.md)."""
    drift, throw, reach, _ = chain_mechanics.free_fall_energy(stiffness=5000.0, substeps=28)
    assert drift < 1e-5 * throw
    assert reach < 0.95 * 2.5
