"""Modal analysis of the formation about a static equilibrium (seed Sec. 2.8, Eq. 2.71-2.73).

World frame (z up), SI units, coordinates ``q_f`` of docs/conventions.md (6n + 3 of them); a
rigid-body payload adds its attitude as a rotation vector (below: 6n + 6 coordinates).

1. Equilibrium (Eq. 2.73 with q_dot = 0): ``f_g + G^T Lambda = B_f u_f``, ``g = 0``. Written in
   the world frame the rows are

       payload:   m_p g e_z + sum_i 2 lambda_i d_i = 0              (d_i = r_p - r_i)
       UAV i:     m_i g e_z - 2 lambda_i d_i = u_T,i R(eta_i) e_z   (B_r of Eq. 2.20)
       attitude:  0 = W^T tau_i, so tau_i = 0

   The payload rows give the multipliers (least squares, exact when the payload can hang at
   rest there), the UAV rows each UAV's thrust and its roll and pitch at the scenario's yaw, the
   allocation the rotor speeds. The UAVs are level only where their cable hangs vertically
   (n = 1): a level UAV's thrust is vertical and cannot balance a slanted cable's horizontal
   pull, so for n >= 2 Eq. 2.73 has no level solution and each UAV tilts away from the payload
   (1.57 deg in the twin_lift scenario). For n >= 4 the payload rows do not fix Lambda
   (statically indeterminate); the least-norm split is taken.
2. Linearisation, open loop: rotor speeds held at the equilibrium values, the exact
   index-reduced DAE of Eq. 2.58 (FormationModel with alpha_f = beta_f = 0) differentiated by
   central differences. Its multipliers are eliminated, not linearised: with n dependent
   coordinates q_d (the UAV altitudes by default, as the seed does for the twin-lift; usable
   while no cable is horizontal) and the constraint Jacobian G = [G_i G_d] at equilibrium,

       dq = T dq_i,   T = [I; -G_d^-1 G_i]   (rows of q_i, then of q_d; G T = 0, Eq. 2.71)

   and projecting ``M dq_ddot = dF - G^T dLambda`` with T^T (Eq. 2.72, T plays N_f) gives

       T^T M T dq_i_ddot = T^T M J_q T dq_i + T^T M J_v T dq_i_dot,

   J_q, J_v the Jacobians of the DAE's accelerations (the G^T dLambda part drops out since
   T^T G^T = 0). ``basis='nullspace'`` uses an orthonormal null-space basis N_f of G instead of
   T; the eigenvalues are the same (test_modal.py). ``hold_uavs`` clamps the UAVs' 6n
   coordinates (their rows of T zero: the cables' upper ends held still, as a bifilar
   suspension's formula assumes); T^T G^T = 0 still removes the multipliers, and what the
   cables' turning does at the equilibrium tension, -T^T (dG^T/dq) Lambda_e, stays in J_q.
3. Eigenvalues of the first-order system ``A = [[0, I], [M_r^-1 K_r, M_r^-1 D_r]]``. A free
   formation under held rotor speeds has rigid-body modes (translation of the whole formation,
   and each UAV's attitude, which nothing restores in open loop) at zero: they are reported
   apart. Purely imaginary pairs of pendulum size are the pendulum modes. Each mode is named
   by where its kinetic energy sits (`motion_shares`): the payload's swing x / y, heave, its
   roll / pitch / yaw (a rigid body), the UAVs' translation or attitude.

A rigid-body payload (docs/rigid_payload.md, "The equations"): cable i holds it at b_i
(payload frame), d_i = r_p + R_p b_i - r_i. Its attitude enters as a rotation vector theta in
the payload frame, R_p = R_e Exp(theta) (3 coordinates after q_f, not the quaternion's 4),
with rates omega_p (= theta_dot to first order at rest, so theta_ddot linearises to the DAE's
alpha_p). The equilibrium's payload rows gain the moment, ``sum_i 2 lambda_i c_i = 0`` with
c_i = b_i x R_p^T d_i (n >= 7, or cables through one point: least-norm), G the columns
``dg_i/dtheta = 2 c_i`` (U_i = 2 (d_i, c_i) of the docs), M the principal inertia J_p. The
hanging rest is the simulator's start (simulation.formation_start: level, the identity).

Cables held off the UAVs' centres (uavs[i].attach_point, a_i body FLU; docs/rigid_payload.md):
cable i starts at s_i = r_i + R_i a_i, so d_i = r_p (+ R_p b_i) - r_i - R_i a_i. The given UAV
positions place each s_i where it would be with the UAV level at its yaw, s_i = r_i +
Rz(psi_i) a_i (simulation.formation_start's convention: the simulator starts the UAVs level
there); the cables' geometry is then fixed, so the payload rows give Lambda as above. Each UAV
tilts to point its thrust along m_i g e_z - F_c,i (F_c,i = 2 lambda_i d_i, the cable's pull on
it), its centre then moves to r_i = s_i - R_i a_i at that attitude (s_i stays put), and its
rotors also cancel the pull's moment about the centre: the attitude rows read
0 = W^T (tau_i + a_i x R_i^T F_c,i), so tau_i = -a_i x R_i^T F_c,i (body FLU; the DAE's
2 lambda_i k_i, physics/free_motion.py cable_moment_arm, with the sign reversed). G gains the
columns of the UAVs' Euler angles, dg_i/deta_i = -2 d_i . d(R_i a_i)/deta_i (= -2 W_i^T k_i,
k_i = a_i x R_i^T d_i), so that T^T G^T = 0 still removes the multipliers of the DAE (which
turns the UAV by J_i^-1 2 lambda_i k_i). Attach points all zero are the seed's case exactly.

Payload drag and gusts do not enter: the quadratic drag has zero slope at zero air speed, and
the analysis is of the formation in still air.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from multilift_sim.constraints import cable_residuals, cable_tension, constraint_jacobian
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.multirotor import euler_mass_matrix
from multilift_sim.physics.layout import PAYLOAD_BODY_RATES, UAV_COORDINATES
from multilift_sim.physics.rigid_payload import payload_rotation
from multilift_sim.scenario import Scenario
from multilift_sim.start import formation_start, uav_offsets

MODE_KINDS = ('pendulum', 'oscillatory', 'unstable', 'damped', 'rigid')
ROTATION_NAMES = ('rx_p', 'ry_p', 'rz_p')  # a rigid payload's rotation vector, payload frame


@dataclass(frozen=True)
class Equilibrium:
    """A static equilibrium of the formation (seed Eq. 2.73), world frame, SI units."""

    state: np.ndarray                     # packed x_e (docs/conventions.md), rates zero
    rotor_speeds: tuple[np.ndarray, ...]  # per UAV [rad/s], rotor order of the conventions
    wrenches: np.ndarray                  # (n, 4): u_T [N], tau [N m] (FLU), from the speeds
    multipliers: np.ndarray               # Lambda_e (n,) [N/m]
    tensions: np.ndarray                  # T_i = 2 l_i lambda_i (n,) [N], positive = taut


def _quaternion_rotation(quaternion: ArrayLike) -> np.ndarray:
    """R_p (3, 3), payload frame -> world, of a unit quaternion (w, x, y, z)."""
    state = np.concatenate((np.zeros(1), np.asarray(quaternion, dtype=float)))
    return payload_rotation(state, 1)


def _cable_offsets(params: FormationParams, uavs: np.ndarray, payload: np.ndarray,
                   rotation: np.ndarray | None, uav_euler: np.ndarray | None = None
                   ) -> np.ndarray:
    """d_i (n, 3) [m], world: from UAV i's centre to where cable i holds the payload, r_p - r_i
    (a point payload) or r_p + R_p b_i - r_i (a rigid body of attitude `rotation`); with
    attach points a_i (params.uav_attach_points) and the UAVs' Euler angles `uav_euler`
    (n, 3), from r_i + R_i a_i instead."""
    if not params.rigid_payload:
        offsets = payload - uavs
    else:
        offsets = payload + np.asarray(params.payload_attach_points) @ rotation.T - uavs
    if params.uav_attach_points is not None and uav_euler is not None:
        offsets = offsets - _attach_offsets(params, uav_euler)
    return offsets


def _attach_offsets(params: FormationParams, uav_euler: np.ndarray) -> np.ndarray:
    """o_i = R_i a_i (n, 3) [m], world: each cable's upper end from its UAV's centre."""
    attach = np.asarray(params.uav_attach_points, dtype=float)
    return np.einsum('ijk,ik->ij', rotation_matrix(np.asarray(uav_euler, dtype=float)), attach)


def _attach_derivatives(euler: np.ndarray, attach: np.ndarray) -> np.ndarray:
    """d(R a)/d(phi, theta, psi) (3, 3) [m/rad], columns, of R = Rz(psi) Ry(theta) Rx(phi):
    R (e_x x a), Rz Ry (e_y x Rx a), e_z x R a."""
    phi, theta, psi = (float(v) for v in euler)
    r_x = rotation_matrix([phi, 0.0, 0.0])
    r_y = rotation_matrix([0.0, theta, 0.0])
    r_z = rotation_matrix([0.0, 0.0, psi])
    rotation = r_z @ r_y @ r_x
    return np.column_stack((rotation @ np.cross([1.0, 0.0, 0.0], attach),
                            r_z @ r_y @ np.cross([0.0, 1.0, 0.0], r_x @ attach),
                            np.cross([0.0, 0.0, 1.0], rotation @ attach)))


def _cable_moments(params: FormationParams, offsets: np.ndarray,
                   rotation: np.ndarray) -> np.ndarray:
    """c_i = b_i x R_p^T d_i (n, 3) [m^2], payload frame (docs/rigid_payload.md)."""
    return np.cross(np.asarray(params.payload_attach_points), offsets @ rotation)


def _state_rotation(layout: StateLayout, x: np.ndarray) -> np.ndarray | None:
    """A rigid payload's R_p (3, 3) at state x; None for a point payload."""
    return _quaternion_rotation(layout.payload_quaternion(x)) if layout.rigid_payload else None


