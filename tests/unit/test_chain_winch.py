"""Winches on heavy cables (`cable_model: chain` with `uavs[i].winch`, issue 32 items 2-3):
the reel shortens or lengthens every link alike (l_i(t) / N), the nodes keep their masses.
Checked against mechanics worked out here: a chain whirling straight in free fall is a rigid
rotor whose every radius scales with the reel, so its angular momentum L is kept and the
winch's work is the change of L^2 / (2 I) between rests; and a heavy twin-lift lowered 3 m at
a constant rate keeps every link within the constraint tolerance."""
from __future__ import annotations

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import fly, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.simulation import FormationSimulator

WINCH = {'rate_limit': 0.5, 'acceleration_limit': 0.5, 'min_length': 1.0, 'max_length': 6.0}
LINKS, MASS_PER_LENGTH, LENGTH = 10, 0.1, 2.5


def _whirling_chain() -> scenario_io.Scenario:
    """single_lift on a 10-link chain of 0.1 kg/m, rotors all but off, no drag: the payload
    thrown sideways at 1 m/s (the chain starts straight, its nodes' velocities in proportion:
    a rigid rotation about the UAV), the winch paying out 0.3 m/s from 0.5 s to 3.5 s."""
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data.update(cable_model='chain', cable={'links': LINKS, 'mass_per_length': MASS_PER_LENGTH})
    data['uavs'][0]['winch'] = dict(WINCH)
    data['events'] = [{'time': 0.5, 'type': 'winch_rate', 'uav': 1, 'rate': 0.3},
                      {'time': 3.5, 'type': 'winch_rate', 'uav': 1, 'rate': 0.0}]
    data['simulation'].update(duration=5.0, physics_rate=400.0, substeps=1)
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': 5.0}]
    data['control'].update(mode='constant_rotor_speed', constant_rotor_speed=1e-3)
    data['payload'].update(drag_coefficient=0.0, initial_velocity=[1.0, 0.0, 0.0])
    data.pop('gusts', None)
    return scenario_io.loads(yaml.safe_dump(data))


def _bodies(s, x, layout) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every body's (mass [kg] (k,), position [m] (k, 3), velocity [m/s] (k, 3)): the UAV, the
    chain's nodes, the payload."""
    node = MASS_PER_LENGTH * LENGTH / (LINKS - 1)
    masses = np.r_[s.uavs[0].vehicle.mass, np.full(LINKS - 1, node), s.payload.mass]
    places = np.vstack([layout.uav_positions(x)[:1], layout.chain_positions(x)[0],
                        layout.payload_position(x)[None]])
    speeds = np.vstack([layout.uav_velocities(x)[:1], layout.chain_velocities(x)[0],
                        layout.payload_velocity(x)[None]])
    return masses, places, speeds


def test_a_whirling_chain_paid_out_keeps_its_momentum_and_the_winch_s_work():
    """Free fall leaves the motion about the centre of mass alone; the links' pulls are along
    the line, so L = sum m (r x v) is kept and the straight chain whirls as a rigid rotor
    whose radii all scale by l(t) / l_a: I_b = I_a (l_b / l_a)^2 with l_b = l_a + 0.9 m. The
    winch's work between rests, L^2 / 2 (1 / I_b - 1 / I_a), equals the change of the kinetic
    energy about the centre of mass to 1e-6 relative."""
    s = _whirling_chain()
    layout = StateLayout(1, chain_nodes=LINKS - 1)
    states = [FormationSimulator(s).state.copy()]
    run_headless(s, on_tick=lambda sim, *_: states.append(sim.state.copy()))
    momenta, energies, inertias, bends = [], [], [], []
    for x in states:
        masses, places, speeds = _bodies(s, x, layout)
        centre = masses @ places / masses.sum()
        drift = masses @ speeds / masses.sum()
        r, v = places - centre, speeds - drift
        momenta.append((masses[:, None] * np.cross(r, v)).sum(axis=0))
        energies.append(0.5 * (masses * (v * v).sum(axis=1)).sum())
        inertias.append((masses * (r * r).sum(axis=1)).sum())
        line = places[-1] - places[0]
        off = np.cross(places - places[0], line / np.linalg.norm(line))
        bends.append(np.linalg.norm(off, axis=1).max())
    momenta = np.array(momenta)
    spin = np.linalg.norm(momenta[0])
    assert np.abs(momenta - momenta[0]).max() < 1e-7 * spin
    assert max(bends) < 1e-6                      # [m]: the chain stays straight
    l_a, l_b = LENGTH, LENGTH + 0.9
    reach = np.linalg.norm(layout.payload_position(states[-1])
                           - layout.uav_positions(states[-1])[0])
    assert reach == pytest.approx(l_b, abs=1e-6)
    i_a, i_b = inertias[0], inertias[0] * (l_b / l_a) ** 2
    assert inertias[-1] == pytest.approx(i_b, rel=1e-6)
    work = 0.5 * spin ** 2 * (1.0 / i_b - 1.0 / i_a)
    assert energies[-1] - energies[0] == pytest.approx(work, rel=1e-6)
    assert work < -0.05                           # [J]: paying out slows the whirl


