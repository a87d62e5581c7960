"""Where a run starts and what its check reaches: the formation's initial state on the
constraint manifold (seed Algorithm 1's x_0), the UAVs' and the payload's start places, and
the constants of the check the tick runs at every state (each cable's reach, how often the
swing is sampled). World frame z up, SI units.
"""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.cables import CABLE_MODELS
from multilift_sim.dynamics import initial_state_single_lift
from multilift_sim.formation_geometry import (hanging_payload, lowest_reached,
                                              nominal_positions, swing_about_uav_axis)
from multilift_sim.formation_params import StateLayout
from multilift_sim.rigid_hang import hanging_body
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.scenario import Scenario
from multilift_sim.scenario.reorganize import starts_at_rest


def cable_reach(scenario: Scenario) -> np.ndarray:
    """How far each cable reaches for the swing's equilibrium place [m], (n,): l_i widened by
    the constraint tolerance, so cables held within it always meet."""
    tolerance = scenario.simulation.constraint_tolerance
    return np.array([math.sqrt(u.cable_length ** 2 + tolerance) for u in scenario.uavs])


def swing_sampling(n_uavs: int) -> int:
    """Every how many ticks the payload swing is sampled: every tick for one or two UAVs (a
    closed form); from three on, where rigid cables hold the payload at its equilibrium place,
    every 10th (10 Hz of a 100 Hz loop)."""
    return 1 if n_uavs <= 2 else 10


def initial_state(scenario: Scenario) -> np.ndarray:
    """Initial formation state on the constraint manifold, at rest (elastic cables: each
    stretched by its share of the hanging payload's weight, `start_lengths`); prescribed UAVs
    (`uavs[i].trajectory`) where their drives are at t = 0 with the payload hanging under
    them, and the payload where `payload.initial_position` / `initial_velocity` put it
    (`given_start`)."""
    state = hanging_start(scenario)
    payload = scenario.payload
    if scenario.prescribed or payload.initial_position is not None \
            or payload.initial_velocity is not None:
        state = given_start(scenario, state)
    if scenario.cable_model == 'chain':
        return chain_start(state, scenario.n_uavs, scenario.cable['links'],
                           uav_offsets(scenario), scenario.payload.attach_points)
    return state


