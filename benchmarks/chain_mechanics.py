#!/usr/bin/env python3
"""Heavy cables (`cable_model: chain`, issue 32 item 4) against mechanics: a chain hanging from
a held point swings in the continuous hanging chain's modes omega_j = (j_0,j / 2) sqrt(g / L)
(Bessel), a chain held at both ends hangs on the catenary, a heavy payload on a light chain
swings at the rigid pendulum's period. Prints each figure's measured value against the
independent one for several link counts; tests/unit/test_chain_mechanics.py asserts them.

Run: scripts/setup && source scripts/env.sh && python benchmarks/chain_mechanics.py
"""
from __future__ import annotations

import math

import numpy as np
import yaml
from scipy.optimize import brentq
from scipy.special import j0, jn_zeros

from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario.files import resolve
from multilift_sim.simulation import FormationSimulator

G = 9.81
HELD_MASS = 1e7   # [kg]: a UAV this heavy is held (a chain's pull of a few N moves it by
#                   < 1e-5 m over these runs)


def held(base: str, links: int, mass_per_length: float, payload_mass: float, duration: float,
         cable_length: float, physics_rate: float = 400.0, substeps: int = 1, **cable):
    """`base`'s scenario on chains of `links` links, mu = mass_per_length [kg/m], each
    cable_length [m], under UAVs of HELD_MASS, no payload drag, no gusts: (scenario,
    simulator, rotor speeds that lift each UAV's weight and its share of the rest)."""
    data = yaml.safe_load(resolve(base).read_text())
    data.update(cable_model='chain', cable_length=cable_length,
                cable={'links': links, 'mass_per_length': mass_per_length, **cable})
    for u in data['uavs']:
        u.pop('cable_length', None)
    data['vehicle'].update(mass=HELD_MASS, rotor_speed_max=2000.0,
                           thrust_coefficient=HELD_MASS * G / (4 * 1000.0 ** 2))
    data['payload'].update(mass=payload_mass, drag_coefficient=0.0)
    data['payload'].pop('swing_deg', None)
    data['control'].update(mode='constant_rotor_speed', constant_rotor_speed=1000.0)
    data['simulation'].update(duration=duration, physics_rate=physics_rate,
                              control_rate=physics_rate / 2, substeps=substeps)
    data.pop('gusts', None)
    s = scenario_io.loads(yaml.safe_dump(data))
    n = s.n_uavs
    weight = HELD_MASS + (payload_mass + mass_per_length * cable_length * n) / n
    speed = 1000.0 * math.sqrt(weight / HELD_MASS)
    return s, FormationSimulator(s), [np.full(4, speed) for _ in range(n)]


def fly(sim, speeds, each) -> None:
    """The simulator to its end under the held rotor speeds, `each(state)` at every tick."""
    flags = [np.zeros(4, dtype=bool) for _ in speeds]
    while not sim.finished:
        each(sim.state)
        sim.advance(speeds, flags)


def period_of(signal, rate: float) -> tuple[float, int]:
    """The mean period [s] between upward zero crossings of a signal sampled at rate [Hz]
    (interpolated), and how many crossings it had."""
    q = np.asarray(signal)
    t = np.arange(len(q)) / rate
    up = np.flatnonzero((q[:-1] < 0.0) & (q[1:] >= 0.0))
    crossings = t[up] + (t[up + 1] - t[up]) * -q[up] / (q[up + 1] - q[up])
    return (crossings[-1] - crossings[0]) / (len(crossings) - 1), len(crossings)