def test_heavy_cables_lowered_3_m_keep_their_links_and_the_payload_follows():
    """twin_lift_chain's two winches pay out 0.3 m/s for 10 s from its hover at 5 s: each
    chain 3 m longer (30 links of 0.443 m), max |g| of every link within the tolerance, the
    payload 3 m further below its UAVs less the geometry's change (sqrt(l^2 - (d/2)^2) for
    straight cables l from UAVs d apart; the chains' sag, under 0.3 m, is the difference)."""
    data = yaml.safe_load((SCENARIOS / 'twin_lift_chain.yaml').read_text())
    for u in data['uavs']:
        u['winch'] = {'rate_limit': 0.5, 'acceleration_limit': 0.5, 'min_length': 8.0,
                      'max_length': 15.0}
    data['events'] = [{'time': t, 'type': 'winch_rate', 'uav': i, 'rate': rate}
                      for t, rate in ((5.0, 0.3), (15.0, 0.0)) for i in (1, 2)]
    data['simulation']['duration'] = 20.0
    data['payload']['swing_deg'] = 0.0
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': 20.0}]
    s = scenario_io.loads(yaml.safe_dump(data))
    lowered = fly(s)
    sim = lowered.summary()['sim']
    length = s.uavs[0].cable_length
    assert sim['longest_cable'] == pytest.approx([length + 3.0] * 2, abs=1e-9)
    assert sim['max_abs_constraint'] < s.simulation.constraint_tolerance
    x = lowered.engine.state[0]
    layout = StateLayout(2, chain_nodes=s.cable['links'] - 1)
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    half = 0.5 * np.linalg.norm(uavs[0, :2] - uavs[1, :2])
    below = uavs[:, 2].mean() - payload[2]
    straight = np.sqrt((length + 3.0) ** 2 - half ** 2)
    assert straight - 0.3 < below <= straight
    links = np.diff(np.vstack([uavs[0], layout.chain_positions(x)[0], payload]), axis=0)
    np.testing.assert_allclose(np.linalg.norm(links, axis=1), (length + 3.0) / s.cable['links'],
                               rtol=1e-3)


def test_a_chain_s_stepping_is_checked_at_the_winch_s_shortest_length():
    """Reeled in to its min_length the chain's links are shorter and carry the same masses:
    its fastest transverse mode grows by sqrt(l / l_min), so a stepping that holds at the
    cable's length is refused at a short enough stop, in one line naming the sub-steps."""
    data = yaml.safe_load((SCENARIOS / 'twin_lift_chain.yaml').read_text())
    scenario_io.loads(yaml.safe_dump(data))
    for u in data['uavs']:
        u['winch'] = {'rate_limit': 0.5, 'acceleration_limit': 0.5, 'min_length': 0.5,
                      'max_length': 15.0}
    with pytest.raises(scenario_io.ScenarioError, match='^[^\n]*$') as error:
        scenario_io.loads(yaml.safe_dump(data))
    assert 'simulation.substeps' in str(error.value)


def test_a_learner_reels_heavy_cables_through_its_actions():
    """Hover-v0 on twin_lift_chain with winches and `winch_actions=True`: the expert flies the
    chains without a termination, and a reel action of 1 on uav1 pays its chain out at the
    winch's 0.5 m/s after the 1 s ramp (the trapezoid of the acceleration limit), to 0.01 m."""
    import gymnasium

    import multilift_learning  # noqa: F401 - registers the environments
    from multilift_sim.physics.layout import REEL_LENGTH
    data = yaml.safe_load((SCENARIOS / 'twin_lift_chain.yaml').read_text())
    for u in data['uavs']:
        u['winch'] = {'rate_limit': 0.5, 'acceleration_limit': 0.5, 'min_length': 8.0,
                      'max_length': 15.0}
    s = scenario_io.loads(yaml.safe_dump(data))
    env = gymnasium.make('multilift/Hover-v0', scenario=s, duration=4.0,
                         winch_actions=True).unwrapped
    env.reset(seed=0)
    size = env.batch.uav_action_size
    start = env.batch.engine.memory.reel[0, 0, REEL_LENGTH]
    ticks = 300
    for _ in range(ticks):
        action = env.expert_action().copy()
        action[size - 1] = 1.0
        observation, _, terminated, truncated, info = env.step(action)
        assert not terminated and np.all(np.isfinite(observation)), info
    paid = 0.5 * ticks * 0.01 - 0.5 * 0.5 / (2 * 0.5)
    assert env.batch.engine.memory.reel[0, 0, REEL_LENGTH] - start == pytest.approx(paid,
                                                                                  abs=0.01)