def static_equilibrium(params: FormationParams, uav_positions: ArrayLike,
                       payload_position: ArrayLike, yaws: ArrayLike | None = None,
                       tolerance: float = 1e-9,
                       payload_quaternion: ArrayLike | None = None) -> Equilibrium:
    """Rotor speeds, attitudes and multipliers that hold the given configuration at rest.

    uav_positions (n, 3) and payload_position (3,) [m] in the world frame, on the constraint
    manifold (every cable at its length); yaws (n,) [rad], default 0; a rigid payload's
    attitude payload_quaternion (w, x, y, z), payload frame -> world, default the identity.
    Solves Eq. 2.73 as the module docstring says (a rigid body: its force and moment rows).
    Cables held off the UAVs' centres (params.uav_attach_points a_i): uav_positions are where
    the centres would be with the UAVs level at their yaws, the cables starting at
    r_i + Rz(psi_i) a_i; the returned state has each UAV tilted about that point (centre
    s_i - R_i a_i) and the rotors' torque cancelling the cable's moment (module docstring).
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
        uavs = uavs + _attach_offsets(params, np.column_stack((np.zeros((n, 2)), yaws)))
    quaternion = np.array([1.0, 0.0, 0.0, 0.0] if payload_quaternion is None
                          else payload_quaternion, dtype=float)
    rotation = _quaternion_rotation(quaternion) if params.rigid_payload else None
    lengths = np.asarray(params.cable_lengths)
    if params.rigid_payload:
        offsets = _cable_offsets(params, uavs, payload, rotation)
        residual = (np.einsum('ij,ij->i', offsets, offsets) - lengths ** 2) / lengths ** 2
    else:
        residual = cable_residuals(uavs, payload, lengths) / lengths ** 2
    worst = int(np.argmax(np.abs(residual)))
    if abs(residual[worst]) > tolerance:
        raise ValueError(f'cable {worst + 1}: |d_i|^2 differs from l_i^2 by a fraction '
                         f'{residual[worst]:.3g}: not on the constraint manifold (Eq. 2.42)')
    offsets = _cable_offsets(params, uavs, payload, rotation)          # d_i, (n, 3)
    weight = np.array([0.0, 0.0, params.payload_mass * params.gravity])
    if params.rigid_payload:
        # payload rows, force and moment: 2 [D^T; C^T] Lambda = (-m_p g e_z, 0), least-norm
        moments = _cable_moments(params, offsets, rotation)
        rows = 2.0 * np.vstack((offsets.T, moments.T))
        multipliers, *_ = np.linalg.lstsq(rows, np.concatenate((-weight, np.zeros(3))),
                                          rcond=None)
        miss = rows @ multipliers + np.concatenate((weight, np.zeros(3)))
        arm = max(1e-3, float(np.abs(params.payload_attach_points).max()))
        if float(np.linalg.norm(miss[3:])) > tolerance * weight[2] * arm:
            raise ValueError(f'the body cannot hang at rest in this attitude: its cables leave '
                             f'{np.linalg.norm(miss[3:]):.3g} N m of moment unbalanced '
                             '(docs/rigid_payload.md)')
        miss = float(np.linalg.norm(miss[:3]))
    else:
        # payload rows: (2 D^T) Lambda = -m_p g e_z, least-norm when indeterminate (n >= 4)
        multipliers, *_ = np.linalg.lstsq(2.0 * offsets.T, -weight, rcond=None)
        miss = float(np.linalg.norm(2.0 * offsets.T @ multipliers + weight))
    if miss > tolerance * weight[2]:
        raise ValueError(f'the payload cannot hang at rest at {payload.tolist()} m: its cables '
                         f'leave {miss:.3g} N of its weight unbalanced (Eq. 2.73)')
    for i, multiplier in enumerate(multipliers):
        if multiplier <= 0.0:
            raise ValueError(f'cable {i + 1}: the equilibrium multiplier is {multiplier:.3g} '
                             'N/m: the cable would be slack or in compression')
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
        uavs = uavs - _attach_offsets(params, euler)
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
    UAVs at the scenario's yaw angles, a rigid payload level (the simulator's start)."""
    uavs, payload = scenario_configuration(scenario)
    return static_equilibrium(scenario.formation_params(0.0, 0.0), uavs, payload,
                              [u.yaw for u in scenario.uavs])