def hanging_mode(mode: int, links: int, length: float = 2.5,
                 mass_per_length: float = 0.1) -> tuple[float, float]:
    """(measured, continuous) omega of a chain's mode j [rad/s]: N links hanging from a held
    UAV, the payload one inner node's mass (N equal masses, the last at the free end),
    displaced 1 mm at the foot along the continuous mode's shape u(z) = J0(2 omega_j
    sqrt(z / g)) (z the height above the foot) and swinging 8 s; omega from its modal
    coordinate's zero crossings."""
    node = mass_per_length * length / (links - 1)
    s, sim, speeds = held('single_lift', links, mass_per_length, node, 8.0, length)
    layout = StateLayout(1, chain_nodes=links - 1)
    omega = jn_zeros(0, 3)[mode - 1] / 2 * math.sqrt(G / length)
    x = sim.state
    top = layout.uav_positions(x)[0]
    nodes = np.vstack([layout.chain_positions(x)[0], layout.payload_position(x)[None]])
    shape = j0(2 * omega * np.sqrt((nodes[:, 2] - nodes[-1, 2]) / G))
    shape *= 1e-3 / shape[-1]
    layout.chain_positions(x)[0, :, 0] = top[0] + shape[:-1]   # sideways (x); a 1 mm
    layout.payload_position(x)[0] = top[0] + shape[-1]         # displacement leaves the links
    sim.state = x                                              # at 1e-7 of their length^2
    modal = []
    fly(sim, speeds, lambda state: modal.append(float((np.append(
        layout.chain_positions(state)[0, :, 0], layout.payload_position(state)[0])
        - top[0]) @ shape)))
    period, _ = period_of(modal, s.simulation.control_rate)
    return 2 * math.pi / period, omega


def catenary(links: int, length: float = 3.0, mass_per_length: float = 0.1,
             duration: float = 20.0) -> tuple[float, float, float]:
    """(measured, catenary, straight) depth [m] of the lowest point below two held UAVs
    (twin_lift's places, 4 m apart), each cable `length` of N links, the payload one node's
    mass (one chain of 2 l and 2 N links of equal masses), damped by the air (C_d 1.2 on
    2 cm nodes): the mean of the last 2 s of `duration`; the catenary's sag a (cosh(D / 2a)
    - 1) with 2 a sinh(D / 2a) = 2 l, D the UAVs' distance; the rigid V's depth."""
    node = mass_per_length * length / (links - 1)
    s, sim, speeds = held('twin_lift', links, mass_per_length, node, duration, length,
                          drag_coefficient=1.2, diameter=0.02)
    layout = StateLayout(2, chain_nodes=links - 1)
    depths = []
    fly(sim, speeds, lambda state: depths.append(float(
        layout.uav_positions(state)[:, 2].mean() - layout.payload_position(state)[2])))
    uavs = layout.uav_positions(sim.state)
    span = float(np.linalg.norm(uavs[0] - uavs[1]))
    a = brentq(lambda a: 2 * a * math.sinh(span / (2 * a)) - 2 * length, 0.05, 100.0)
    settled = float(np.mean(depths[-int(2 * s.simulation.control_rate):]))
    return settled, a * (math.cosh(span / (2 * a)) - 1.0), math.sqrt(length ** 2
                                                                       - (span / 2) ** 2)


def pendulum(links: int = 10, payload_mass: float = 5.0, mass_per_length: float = 0.01,
             length: float = 2.5, degrees: float = 3.0) -> tuple[float, float, int]:
    """(measured, rigid pendulum's) period [s] and the crossings counted: a payload of
    payload_mass on a light chain (mu l = 25 g) under a held UAV, released `degrees` from
    hanging with the chain straight, 20 s; the rigid pendulum's 2 pi sqrt(l / g)
    (1 + theta_0^2 / 16)."""
    theta = math.radians(degrees)
    s, sim, speeds = held('single_lift', links, mass_per_length, payload_mass, 20.0, length,
                          substeps=3)
    layout = StateLayout(1, chain_nodes=links - 1)
    x = sim.state
    top = layout.uav_positions(x)[0]
    offset = length * np.array([math.sin(theta), 0.0, -math.cos(theta)])
    layout.chain_positions(x)[0] = top + (np.arange(1, links) / links)[:, None] * offset
    layout.payload_position(x)[:] = top + offset
    sim.state = x
    swing = []
    fly(sim, speeds, lambda state: swing.append(layout.payload_position(state)[0] - top[0]))
    period, count = period_of(swing, s.simulation.control_rate)
    return period, 2 * math.pi * math.sqrt(length / G) * (1 + theta ** 2 / 16), count


