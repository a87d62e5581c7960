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
from multilift_sim.formation_geometry import (hanging_payload, nominal_positions,
                                              swing_about_uav_axis)
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario import Scenario


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
    stretched by its share of the hanging payload's weight, `start_lengths`)."""
    if scenario.n_uavs == 1:
        uav = scenario.uavs[0]
        return initial_state_single_lift(np.asarray(uav.position, dtype=float),
                                         np.array([0.0, 0.0, uav.yaw]),
                                         start_lengths(scenario)[0],
                                         scenario.payload.alpha, scenario.payload.beta)
    formation = scenario.formation
    uavs, payload = formation_start(scenario)
    if scenario.payload.swing:  # about the line through the cables' upper ends
        offsets = uav_offsets(scenario)
        ends = uavs if offsets is None else uavs + offsets
        payload = swing_about_uav_axis(payload, ends[0], ends[1], scenario.payload.swing)
    euler = np.array([[0.0, 0.0, u.yaw] for u in scenario.uavs])
    layout = StateLayout(scenario.n_uavs, scenario.payload.type == 'rigid_body')
    assert formation is not None
    return layout.pack(uavs, euler, payload)  # a rigid payload level (the identity attitude)


def formation_start(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """(UAV positions (n, 3), payload position) at t = 0, world [m]."""
    f = scenario.formation
    uavs = nominal_positions(f.geometry, scenario.n_uavs, scenario.uavs[0].position, f.offsets,
                             f.distance, f.half_angle)
    return hanging_payload(uavs, start_lengths(scenario), scenario.payload.attach_points,
                           uav_offsets(scenario))


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
