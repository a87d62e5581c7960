"""The formation's coordinates q_f at rest, for its analysis (seed Eq. 2.42, 2.47, 2.65-2.67):
their names, the inertia M_f, the constraint residuals g and Jacobian G, a packed state moved
by (dq, dq_dot) and its accelerations in q_f. World frame (z up), SI units. q_f is the seed's
minimal coordinates (Eq. 2.41, `physics.layout` SEED_*: per UAV r_i and its ZYX angles eta_i,
then r_p: 6n + 3; a rigid-body payload's rotation vector after them: 6n + 6), which the state
(translations, then each body's quaternion and body rates) maps to and from here; the
derivation is in the package docstring (multilift_sim/analysis/__init__.py).
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.constraints import cable_residuals, constraint_jacobian
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.kinematics import (euler_rate_matrix, euler_rate_matrix_dot,
                                      euler_rate_matrix_inverse, rotation_matrix)
from multilift_sim.multirotor import euler_mass_matrix
from multilift_sim.physics import attitude
from multilift_sim.physics.layout import (BODY_RATES, POSITION, SEED_EULER, attitude_slot,
                                          seed_coordinates, seed_payload_slot, seed_uav_slot,
                                          uav_attitude_slot)

ROTATION_NAMES = ('rx_p', 'ry_p', 'rz_p')  # a rigid payload's rotation vector, payload frame


def quaternion_rotation(quaternion: ArrayLike) -> np.ndarray:
    """R (3, 3), body -> world, of a unit quaternion (w, x, y, z) (physics.attitude's)."""
    state = np.concatenate((np.zeros(1), np.asarray(quaternion, dtype=float)))
    return attitude.quaternion_rotation(state, 1)


def cable_offsets(params: FormationParams, uavs: np.ndarray, payload: np.ndarray,
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
        offsets = offsets - attach_offsets(params, uav_euler)
    return offsets


def attach_offsets(params: FormationParams, uav_euler: np.ndarray) -> np.ndarray:
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


def cable_moments(params: FormationParams, offsets: np.ndarray,
                  rotation: np.ndarray) -> np.ndarray:
    """c_i = b_i x R_p^T d_i (n, 3) [m^2], payload frame (docs/rigid_payload.md)."""
    return np.cross(np.asarray(params.payload_attach_points), offsets @ rotation)


def _state_rotation(layout: StateLayout, x: np.ndarray) -> np.ndarray | None:
    """A rigid payload's R_p (3, 3) at state x; None for a point payload."""
    return quaternion_rotation(layout.payload_quaternion(x)) if layout.rigid_payload else None


def coordinate_names(n_uavs: int, rigid_payload: bool = False) -> tuple[str, ...]:
    """Names of the 6n + 3 coordinates q_f: x1 y1 z1 phi1 theta1 psi1 ... x_p y_p z_p, and a
    rigid payload's rotation vector rx_p ry_p rz_p [rad] (payload frame) after them."""
    names = [f'{c}{i + 1}' for i in range(n_uavs)
             for c in ('x', 'y', 'z', 'phi', 'theta', 'psi')]
    return tuple(names + ['x_p', 'y_p', 'z_p'] + (list(ROTATION_NAMES) if rigid_payload else []))


def _columns(n: int, rigid_payload: bool) -> tuple[int, int, int]:
    """The analysis' coordinates (coordinate_names): (their count, r_p's column, a rigid
    payload's rotation vector's first column: q_f's length)."""
    return (len(coordinate_names(n, rigid_payload)), seed_payload_slot(n), seed_coordinates(n))


def mass_matrix(params: FormationParams, uav_euler: ArrayLike) -> np.ndarray:
    """Formation inertia M_f (Eq. 2.47): blocks m_i I, M_eta,i = W^T J W (Eq. 2.24), m_p I;
    a rigid payload's J_p = diag(J_xx, J_yy, J_zz) [kg m^2] (payload frame) after them."""
    n = params.n_uavs
    euler = np.asarray(uav_euler, dtype=float).reshape(n, 3)
    size, p, rotation = _columns(n, params.rigid_payload)
    mass = np.zeros((size, size))
    for i, uav in enumerate(params.uavs):
        r, e = seed_uav_slot(i) + POSITION, seed_uav_slot(i) + SEED_EULER
        mass[r:r + 3, r:r + 3] = uav.mass * np.eye(3)
        mass[e:e + 3, e:e + 3] = euler_mass_matrix(uav.inertia, euler[i])
    mass[p:p + 3, p:p + 3] = params.payload_mass * np.eye(3)
    if params.rigid_payload:
        mass[rotation:, rotation:] = np.diag(params.payload_inertia)
    return mass


def formation_jacobian(params: FormationParams, x: np.ndarray) -> np.ndarray:
    """G [m] (n, 6n + 3) at state x (Eq. 2.65-2.67, constraints.constraint_jacobian); a rigid
    payload's (n, 6n + 6) with the columns dg_i/dtheta = 2 c_i [m^2] of its rotation vector
    (R_p = R Exp(theta), c_i = b_i x R^T d_i at x's attitude R; docs/rigid_payload.md).
    Cables held off the UAVs' centres: d_i from r_i + R_i a_i, and the UAVs' Euler columns
    dg_i/deta_i = -2 d_i . d(R_i a_i)/deta_i [m^2/rad] (package docstring)."""
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    attached = params.uav_attach_points is not None
    if not params.rigid_payload and not attached:
        return constraint_jacobian(uavs, payload)
    n = params.n_uavs
    rotation = _state_rotation(layout, x)
    euler = layout.uav_euler(x)
    offsets = cable_offsets(params, uavs, payload, rotation, euler)
    size, p, turn = _columns(n, params.rigid_payload)
    jacobian = np.zeros((n, size))
    for i in range(n):
        r, e = seed_uav_slot(i) + POSITION, seed_uav_slot(i) + SEED_EULER
        jacobian[i, r:r + 3] = -2.0 * offsets[i]
        jacobian[i, p:p + 3] = 2.0 * offsets[i]
        if attached:
            jacobian[i, e:e + 3] = -2.0 * offsets[i] @ _attach_derivatives(
                euler[i], np.asarray(params.uav_attach_points[i], dtype=float))
    if params.rigid_payload:
        jacobian[:, turn:] = 2.0 * cable_moments(params, offsets, rotation)
    return jacobian


def formation_residuals(params: FormationParams, x: np.ndarray) -> np.ndarray:
    """g_i = |d_i|^2 - l_i^2 [m^2] (n,) at state x (Eq. 2.42; a rigid payload's d_i, and from
    the UAVs' attach points r_i + R_i a_i when params.uav_attach_points)."""
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    if not params.rigid_payload and params.uav_attach_points is None:
        return cable_residuals(uavs, payload, params.cable_lengths)
    offsets = cable_offsets(params, uavs, payload, _state_rotation(layout, x),
                             layout.uav_euler(x))
    return np.einsum('ij,ij->i', offsets, offsets) - np.asarray(params.cable_lengths) ** 2


def seed_coordinates_of(layout: StateLayout, x: np.ndarray) -> np.ndarray:
    """q_f (6n + 3,) of a state x (or (..., 6n + 3) of a stack): per UAV r_i [m] and the ZYX
    angles eta_i [rad] of its quaternion, then r_p [m] (a rigid payload's attitude not
    included)."""
    x = np.asarray(x, dtype=float)
    n = layout.n_uavs
    out = np.empty(x.shape[:-1] + (seed_coordinates(n),))
    euler = layout.uav_euler(x)
    for i in range(n):
        r, e = seed_uav_slot(i) + POSITION, seed_uav_slot(i) + SEED_EULER
        out[..., r:r + 3] = layout.uav_positions(x)[..., i, :]
        out[..., e:e + 3] = euler[..., i, :]
    out[..., seed_payload_slot(n):] = layout.payload_position(x)
    return out


def displaced_state(layout: StateLayout, x: np.ndarray, dq: np.ndarray,
                    dq_dot: np.ndarray) -> np.ndarray:
    """The packed state x moved by dq (q_f [m, rad], a rigid payload's rotation vector theta
    [rad], payload frame, after it) and dq_dot (q_f_dot [m/s, rad/s], then omega_p [rad/s]):
    the translations by theirs; each UAV's ZYX angles eta_i (of its quaternion) and Euler rates
    eta_dot_i = W^-1 omega_i by theirs, stored back as its quaternion and body rates omega_i =
    W eta_dot_i (Eq. 2.7); a rigid payload's attitude q (x) Exp(theta) (a body-frame rotation,
    the quaternion kept unit) and body rates omega_p + dq_dot's last three."""
    n = layout.n_uavs
    out = np.array(x, dtype=float)
    for i in range(n):
        r = seed_uav_slot(i) + POSITION
        layout.uav_positions(out)[i] += dq[r:r + 3]
        layout.uav_velocities(out)[i] += dq_dot[r:r + 3]
    p = seed_payload_slot(n)
    layout.payload_position(out)[:] += dq[p:p + 3]
    layout.payload_velocity(out)[:] += dq_dot[p:p + 3]
    euler = layout.uav_euler(x)
    euler_rates = np.einsum('ijk,ik->ij', euler_rate_matrix_inverse(euler),
                            layout.uav_body_rates(x))
    angles = [seed_uav_slot(i) + SEED_EULER + k for i in range(n) for k in range(3)]
    euler = euler + dq[angles].reshape(n, 3)
    euler_rates = euler_rates + dq_dot[angles].reshape(n, 3)
    layout.set_uav_euler(out, euler)
    layout.uav_body_rates(out)[:] = np.einsum('ijk,ik->ij', euler_rate_matrix(euler),
                                              euler_rates)
    if not layout.rigid_payload:
        return out
    nq = seed_coordinates(n)
    theta = np.asarray(dq[nq:nq + 3], dtype=float)
    angle = float(np.linalg.norm(theta))
    w, v = layout.payload_quaternion(x)[0], layout.payload_quaternion(x)[1:]
    turn_w = math.cos(0.5 * angle)
    turn_v = theta * (0.5 if angle == 0.0 else math.sin(0.5 * angle) / angle)
    layout.payload_quaternion(out)[:] = np.concatenate((
        [w * turn_w - v @ turn_v], w * turn_v + turn_w * v + np.cross(v, turn_v)))
    layout.payload_body_rates(out)[:] += dq_dot[nq:nq + 3]
    return out


def coordinate_accelerations(layout: StateLayout, x: np.ndarray,
                             acc: np.ndarray) -> np.ndarray:
    """q_f_ddot [m/s^2, rad/s^2] (and a rigid payload's alpha_p [rad/s^2], payload frame, after
    it) at state x from the DAE's acc there (`FormationModel.accelerations_from_wrenches`:
    q_ddot, then the attitude blocks' rates): each UAV's eta_ddot = W^-1 (omega_dot -
    W_dot eta_dot) (Eq. 2.8) with eta_dot = W^-1 omega."""
    n = layout.n_uavs
    nq = layout.n_coordinates
    out = np.empty(len(coordinate_names(n, layout.rigid_payload)))
    positions = acc[:nq]
    for i in range(n):
        r = seed_uav_slot(i) + POSITION
        out[r:r + 3] = layout.uav_positions(positions)[i]
    p = seed_payload_slot(n)
    out[p:p + 3] = layout.payload_position(positions)
    euler = layout.uav_euler(x)
    inverse = euler_rate_matrix_inverse(euler)
    euler_rates = np.einsum('ijk,ik->ij', inverse, layout.uav_body_rates(x))
    turning = euler_rate_matrix_dot(euler, euler_rates)
    for i in range(n):
        rate = uav_attitude_slot(n, i) - nq + BODY_RATES   # omega_dot_i in acc
        e = seed_uav_slot(i) + SEED_EULER
        out[e:e + 3] = inverse[i] @ (acc[rate:rate + 3] - turning[i] @ euler_rates[i])
    if layout.rigid_payload:
        rate = attitude_slot(n) - nq + BODY_RATES            # alpha_p in acc
        out[seed_coordinates(n):] = acc[rate:rate + 3]
    return out