def free_fall_energy(links: int = 10, mass_per_length: float = 0.1, length: float = 2.5,
                     physics_rate: float = 400.0, attach_point=None, stiffness: float = 0.0,
                     substeps: int = 1) -> tuple[float, float, float, float]:
    """single_lift's UAV and payload on a chain of `links` links, rotors off, no drag, no
    gusts, the payload thrown sideways at 1 m/s, the nodes at rest (every link's g_dot 0): in
    free fall the payload drags the chain into a fold and whirls about the UAV for 5 s. Returns
    (the largest change of kinetic + gravitational energy [J] over the run (every body: the
    UAV, the payload, each node), the throw's energy m_p v^2 / 2 [J], the shortest distance
    UAV -> payload [m] (below l: folded), the run's max |g| [m^2]). With `attach_point` [m],
    body FLU, the cable holds the UAV there (the payload starting l below it): the chain
    turns the UAV too (its rotational energy 1/2 omega . J omega counted). With `stiffness`
    [N/m] (the whole cable's k, `substeps` RK4 steps a physics step) the links are elastic:
    their energy N k / 2 stretch^2 counted (the UAV's centre holding the chain)."""
    data = yaml.safe_load(resolve('single_lift').read_text())
    data.update(cable_model='chain', cable_length=length,
                cable={'links': links, 'mass_per_length': mass_per_length,
                       **({'stiffness': stiffness} if stiffness else {})})
    for u in data['uavs']:
        u.pop('cable_length', None)
        if attach_point is not None:
            u['attach_point'] = list(attach_point)
    data['payload'].update(drag_coefficient=0.0, initial_velocity=[1.0, 0.0, 0.0])
    if attach_point is not None:  # hanging from the attach point (the UAV level at 0)
        data['payload']['initial_position'] = [attach_point[0], attach_point[1],
                                               attach_point[2] - length]
    data['control'].update(mode='constant_rotor_speed', constant_rotor_speed=1.0)
    data['simulation'].update(duration=5.0, physics_rate=physics_rate, control_rate=100.0,
                              substeps=substeps)
    data.pop('gusts', None)
    s = scenario_io.loads(yaml.safe_dump(data))
    sim = FormationSimulator(s)
    layout = StateLayout(1, chain_nodes=links - 1)
    x = sim.state
    layout.chain_velocities(x)[:] = 0.0
    sim.state = x
    node = mass_per_length * length / (links - 1)
    uav, payload = s.uavs[0].vehicle.mass, s.payload.mass
    inertia = np.array(s.uavs[0].vehicle.inertia)   # principal, body [kg m^2]
    energies, reach = [], []

    def each(x):
        bodies = ((uav, layout.uav_positions(x)[0], layout.uav_velocities(x)[0]),
                  (payload, layout.payload_position(x), layout.payload_velocity(x)))
        energy = sum(0.5 * m * v @ v + m * G * p[2] for m, p, v in bodies)
        rates = layout.uav_body_rates(x)[0]
        energy += 0.5 * rates @ (inertia * rates)
        nodes, speeds = layout.chain_positions(x)[0], layout.chain_velocities(x)[0]
        if stiffness:
            places = np.vstack([bodies[0][1], nodes, bodies[1][1]])
            stretch = np.maximum(np.linalg.norm(np.diff(places, axis=0), axis=1)
                                 - length / links, 0.0)
            energy += 0.5 * links * stiffness * stretch @ stretch
        energies.append(energy + 0.5 * node * (speeds * speeds).sum()
                        + node * G * nodes[:, 2].sum())
        reach.append(float(np.linalg.norm(layout.payload_position(x)
                                          - layout.uav_positions(x)[0])))

    fly(sim, [np.zeros(4)], each)
    return (float(np.ptp(energies)), 0.5 * payload, min(reach),
            sim.stats.max_abs_constraint)


