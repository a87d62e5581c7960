"""The static equilibrium of the formation (seed Eq. 2.73 with q_dot = 0): the rotor speeds,
attitudes and multipliers that hold a configuration at rest, and a scenario's hanging rest.
World frame (z up), SI units; the rows solved are step 1 of the package docstring
(multilift_sim/analysis/__init__.py), a rigid-body payload's and attach points' included.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.analysis.coordinates import (attach_offsets, cable_moments, cable_offsets,
                                                quaternion_rotation)
from multilift_sim.constraints import cable_residuals, cable_tension
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.scenario import Scenario
from multilift_sim.start import formation_start, start_body_pose, uav_offsets


@dataclass(frozen=True)
class Equilibrium:
    """A static equilibrium of the formation (seed Eq. 2.73), world frame, SI units."""

    state: np.ndarray                     # packed x_e (docs/conventions.md), rates zero
    rotor_speeds: tuple[np.ndarray, ...]  # per UAV [rad/s], rotor order of the conventions
    wrenches: np.ndarray                  # (n, 4): u_T [N], tau [N m] (FLU), from the speeds
    multipliers: np.ndarray               # Lambda_e (n,) [N/m]
    tensions: np.ndarray                  # T_i = 2 l_i lambda_i (n,) [N], positive = taut


def static_equilibrium(params: FormationParams, uav_positions: ArrayLike,
                       payload_position: ArrayLike, yaws: ArrayLike | None = None,
                       tolerance: float = 1e-9,
                       payload_quaternion: ArrayLike | None = None) -> Equilibrium:
    """Rotor speeds, attitudes and multipliers that hold the given configuration at rest.

    uav_positions (n, 3) and payload_position (3,) [m] in the world frame, on the constraint
    manifold (every cable at its length); yaws (n,) [rad], default 0; a rigid payload's
    attitude payload_quaternion (w, x, y, z), payload frame -> world, default the identity.
    Solves Eq. 2.73 as the package docstring says (a rigid body: its force and moment rows).
    Cables held off the UAVs' centres (params.uav_attach_points a_i): uav_positions are where
    the centres would be with the UAVs level at their yaws, the cables starting at
    r_i + Rz(psi_i) a_i; the returned state has each UAV tilted about that point (centre
    s_i - R_i a_i) and the rotors' torque cancelling the cable's moment (package docstring).
    Raises ValueError naming the cable or UAV when the payload cannot hang at rest there, a
    cable would be slack, or a rotor would leave its speed limits.
    """
    n = params.n_uavs
    uavs = np.asarray(uav_positions, dtype=float).reshape(n, 3)
    payload = np.asarray(payload_position, dtype=float).reshape(3)
    yaws = np.zeros(n) if yaws is None else np.asarray(yaws, dtype=float).reshape(n)
    attach = (None if params.uav_attach_points is None
              else np.asarray(params.uav_attach_points, dtype=float).reshape(n, 3))
    if attach is not None:  # the cables' upper ends s_i, the UAVs level at their yaws
        uavs = uavs + attach_offsets(params, np.column_stack((np.zeros((n, 2)), yaws)))
    quaternion = np.array([1.0, 0.0, 0.0, 0.0] if payload_quaternion is None
                          else payload_quaternion, dtype=float)
    rotation = quaternion_rotation(quaternion) if params.rigid_payload else None
    lengths = np.asarray(params.cable_lengths)
    if params.rigid_payload:
        offsets = cable_offsets(params, uavs, payload, rotation)
        residual = (np.einsum('ij,ij->i', offsets, offsets) - lengths ** 2) / lengths ** 2
    else:
        residual = cable_residuals(uavs, payload, lengths) / lengths ** 2
    worst = int(np.argmax(np.abs(residual)))
    if abs(residual[worst]) > tolerance:
        raise ValueError(f'cable {worst + 1}: |d_i|^2 differs from l_i^2 by a fraction '
                         f'{residual[worst]:.3g}: not on the constraint manifold (Eq. 2.42)')
    offsets = cable_offsets(params, uavs, payload, rotation)          # d_i, (n, 3)
    multipliers = payload_multipliers(
        params, offsets, rotation, np.array([0.0, 0.0, params.payload_mass * params.gravity]),
        tolerance, payload)
    euler = np.zeros((n, 3))
    rotor_speeds = []
    wrenches = np.zeros((n, 4))
    for i, uav in enumerate(params.uavs):
        # UAV rows: the rotors carry the UAV's weight and the cable's pull 2 lambda_i d_i
        force = uav.mass * params.gravity * np.array([0.0, 0.0, 1.0]) \
            - 2.0 * multipliers[i] * offsets[i]
        thrust = float(np.linalg.norm(force))
        # R e_z = force / thrust at yaw psi (seed Eq. 2.6, as cascade.attitude_from_force, which
        # multilift_sim must not import): rotate by -psi, then roll = asin(-b), pitch = atan2(a, c)
        s_psi, c_psi = math.sin(yaws[i]), math.cos(yaws[i])
        a = (c_psi * force[0] + s_psi * force[1]) / thrust
        b = (-s_psi * force[0] + c_psi * force[1]) / thrust
        euler[i] = math.asin(-b), math.atan2(a, force[2] / thrust), yaws[i]
        torque = np.zeros(3)
        if attach is not None:  # the rotors cancel the pull's moment about the centre
            pull = 2.0 * multipliers[i] * offsets[i]
            torque = -np.cross(attach[i], rotation_matrix(euler[i]).T @ pull)
        allocator = uav.allocator()
        speeds, saturated = allocator.rotor_speeds([thrust, *torque],
                                                   uav.rotor_speed_min, uav.rotor_speed_max)
        if np.any(saturated):
            moment = '' if attach is None else f' and torque {np.linalg.norm(torque):.3g} N m'
            raise ValueError(f'uav{i + 1}: the equilibrium thrust {thrust:.2f} N{moment} needs '
                             f'rotor speeds outside [{uav.rotor_speed_min:g}, '
                             f'{uav.rotor_speed_max:g}] rad/s')
        rotor_speeds.append(speeds)
        wrenches[i] = allocator.wrench(speeds)
    if attach is not None:  # each centre where its tilted UAV holds s_i
        uavs = uavs - attach_offsets(params, euler)
    if params.rigid_payload:
        state = StateLayout(n, True).pack(uavs, euler, payload, payload_quaternion=quaternion)
    else:
        state = StateLayout(n).pack(uavs, euler, payload)
    return Equilibrium(state=state, rotor_speeds=tuple(rotor_speeds), wrenches=wrenches,
                       multipliers=multipliers, tensions=cable_tension(multipliers, lengths))


def scenario_configuration(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """(UAV positions (n, 3), payload position (3,)) [m] of the scenario's hanging rest.

    n = 1: the scenario's UAV position with the payload straight below (alpha = beta = 0; the
    release angles of payload.alpha_deg/beta_deg are an initial condition, not the
    equilibrium). n >= 2: simulation.formation_start (the payload under the UAVs' horizontal
    centroid, where equal multipliers balance it; a rigid body level, its centre under the
    centroid of r_i - b_i), without the payload.swing_deg release. Cables held off the UAVs'
    centres (uavs[i].attach_point): the UAVs level at their yaws, each cable from
    r_i + Rz(psi_i) a_i (simulation.uav_offsets), as static_equilibrium reads them.
    """
    if scenario.n_uavs == 1:
        uav = np.array([scenario.uavs[0].position], dtype=float)
        offsets = uav_offsets(scenario)         # a cable held off the level UAV's centre
        end = uav[0] if offsets is None else uav[0] + offsets[0]
        return uav, end - np.array([0.0, 0.0, scenario.uavs[0].cable_length])
    return formation_start(scenario)


def scenario_equilibrium(scenario: Scenario) -> Equilibrium:
    """The static equilibrium (Eq. 2.73) of the scenario's formation at its hanging rest,
    UAVs at the scenario's yaw angles, a rigid payload level, or tilted as it hangs from
    `formation.start_places` (the simulator's start, `start.start_body_pose`)."""
    uavs, payload = scenario_configuration(scenario)
    tilted = scenario.payload.type == 'rigid_body' and scenario.n_uavs > 1
    return static_equilibrium(scenario.formation_params(0.0, 0.0), uavs, payload,
                              [u.yaw for u in scenario.uavs], payload_quaternion=(
                                  start_body_pose(scenario)[1] if tilted else None))


def payload_multipliers(params: FormationParams, offsets: np.ndarray,
                        rotation: np.ndarray | None, load: np.ndarray,
                        tolerance: float = 1e-9, payload: ArrayLike | None = None) -> np.ndarray:
    """Lambda (n,) [N/m] of the payload's rows of Eq. 2.73: the cables (offsets d_i (n, 3) [m],
    world) hold the payload against `load` [N], world, the force its support must give (at
    rest its weight m_p g e_z; moving at acceleration a, m_p (g e_z + a) less its drag), a
    rigid body (attitude `rotation`) also with no moment. Least-norm where indeterminate
    (n >= 4). Raises ValueError when the cables leave part of the load (or a moment)
    unbalanced, or one would be slack or in compression."""
    weight = float(np.linalg.norm(load))
    where = '' if payload is None else f' at {np.asarray(payload).tolist()} m'
    if params.rigid_payload:
        # force and moment rows: 2 [D^T; C^T] Lambda = (-load, 0), least-norm
        moments = cable_moments(params, offsets, rotation)
        rows = 2.0 * np.vstack((offsets.T, moments.T))
        multipliers, *_ = np.linalg.lstsq(rows, np.concatenate((-load, np.zeros(3))),
                                          rcond=None)
        miss = rows @ multipliers + np.concatenate((load, np.zeros(3)))
        arm = max(1e-3, float(np.abs(params.payload_attach_points).max()))
        if float(np.linalg.norm(miss[3:])) > tolerance * weight * arm:
            raise ValueError(f'the body cannot hang at rest in this attitude: its cables leave '
                             f'{np.linalg.norm(miss[3:]):.3g} N m of moment unbalanced '
                             '(docs/rigid_payload.md)')
        miss = float(np.linalg.norm(miss[:3]))
    else:
        # (2 D^T) Lambda = -load
        multipliers, *_ = np.linalg.lstsq(2.0 * offsets.T, -load, rcond=None)
        miss = float(np.linalg.norm(2.0 * offsets.T @ multipliers + load))
    if miss > tolerance * weight:
        raise ValueError(f'the payload cannot hang at rest{where}: its cables leave {miss:.3g} '
                         'N of its load unbalanced (Eq. 2.73)')
    for i, multiplier in enumerate(multipliers):
        if multiplier <= 0.0:
            raise ValueError(f'cable {i + 1}: the equilibrium multiplier is {multiplier:.3g} '
                             'N/m: the cable would be slack or in compression')
    return multipliers