def chain_start(state: np.ndarray, n: int, links: int, offsets: np.ndarray | None = None,
                payload_points=None) -> np.ndarray:
    """A point or rigid payload's state with each cable's N - 1 inner nodes appended
    (`cable_model: chain`): on the straight line from where the cable holds its UAV (its
    centre, or `offsets` (n, 3) [m] from it, world: `uav_offsets`, each UAV not turning at the
    start) to where it holds the payload (its centre, or a rigid one's `payload_points` (n, 3)
    [m], payload frame, turned by its attitude; the payload not turning at the start), node k
    at k / N of it, moving as that line's point does (the rigid cable's start)."""
    rigid = payload_points is not None
    point = StateLayout(n, rigid)
    layout = StateLayout(n, rigid, chain_nodes=links - 1)
    out = np.zeros(layout.size)
    out[:point.size] = state
    uavs, payload = point.uav_positions(state), point.payload_position(state)
    if offsets is not None:
        uavs = uavs + offsets
    ends = np.tile(payload, (n, 1))
    if rigid:
        w, x, y, z = point.payload_quaternion(state)
        rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                             [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                             [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        ends = ends + np.asarray(payload_points, dtype=float) @ rotation.T
    uav_velocities, payload_velocity = point.uav_velocities(state), point.payload_velocity(state)
    share = (np.arange(1, links) / links)[None, :, None]
    layout.chain_positions(out)[:] = uavs[:, None, :] + share * (ends - uavs)[:, None, :]
    layout.chain_velocities(out)[:] = uav_velocities[:, None, :] + share * (
        payload_velocity - uav_velocities)[:, None, :]
    return out


def given_start(scenario: Scenario, state: np.ndarray) -> np.ndarray:
    """`hanging_start`'s state with the prescribed UAVs on their drives at t = 0 (position,
    velocity, attitude, body rates: `physics.prescribed.prescribe_state`, the tick's own), the
    payload moved with them (one UAV: by its displacement, the release angles kept; more:
    hanging under their places) unless `payload.initial_position` gives it, its velocity
    `payload.initial_velocity` (else at rest)."""
    from multilift_sim import kernels
    from multilift_sim.formation_params import constant_arrays
    from multilift_sim.physics.prescribed import prescribe_state
    n = scenario.n_uavs
    layout = StateLayout(n, scenario.payload.type == 'rigid_body')
    state = state.copy()
    before = layout.uav_positions(state).copy()
    if scenario.prescribed:
        formation = constant_arrays(scenario.formation_params())[2]
        kernels.runnable(prescribe_state)(state, n, formation, 0.0)
        uavs = layout.uav_positions(state)
        if n == 1:
            layout.payload_position(state)[:] += uavs[0] - before[0]
        else:
            offsets = uav_offsets(scenario)
            _, hanging = hanging_payload(uavs.copy(), start_lengths(scenario),
                                         scenario.payload.attach_points, offsets)
            layout.payload_position(state)[:] = hanging
    given = scenario.payload
    if given.initial_position is not None:
        layout.payload_position(state)[:] = given.initial_position
    if given.initial_velocity is not None:
        layout.payload_velocity(state)[:] = given.initial_velocity
    return state


def uav_start_motion(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """Where each cable holds its UAV at t = 0 (n, 3) [m] and the UAVs' velocities (n, 3)
    [m/s], world: the UAVs' start places (prescribed ones on their drives, moving as they do;
    the others at rest) plus the attach points' offsets."""
    layout = StateLayout(scenario.n_uavs, scenario.payload.type == 'rigid_body')
    state = given_start(scenario, hanging_start(scenario))
    uavs = layout.uav_positions(state)
    offsets = uav_offsets(scenario)
    return (uavs.copy() if offsets is None else uavs + offsets,
            layout.uav_velocities(state).copy())


def hanging_start(scenario: Scenario) -> np.ndarray:
    """The seed's start: the leader at its position, the followers at the formation's places,
    the payload hanging at rest (one UAV: released at the angles alpha, beta), the UAVs level;
    a reorganising formation of a point payload (`scenario.reorganize.starts_at_rest`) the
    whole formation at rest, each UAV at the attitude of the statics (`start_attitudes`)."""
    if scenario.n_uavs == 1:
        uav = scenario.uavs[0]
        return initial_state_single_lift(np.asarray(uav.position, dtype=float),
                                         np.array([0.0, 0.0, uav.yaw]),
                                         start_lengths(scenario)[0],
                                         scenario.payload.alpha, scenario.payload.beta)
    formation = scenario.formation
    assert formation is not None
    uavs, payload = formation_start(scenario)
    if scenario.payload.swing:  # about the line through the cables' upper ends
        offsets = uav_offsets(scenario)
        ends = uavs if offsets is None else uavs + offsets
        payload = swing_about_uav_axis(payload, ends[0], ends[1], scenario.payload.swing)
    euler = (start_attitudes(scenario) if starts_at_rest(scenario)
             else np.array([[0.0, 0.0, u.yaw] for u in scenario.uavs]))
    rigid = scenario.payload.type == 'rigid_body'
    layout = StateLayout(scenario.n_uavs, rigid)
    return layout.pack(uavs, euler, payload,  # a rigid payload level but from start_places
                       payload_quaternion=start_body_pose(scenario)[1] if rigid else None)


def start_attitudes(scenario: Scenario) -> np.ndarray:
    """The UAVs' ZYX Euler angles (n, 3) [rad] at the static equilibrium of Eq. 2.73 at the
    formation's start (`start_equilibrium`). Raises ValueError naming the UAV whose rotors
    cannot hold it."""
    return start_equilibrium(scenario)[0]


def start_equilibrium(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """(ZYX Euler angles (n, 3) [rad], thrust vectors R_i e_z u_T,i (n, 3) [N], world) of the
    UAVs at the static equilibrium of Eq. 2.73 at the formation's start
    (`analysis.equilibrium.scenario_equilibrium`): each tilted so that its thrust carries its
    weight and its cable's pull, as it hovers at rest there (a level UAV whose cable pulls it
    sideways is not at rest: `scenario.reorganize.starts_at_rest`). Raises ValueError naming
    the UAV whose rotors cannot hold it."""
    from multilift_sim.analysis.equilibrium import scenario_equilibrium  # it imports this
    equilibrium = scenario_equilibrium(scenario)
    layout = StateLayout(scenario.n_uavs, scenario.payload.type == 'rigid_body')
    euler = layout.uav_euler(equilibrium.state)
    thrusts = np.array([rotation_matrix(angles)[:, 2] * wrench[0]
                        for angles, wrench in zip(euler, equilibrium.wrenches)])
    return euler, thrusts


def formation_start(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """(UAV positions (n, 3), payload position) at t = 0, world [m]: the geometry's places,
    or with `formation.start_places` the followers there, level with the leader, and the point
    payload where it hangs at rest from them (`lowest_reached`: the statics of Eq. 2.73 at
    hover, every taut cable at its length)."""
    f = scenario.formation
    if f.start_places:
        leader = np.asarray(scenario.uavs[0].position, dtype=float)
        uavs = np.tile(leader, (scenario.n_uavs, 1))
        uavs[1:, :2] += np.asarray(f.start_places, dtype=float)
        if scenario.payload.type == 'rigid_body':  # a body tilted as it hangs there
            return uavs, start_body_pose(scenario, uavs)[0]
        payload = lowest_reached(uavs, start_lengths(scenario), np.array([0.0, 0.0, -1.0]))
        if payload is None:
            raise ValueError('formation.start_places: the cables cannot all reach one point')
        return uavs, payload
    uavs = nominal_positions(f.geometry, scenario.n_uavs, scenario.uavs[0].position, f.offsets,
                             f.distance, f.half_angle)
    return hanging_payload(uavs, start_lengths(scenario), scenario.payload.attach_points,
                           uav_offsets(scenario))


def start_body_pose(scenario: Scenario, uavs: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,) [m], quaternion (w, x, y, z)) of a rigid payload at t = 0: level (the
    identity) at the geometry's places; from `formation.start_places` (UAVs `uavs` (n, 3) [m]),
    tilted where it hangs at rest (`rigid_hang.hanging_body`, issue 35)."""
    if uavs is None:
        uavs, payload = formation_start(scenario)
        if not scenario.formation.start_places:
            return payload, np.array([1.0, 0.0, 0.0, 0.0])
    return hanging_body(uavs, start_lengths(scenario), scenario.payload.attach_points)


def start_lengths(scenario: Scenario) -> np.ndarray:
    """Each cable's length at the start [m]: l_i; an elastic one (cable_model: elastic)
    stretched by T_i / k_i, T_i its share of the payload's weight hanging at rest (the statics
    sum_i T_i e_i = m_p g e_z over the unit cables e_i, solved on the unstretched hang; the
    stretch moves it by a share of k's compliance, second order)."""
    lengths = np.array([u.cable_length for u in scenario.uavs], dtype=float)
    if CABLE_MODELS[scenario.cable_model].KEEPS_LENGTH:
        return lengths
    weight = scenario.payload.mass * scenario.simulation.gravity
    if scenario.n_uavs == 1:
        tensions = np.array([weight])
    else:
        f = scenario.formation
        uavs = nominal_positions(f.geometry, scenario.n_uavs, scenario.uavs[0].position,
                                 f.offsets, f.distance, f.half_angle)
        uavs, payload = hanging_payload(uavs, lengths)
        directions = (uavs - payload) / lengths[:, None]             # e_i, (n, 3)
        tensions, *_ = np.linalg.lstsq(directions.T, [0.0, 0.0, weight], rcond=None)
    return lengths + tensions / np.array([u.cable_stiffness for u in scenario.uavs])


def uav_offsets(scenario: Scenario) -> np.ndarray | None:
    """Where each cable holds its level UAV relative to its centre at the start, R_z(yaw) a_i
    (n, 3) [m], world; None when every cable holds its UAV's centre."""
    if not any(any(u.attach_point) for u in scenario.uavs):
        return None
    out = np.empty((scenario.n_uavs, 3))
    for i, u in enumerate(scenario.uavs):
        c, s = math.cos(u.yaw), math.sin(u.yaw)
        x, y, z = u.attach_point
        out[i] = (c * x - s * y, s * x + c * y, z)
    return out