def beam_energy(links: int = 10, mass_per_length: float = 0.05,
                speeds: tuple[float, float] = (1900.0, 1890.0),
                duration: float = 5.0) -> tuple[float, float, float, float]:
    """beam_lift's 1.5 kg beam (a rigid body, held at its ends) on chains of `links` links, no
    drag, no gusts, UAV i's rotors all held at `speeds`[i] [rad/s] (no torque: the UAVs stay
    level, their thrust F_i = n k_T speed_i^2 straight up; uneven, so the beam tilts): the
    chains start straight and sag, the beam swings and turns. Returns (the largest
    |E(t) - E(0) - sum_i F_i (z_i(t) - z_i(0))| [J] over the run,
    E kinetic (the beam's rotation 1/2 omega . J omega included) + gravitational energy of every
    body; the largest |E(t) - E(0)| [J] (what the rotors did); the beam's largest rate
    [rad/s]; the run's max |g| [m^2])."""
    data = yaml.safe_load(resolve('beam_lift').read_text())
    data.update(cable_model='chain', cable={'links': links, 'mass_per_length': mass_per_length})
    data['payload'].update(drag_coefficient=0.0)
    data['control'].update(mode='constant_rotor_speed', constant_rotor_speed=speeds[0])
    data['simulation'].update(duration=duration, substeps=2)
    data.pop('gusts', None)
    s = scenario_io.loads(yaml.safe_dump(data))
    sim = FormationSimulator(s)
    n = s.n_uavs
    layout = StateLayout(n, True, chain_nodes=links - 1)
    vehicle = s.uavs[0].vehicle
    lift = vehicle.n_rotors * vehicle.thrust_coefficient * np.square(speeds)   # [N] (n,)
    node = mass_per_length * s.uavs[0].cable_length / (links - 1)
    inertia = np.array(s.payload.inertia)
    start = layout.uav_positions(sim.state)[:, 2].copy()
    energies, works, rates = [], [], []

    def each(x):
        v, w = layout.uav_velocities(x), layout.payload_velocity(x)
        omega = layout.payload_body_rates(x)
        nodes, speeds = layout.chain_positions(x), layout.chain_velocities(x)
        energies.append(0.5 * vehicle.mass * (v * v).sum()
                        + vehicle.mass * G * layout.uav_positions(x)[:, 2].sum()
                        + 0.5 * s.payload.mass * w @ w
                        + s.payload.mass * G * layout.payload_position(x)[2]
                        + 0.5 * omega @ (inertia * omega)
                        + 0.5 * node * (speeds * speeds).sum() + node * G * nodes[..., 2].sum())
        works.append(float(lift @ (layout.uav_positions(x)[:, 2] - start)))
        rates.append(float(np.linalg.norm(omega)))

    fly(sim, [np.full(vehicle.n_rotors, speed) for speed in speeds], each)
    change = np.array(energies) - energies[0]
    return (float(np.abs(change - np.array(works)).max()), float(np.abs(change).max()),
            max(rates), sim.stats.max_abs_constraint)


def elastic_bounce(links: int = 10, stiffness: float = 2000.0, payload_mass: float = 2.0,
                   mass_per_length: float = 0.02, length: float = 2.5, duration: float = 4.0,
                   substeps: int = 20) -> tuple[float, float]:
    """A payload on an elastic chain (`cable.stiffness` k [N/m], the whole cable's: each link
    N k) under a held UAV, no damping, no drag: started at its static stretch (each link
    stretched by the weight below it over N k) and pushed down at 0.3 of the stretch's speed
    at omega_1, it bounces along the chain. Returns (its measured omega [rad/s], the lowest
    omega of the discrete chain's stiffness and mass matrices (the N - 1 nodes and the payload,
    the UAV fixed) [rad/s])."""
    s, sim, speeds = held('single_lift', links, mass_per_length, payload_mass, duration,
                          length, substeps=substeps, stiffness=stiffness)
    layout = StateLayout(1, chain_nodes=links - 1)
    node = mass_per_length * length / (links - 1)
    link_k, rest = links * stiffness, length / links
    masses = np.r_[np.full(links - 1, node), payload_mass]   # node 1 .. N (N the payload)
    carried = G * np.cumsum(masses[::-1])[::-1]                # link k holds nodes k .. N
    stiffness_matrix = (np.diag(np.r_[2.0 * np.ones(links - 1), 1.0])
                        - np.diag(np.ones(links - 1), 1) - np.diag(np.ones(links - 1), -1))
    omegas = np.sqrt(np.linalg.eigvals(link_k * stiffness_matrix / masses[:, None]).real)
    expected = float(omegas.min())
    x = sim.state
    top = layout.uav_positions(x)[0]
    depth = np.cumsum(rest + carried / link_k)                 # node k below the UAV [m]
    layout.chain_positions(x)[0] = top - np.outer(depth[:-1], [0.0, 0.0, 1.0])
    layout.payload_position(x)[:] = top - [0.0, 0.0, depth[-1]]
    layout.chain_velocities(x)[0] = 0.0
    push = 0.3 * (carried[-1] / link_k) * expected
    layout.payload_velocity(x)[:] = [0.0, 0.0, -push]
    sim.state = x
    heights = []

    def each(x):
        heights.append(layout.payload_position(x)[2])

    fly(sim, speeds, each)
    z = np.array(heights)
    period, _ = period_of(z - z.mean(), 1.0 / s.simulation.control_period)
    return 2.0 * math.pi / period, expected


