"""The whole formation without ROS: the simulator core and every controller in one process.

Same physics, same control laws, same tick order as the ROS stack (state at t -> commands
answering t -> integrate to the next tick), for studies, sweeps and benchmarks.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from multilift_control.cascade import UavState
from multilift_control.controllers import make_controller
from multilift_control.formation import FormationFollower
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import FormationSimulator, Snapshot


def uav_states(snapshot: Snapshot) -> list[UavState]:
    return [UavState(u.position, u.velocity, u.euler, u.body_rates) for u in snapshot.uavs]


def run_headless(scenario: Scenario,
                 on_tick: Callable[[FormationSimulator, list], None] | None = None
                 ) -> FormationSimulator:
    """Fly `scenario` to t_max; `on_tick(sim, outputs)` sees every tick. Returns the simulator
    (its `stats` hold the run's figures). Raises SimulationStopped like the node would."""
    sim = FormationSimulator(scenario)
    leader = make_controller(scenario, 0)
    followers = [FormationFollower.from_scenario(scenario, i) for i in range(1, scenario.n_uavs)]
    share = scenario.payload.mass / scenario.n_uavs
    thrusts = [(u.vehicle.mass + share) * scenario.simulation.gravity for u in scenario.uavs]
    k_t = [u.vehicle.thrust_coefficient for u in scenario.uavs]
    while True:
        snapshot = sim.snapshot()
        states = uav_states(snapshot)
        output, _ = leader.update(sim.t, states[0])
        outputs = [output]
        if followers:
            thrusts[0] = k_t[0] * float(np.sum(output.rotor_speeds ** 2))
            # as the follower nodes: the leader's thrust at t, the other followers' of the last
            # tick; R(eta) e_z is the snapshot's rotation (kinematics.rotation_matrix)
            axes = np.array([u.rotation[:, 2] for u in snapshot.uavs])
            vectors = axes * np.array(thrusts)[:, None]
            outputs += [f.update(sim.t, states, vectors)[0] for f in followers]
            thrusts = [k * float(np.sum(o.rotor_speeds ** 2)) for k, o in zip(k_t, outputs)]
        if on_tick is not None:
            on_tick(sim, outputs)
        if sim.finished:
            return sim
        sim.advance([o.rotor_speeds for o in outputs], [o.saturated for o in outputs])


def hover_speeds(scenario: Scenario) -> list[np.ndarray]:
    """Rotor speeds whose thrust carries each UAV and its share of the payload [rad/s]."""
    from multilift_control.cascade import balancing_rotor_speed
    share = scenario.payload.mass / scenario.n_uavs
    return [np.full(u.vehicle.n_rotors,
                    balancing_rotor_speed(u.vehicle, u.vehicle.mass + share,
                                          scenario.simulation.gravity))
            for u in scenario.uavs]