def coordinate_names(n_uavs: int, rigid_payload: bool = False) -> tuple[str, ...]:
    """Names of the 6n + 3 coordinates q_f: x1 y1 z1 phi1 theta1 psi1 ... x_p y_p z_p, and a
    rigid payload's rotation vector rx_p ry_p rz_p [rad] (payload frame) after them."""
    names = [f'{c}{i + 1}' for i in range(n_uavs)
             for c in ('x', 'y', 'z', 'phi', 'theta', 'psi')]
    return tuple(names + ['x_p', 'y_p', 'z_p'] + (list(ROTATION_NAMES) if rigid_payload else []))


def mass_matrix(params: FormationParams, uav_euler: ArrayLike) -> np.ndarray:
    """Formation inertia M_f (Eq. 2.47): blocks m_i I, M_eta,i = W^T J W (Eq. 2.24), m_p I;
    a rigid payload's J_p = diag(J_xx, J_yy, J_zz) [kg m^2] (payload frame) after them."""
    n = params.n_uavs
    euler = np.asarray(uav_euler, dtype=float).reshape(n, 3)
    size = 6 * n + (6 if params.rigid_payload else 3)
    mass = np.zeros((size, size))
    for i, uav in enumerate(params.uavs):
        mass[6 * i:6 * i + 3, 6 * i:6 * i + 3] = uav.mass * np.eye(3)
        mass[6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = euler_mass_matrix(uav.inertia, euler[i])
    mass[6 * n:6 * n + 3, 6 * n:6 * n + 3] = params.payload_mass * np.eye(3)
    if params.rigid_payload:
        mass[6 * n + 3:, 6 * n + 3:] = np.diag(params.payload_inertia)
    return mass


def formation_jacobian(params: FormationParams, x: np.ndarray) -> np.ndarray:
    """G [m] (n, 6n + 3) at state x (Eq. 2.65-2.67, constraints.constraint_jacobian); a rigid
    payload's (n, 6n + 6) with the columns dg_i/dtheta = 2 c_i [m^2] of its rotation vector
    (R_p = R Exp(theta), c_i = b_i x R^T d_i at x's attitude R; docs/rigid_payload.md).
    Cables held off the UAVs' centres: d_i from r_i + R_i a_i, and the UAVs' Euler columns
    dg_i/deta_i = -2 d_i . d(R_i a_i)/deta_i [m^2/rad] (module docstring)."""
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    attached = params.uav_attach_points is not None
    if not params.rigid_payload and not attached:
        return constraint_jacobian(uavs, payload)
    n = params.n_uavs
    rotation = _state_rotation(layout, x)
    euler = layout.uav_euler(x)
    offsets = _cable_offsets(params, uavs, payload, rotation, euler)
    jacobian = np.zeros((n, 6 * n + (6 if params.rigid_payload else 3)))
    for i in range(n):
        jacobian[i, 6 * i:6 * i + 3] = -2.0 * offsets[i]
        jacobian[i, 6 * n:6 * n + 3] = 2.0 * offsets[i]
        if attached:
            jacobian[i, 6 * i + 3:6 * i + 6] = -2.0 * offsets[i] @ _attach_derivatives(
                euler[i], np.asarray(params.uav_attach_points[i], dtype=float))
    if params.rigid_payload:
        jacobian[:, 6 * n + 3:] = 2.0 * _cable_moments(params, offsets, rotation)
    return jacobian


def formation_residuals(params: FormationParams, x: np.ndarray) -> np.ndarray:
    """g_i = |d_i|^2 - l_i^2 [m^2] (n,) at state x (Eq. 2.42; a rigid payload's d_i, and from
    the UAVs' attach points r_i + R_i a_i when params.uav_attach_points)."""
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    if not params.rigid_payload and params.uav_attach_points is None:
        return cable_residuals(uavs, payload, params.cable_lengths)
    offsets = _cable_offsets(params, uavs, payload, _state_rotation(layout, x),
                             layout.uav_euler(x))
    return np.einsum('ij,ij->i', offsets, offsets) - np.asarray(params.cable_lengths) ** 2


def displaced_state(layout: StateLayout, x: np.ndarray, dq: np.ndarray,
                    dq_dot: np.ndarray) -> np.ndarray:
    """The packed state x moved by dq (q_f [m, rad], a rigid payload's rotation vector theta
    [rad], payload frame, after it) and dq_dot (q_f_dot [m/s, rad/s], then omega_p [rad/s]):
    x + (dq, dq_dot) for a point payload; a rigid one's attitude q (x) Exp(theta) (a body-frame
    rotation, the quaternion kept unit) and body rates omega_p + dq_dot's last three."""
    if not layout.rigid_payload:
        return x + np.concatenate((dq, dq_dot))
    nq = layout.n_coordinates
    out = np.array(x, dtype=float)
    out[:nq] += dq[:nq]
    out[nq:2 * nq] += dq_dot[:nq]
    theta = np.asarray(dq[nq:nq + 3], dtype=float)
    angle = float(np.linalg.norm(theta))
    w, v = layout.payload_quaternion(x)[0], layout.payload_quaternion(x)[1:]
    turn_w = math.cos(0.5 * angle)
    turn_v = theta * (0.5 if angle == 0.0 else math.sin(0.5 * angle) / angle)
    layout.payload_quaternion(out)[:] = np.concatenate((
        [w * turn_w - v @ turn_v], w * turn_v + turn_w * v + np.cross(v, turn_v)))
    layout.payload_body_rates(out)[:] += dq_dot[nq:nq + 3]
    return out


def default_dependent_coordinates(jacobian: np.ndarray,
                                  held: tuple[int, ...] = ()) -> tuple[int, ...]:
    """n dependent coordinates where G restricted to them has full rank.

    The UAV altitudes z_i (the seed's choice for the twin-lift, Sec. 2.8.2), whose block of G
    is diag(-2 (z_p - z_i)): fine unless a cable is (nearly) horizontal; then, or when the
    coordinates `held` (clamped, not free) include them, the first n pivots of a
    column-pivoted QR of G over the free coordinates.
    """
    n = jacobian.shape[0]
    altitudes = tuple(UAV_COORDINATES * i + 2 for i in range(n))
    rows = np.linalg.norm(jacobian, axis=1)                     # 2 l_i on the manifold
    if not held and np.min(np.abs(jacobian[np.arange(n), altitudes]) / rows) > 1e-3:
        return altitudes
    free = [k for k in range(jacobian.shape[1]) if k not in held]
    _, _, pivots = scipy.linalg.qr(jacobian[:, free], pivoting=True)
    return tuple(sorted(free[int(k)] for k in pivots[:n]))


def elimination_basis(jacobian: np.ndarray, dependent: tuple[int, ...],
                      held: tuple[int, ...] = ()) -> tuple[np.ndarray, tuple[int, ...]]:
    """(T (size, size - n - len(held)), independent indices): ``dq = T dq_i`` solves
    ``G dq = 0`` to first order with ``dq_d = -G_d^-1 G_i dq_i``, the coordinates `held`
    clamped (their rows of T zero). Raises ValueError when G_d is singular."""
    n, size = jacobian.shape
    dependent = tuple(int(k) for k in dependent)
    if len(set(dependent)) != n or not all(0 <= k < size and k not in held for k in dependent):
        raise ValueError(f'need {n} distinct dependent coordinates in 0..{size - 1}, none held, '
                         f'got {dependent}')
    independent = tuple(k for k in range(size) if k not in dependent and k not in held)
    block = jacobian[:, dependent]
    if np.linalg.cond(block) > 1e10:
        raise ValueError(f'G restricted to the dependent coordinates {dependent} is singular')
    basis = np.zeros((size, len(independent)))
    basis[independent, np.arange(len(independent))] = 1.0
    basis[list(dependent)] = -np.linalg.solve(block, jacobian[:, independent])
    return basis, independent


@dataclass(frozen=True)
class ModalAnalysis:
    """Linearised open-loop formation about an equilibrium and its eigen-decomposition.

    Eigenvalues [1/s] are sorted: non-rigid modes by decreasing |Im| then |Re| (conjugates
    adjacent, positive imaginary part first), rigid-body (zero) modes last. ``shapes[k]`` is
    mode k's shape in all 6n + 3 coordinates q_f ([m] and [rad], complex; a rigid payload's
    rotation vector [rad], payload frame, after them: 6n + 6), scaled so that its largest
    component is 1.
    """

    params: FormationParams
    equilibrium: Equilibrium
    basis_kind: str                   # 'elimination' or 'nullspace'
    dependent: tuple[int, ...]        # indices into q_f ('elimination'); () for 'nullspace'
    basis: np.ndarray                 # T (or N_f), (6n+3, 5n+3); rigid (6n+6, 5n+6)
    mass: np.ndarray                  # M_r = T^T M T
    stiffness: np.ndarray             # K_r = T^T M J_q T: M_r dq_i_ddot = K_r dq_i + D_r dq_i_dot
    damping: np.ndarray               # D_r = T^T M J_v T (zero: nothing damps at rest)
    state_matrix: np.ndarray          # A, (2(5n+3), 2(5n+3))
    eigenvalues: np.ndarray           # (2(5n+3),) complex [1/s]
    shapes: np.ndarray                # (2(5n+3), 6n+3) complex
    kinds: tuple[str, ...]            # one of MODE_KINDS per eigenvalue
    zero_tolerance: float             # |lambda| below this is a rigid-body mode [1/s]
    inertia: np.ndarray               # M at the equilibrium (6n+3 or 6n+6 square) [kg, kg m^2]
    held_uavs: bool                   # the UAVs' coordinates clamped (modal_analysis hold_uavs)

    def indices(self, kind: str) -> np.ndarray:
        """Indices of the eigenvalues of one kind (MODE_KINDS)."""
        return np.array([k for k, c in enumerate(self.kinds) if c == kind], dtype=int)

    @property
    def pendulum_modes(self) -> np.ndarray:
        """Indices of the pendulum modes with positive imaginary part (one per pair)."""
        return np.array([k for k in self.indices('pendulum') if self.eigenvalues[k].imag > 0],
                        dtype=int)

    @property
    def pendulum_periods(self) -> np.ndarray:
        """Periods 2 pi / omega [s] of the pendulum pairs, fastest first (repeats kept)."""
        return 2.0 * np.pi / self.eigenvalues[self.pendulum_modes].imag

    @property
    def rigid_count(self) -> int:
        """Number of zero (rigid-body) eigenvalues."""
        return len(self.indices('rigid'))

    def motion(self, mode: int, least: float = 0.05, most: int = 3) -> str:
        """Mode `mode` named by where its kinetic energy sits (motion_shares): the `most`
        largest shares of at least `least`, e.g. 'yaw 0.99' or 'UAVs 0.57, swing y 0.30,
        roll 0.13'."""
        shares = sorted(motion_shares(self, mode).items(), key=lambda item: -item[1])
        kept = [item for item in shares[:most] if item[1] >= least] or shares[:1]
        return ', '.join(f'{name} {share:.2f}' for name, share in kept)


def motion_groups(n_uavs: int, rigid_payload: bool) -> dict[str, list[int]]:
    """The coordinates (indices into q_f, a rigid payload's rotation after it) of each motion
    a mode is named by: the payload's swing x, swing y (world), heave (z); a rigid payload's
    roll, pitch, yaw (its rotation about its own x, y, z axes); the UAVs' translation and
    attitude (all UAVs together)."""
    p = UAV_COORDINATES * n_uavs
    groups = {'swing x': [p], 'swing y': [p + 1], 'heave': [p + 2]}
    if rigid_payload:
        groups.update({'roll': [p + 3], 'pitch': [p + 4], 'yaw': [p + 5]})
    groups['UAVs'] = [UAV_COORDINATES * i + k for i in range(n_uavs) for k in range(3)]
    groups['UAV attitudes'] = [UAV_COORDINATES * i + k for i in range(n_uavs) for k in (3, 4, 5)]
    return groups


def motion_shares(analysis: ModalAnalysis, mode: int) -> dict[str, float]:
    """Each motion's share (motion_groups) of mode `mode`'s kinetic energy, sum 1:
    Re(v_g^H M_gg v_g) / Re(v^H M v) with v the shape and M the formation's inertia at the
    equilibrium (block-diagonal over the groups, so the shares add up; unit-free, unlike the
    shape's components in m and rad)."""
    shape = analysis.shapes[mode]
    inertia = analysis.inertia
    groups = motion_groups(analysis.params.n_uavs, analysis.params.rigid_payload)
    energy = {name: float(np.real(np.conj(shape[k]) @ inertia[np.ix_(k, k)] @ shape[k]))
              for name, k in groups.items()}
    total = sum(energy.values())
    return {name: value / total for name, value in energy.items()}


def modal_analysis(params: FormationParams, equilibrium: Equilibrium,
                   dependent: tuple[int, ...] | None = None, basis: str = 'elimination',
                   zero_tolerance: float = 1e-4, imaginary_tolerance: float = 1e-6,
                   position_step: float = 1e-5, rate_step: float = 1e-3,
                   hold_uavs: bool = False) -> ModalAnalysis:
    """Linearise the open-loop formation about `equilibrium` and find its modes.

    dependent: indices into q_f (a rigid payload: and its rotation vector) of the n eliminated
    coordinates (default: the UAV altitudes, see default_dependent_coordinates); basis:
    'elimination' (T of the module docstring) or 'nullspace' (orthonormal N_f, Eq. 2.71).
    hold_uavs: the UAVs' 6n coordinates clamped (the cables' upper ends held still; only the
    payload moves). zero_tolerance [1/s]: smaller |lambda| are rigid-body modes; a pair is
    purely imaginary when |Re| <= imaginary_tolerance |lambda|, and a pendulum mode when also
    0.1 sqrt(g / l_max) <= |omega| <= 10 sqrt(g / l_min) (pendulum size; 'oscillatory'
    otherwise). position_step [m or rad] and rate_step [m/s or rad/s]: central-difference steps
    (the accelerations are even in the rates at rest, so rate_step only meets rounding).
    """
    if basis not in ('elimination', 'nullspace'):
        raise ValueError(f"basis must be 'elimination' or 'nullspace', got {basis!r}")
    # still air, exact index-reduced DAE: drag (zero slope at rest) and gusts out, no Baumgarte
    still = dataclasses.replace(params, gusts=(), payload_drag_coefficient=0.0,
                                baumgarte_alpha=0.0, baumgarte_beta=0.0)
    model = FormationModel(still)
    layout = model.layout
    nq = layout.n_coordinates
    x_e = np.asarray(equilibrium.state, dtype=float)
    jacobian = formation_jacobian(still, x_e)
    size = jacobian.shape[1]                     # 6n + 3, a rigid payload's 6n + 6
    held = tuple(range(UAV_COORDINATES * params.n_uavs)) if hold_uavs else ()
    if basis == 'elimination':
        dependent = (default_dependent_coordinates(jacobian, held) if dependent is None
                     else tuple(dependent))
        transform, _ = elimination_basis(jacobian, dependent, held)
    else:
        dependent = ()
        free = [k for k in range(size) if k not in held]
        transform = np.zeros((size, len(free) - params.n_uavs))
        transform[free] = scipy.linalg.null_space(jacobian[:, free] if held else jacobian)
    n_free = transform.shape[1]

    def acceleration(dq: np.ndarray, dq_dot: np.ndarray) -> np.ndarray:
        """q_ddot (and a rigid payload's alpha_p [rad/s^2], = theta_ddot at rest) at x_e
        moved by (dq, dq_dot) (displaced_state)."""
        acc = model.accelerations_from_wrenches(displaced_state(layout, x_e, dq, dq_dot),
                                                equilibrium.wrenches)[0]
        if not layout.rigid_payload:
            return acc
        return np.concatenate((acc[:nq], acc[nq + PAYLOAD_BODY_RATES:nq + PAYLOAD_BODY_RATES + 3]))

    still_rates = np.zeros(size)
    j_q = np.empty((size, n_free))
    j_v = np.empty((size, n_free))
    for k in range(n_free):
        direction = transform[:, k]
        h = position_step / max(1.0, float(np.linalg.norm(direction)))
        j_q[:, k] = (acceleration(h * direction, still_rates)
                     - acceleration(-(h * direction), still_rates)) / (2.0 * h)
        h = rate_step / max(1.0, float(np.linalg.norm(direction)))
        j_v[:, k] = (acceleration(still_rates, h * direction)
                     - acceleration(still_rates, -(h * direction))) / (2.0 * h)
    inertia = mass_matrix(still, layout.uav_euler(x_e))
    mass = transform.T @ inertia @ transform                         # Eq. 2.72, left side
    stiffness = transform.T @ inertia @ j_q
    damping = transform.T @ inertia @ j_v
    state_matrix = np.block([[np.zeros((n_free, n_free)), np.eye(n_free)],
                             [np.linalg.solve(mass, stiffness), np.linalg.solve(mass, damping)]])
    eigenvalues, vectors = np.linalg.eig(state_matrix)

    lengths = np.asarray(still.cable_lengths)
    band = (0.1 * math.sqrt(still.gravity / lengths.max()),
            10.0 * math.sqrt(still.gravity / lengths.min()))
    kinds = [_kind(value, zero_tolerance, imaginary_tolerance, band) for value in eigenvalues]
    rank = {kind: r for r, kind in enumerate(MODE_KINDS)}
    order = sorted(range(eigenvalues.size), key=lambda k: (
        kinds[k] == 'rigid', -round(abs(eigenvalues[k].imag), 9),
        -round(abs(eigenvalues[k].real), 9), rank[kinds[k]], -eigenvalues[k].imag))
    eigenvalues, kinds = eigenvalues[order], [kinds[k] for k in order]
    shapes = (transform @ vectors[:n_free, order]).T
    for shape in shapes:
        shape /= shape[np.argmax(np.abs(shape))]
    if np.abs(damping).max() <= 1e-9 * max(1.0, np.abs(stiffness).max()):
        _real_shapes(eigenvalues, kinds, shapes, np.linalg.solve(mass, stiffness), transform)
    return ModalAnalysis(params=params, equilibrium=equilibrium, basis_kind=basis,
                         dependent=tuple(dependent), basis=transform, mass=mass,
                         stiffness=stiffness, damping=damping, state_matrix=state_matrix,
                         eigenvalues=eigenvalues, shapes=shapes, kinds=tuple(kinds),
                         zero_tolerance=zero_tolerance, inertia=inertia, held_uavs=hold_uavs)


def _real_shapes(eigenvalues: np.ndarray, kinds: list[str], shapes: np.ndarray,
                 reduced_stiffness: np.ndarray, transform: np.ndarray) -> None:
    """Real mode shapes for the purely imaginary eigenvalues of an undamped system.

    Without damping a pair +/- j omega has the real shapes v of ``(M_r^-1 K_r + omega^2 I) v
    = 0``. eig returns an arbitrary complex basis when omega is repeated (the single-lift's x
    and y swings), so each group of equal omega gets its real null space, in the basis whose
    vectors are 1 at one coordinate of q_f and 0 at the others' (pivoted QR picks them).
    Overwrites `shapes` in place.
    """
    size = reduced_stiffness.shape[0]
    done: set[int] = set()
    for k, value in enumerate(eigenvalues):
        if k in done or kinds[k] not in ('pendulum', 'oscillatory') or value.imag <= 0:
            continue
        omega = value.imag
        group = [j for j, other in enumerate(eigenvalues)
                 if kinds[j] == kinds[k] and abs(abs(other.imag) - omega) <= 1e-6 * omega]
        upper = [j for j in group if eigenvalues[j].imag > 0]
        _, _, right = np.linalg.svd(reduced_stiffness + omega ** 2 * np.eye(size))
        basis = transform @ right[size - len(upper):].T                   # (6n+3, m), real
        _, _, pivots = scipy.linalg.qr(basis.T, pivoting=True)
        basis = basis @ np.linalg.inv(basis[pivots[:len(upper)]])
        basis /= basis[np.argmax(np.abs(basis), axis=0), np.arange(len(upper))]
        for column, j in enumerate(upper):
            conjugate = [c for c in group if c not in upper]
            shapes[j] = basis[:, column]
            if column < len(conjugate):
                shapes[conjugate[column]] = basis[:, column]
        done.update(group)


def _kind(value: complex, zero_tolerance: float, imaginary_tolerance: float,
          band: tuple[float, float]) -> str:
    if abs(value) < zero_tolerance:
        return 'rigid'
    if abs(value.real) <= imaginary_tolerance * abs(value):
        return 'pendulum' if band[0] <= abs(value.imag) <= band[1] else 'oscillatory'
    return 'unstable' if value.real > 0 else 'damped'


def scenario_modal_analysis(scenario: Scenario, **options: Any) -> ModalAnalysis:
    """modal_analysis of a scenario's formation at its static equilibrium (Eq. 2.73)."""
    return modal_analysis(scenario.formation_params(0.0, 0.0), scenario_equilibrium(scenario),
                          **options)


def mode_state(analysis: ModalAnalysis, mode: int, amplitude: float,
               iterations: int = 20) -> np.ndarray:
    """A state at rest displaced along mode `mode`'s (real) shape, back on the manifold.

    The coordinates move by ``amplitude * Re(shape)`` (largest component = amplitude [m or
    rad]; a rigid payload's rotation vector turns its attitude, displaced_state); then
    least-norm Newton steps ``dq = -G^+ g`` (over the free coordinates when the UAVs are held)
    put every cable at its length (a second-order correction). Velocities are zero. Returns
    the packed state.
    """
    params = analysis.params
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    x = np.array(analysis.equilibrium.state, dtype=float)
    size = analysis.shapes.shape[1]
    still = np.zeros(size)
    x = displaced_state(layout, x, amplitude * analysis.shapes[mode].real, still)
    lengths = np.asarray(params.cable_lengths)
    free = np.ones(size, dtype=bool)
    free[:UAV_COORDINATES * params.n_uavs] = not analysis.held_uavs
    for _ in range(iterations):
        residual = formation_residuals(params, x)
        if np.max(np.abs(residual) / lengths ** 2) < 1e-15:
            break
        jacobian = formation_jacobian(params, x)
        step = np.zeros(size)
        step[free] = np.linalg.pinv(jacobian[:, free]) @ residual
        x = displaced_state(layout, x, -step, still)
    return x