def main() -> None:
    print('hanging chain, L = 2.5 m, mu = 0.1 kg/m: omega measured / continuous - 1')
    for links in (10, 25, 40):
        errors = [m / c - 1 for m, c in (hanging_mode(j, links) for j in (1, 2, 3))]
        print(f'  N = {links:3d}: ' + ', '.join(f'mode {j + 1} {e:+.4f}'
                                                for j, e in enumerate(errors)))
    print('chain held at both ends (D = 4 m, 2 x 3 m): depth measured / catenary - 1')
    for links in (10, 20):
        measured, sag, straight = catenary(links)
        print(f'  N = {links:3d} a cable: {measured:.4f} m against {sag:.4f} m '
              f'({measured / sag - 1:+.4f}; the rigid V {straight:.4f} m)')
    period, expected, count = pendulum()
    mismatch, change, turn, worst = beam_energy()
    print(f'beam_lift\'s beam on 10-link chains, rotors at 1900 and 1890 rad/s, 5 s: energy '
          f'change {change:.1f} J, the rotors\' work less it {mismatch:.2e} J '
          f'({mismatch / change:.1e}), the beam turning up to {turn:.3f} rad/s, '
          f'max |g| {worst:.1e} m^2')
    drift, throw, reach, worst = free_fall_energy(attach_point=(0.1, 0.05, -0.1))
    print(f'the same held 0.1, 0.05, -0.1 m off the UAV\'s centre: energy kept to '
          f'{drift:.2e} J ({drift / throw:.1e}), folded to {reach:.3f} m, max |g| {worst:.1e}')
    drift, throw, reach, worst = free_fall_energy()
    print(f'a chain whirling in free fall (10 links, 5 s at 400 Hz): energy kept to '
          f'{drift:.2e} J ({drift / throw:.1e} of the throw\'s {throw:.2f} J), folded to '
          f'{reach:.3f} m of its 2.5 m, max |g| {worst:.1e} m^2')
    print(f'heavy payload (5 kg on 25 g of chain, 10 links): period {period:.5f} s against '
          f'{expected:.5f} s ({period / expected - 1:+.2e}, {count} crossings)')
    measured, expected = elastic_bounce()
    print(f'elastic links (10 of k = 20 kN/m, 2 kg payload, 50 g of chain): bounce at '
          f'{measured:.4f} rad/s against the discrete chain\'s {expected:.4f} rad/s '
          f'({measured / expected - 1:+.1e})')
    for substeps in (14, 28):
        drift, throw, reach, _ = free_fall_energy(stiffness=5000.0, substeps=substeps)
        print(f'the whirl on elastic links (k = 5 kN/m, {substeps} sub-steps at 400 Hz): '
              f'energy kept to {drift:.2e} J ({drift / throw:.1e} of the throw\'s), folded to '
              f'{reach:.3f} m')


if __name__ == '__main__':
    main()
