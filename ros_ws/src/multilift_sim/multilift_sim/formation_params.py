"""A formation's parameters and the arrays built from them: `FormationParams` (what the DAE
needs of a scenario), `StateLayout` (numpy views of the formation state x: the translations'
(q, q_dot), then the bodies' attitude blocks, docs/conventions.md) and the constant rows the
physics functions read (`constant_arrays`,
`actuator_array`; their slots: multilift_sim.physics.layout). World frame (z up), SI units."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.kinematics import euler_from_quaternion, quaternion_from_euler
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.physics import layout as slots
from multilift_sim.physics.layout import (
    ACTUATOR_COLUMNS, ACTUATOR_RATE_LIMIT, ACTUATOR_TIME_CONSTANT, FORMATION_BETA_SQ,
    FORMATION_CHAIN_LINKS, FORMATION_DRAG, FORMATION_ELASTIC, FORMATION_GRAVITY,
    FORMATION_INV_PAYLOAD_MASS,
    FORMATION_NULL_SPACE, FORMATION_PAYLOAD_INERTIA, FORMATION_PAYLOAD_MASS,
    FORMATION_PRESCRIBED, FORMATION_PROJECTION_STEPS, FORMATION_PROJECTION_TOLERANCE,
    FORMATION_SCALARS, FORMATION_TIME, FORMATION_WINCH, UAV_WINCH_ACCELERATION_LIMIT,
    UAV_REEL_LENGTH, UAV_WINCH_MAX_LENGTH, UAV_WINCH_MIN_LENGTH, UAV_WINCH_RATE_LIMIT,
    FORMATION_SUBSTEPS, FORMATION_TWO_ALPHA, FORMATION_WIND, GUST_CENTER, GUST_COLUMNS,
    GUST_DIRECTION, GUST_GRADIENT_DISTANCE, GUST_REFERENCE_SPEED, UAV_ATTACH,
    UAV_CABLE_DAMPING, UAV_CABLE_STIFFNESS, UAV_COLUMNS, UAV_DRAG, UAV_GYRO, UAV_INV_INERTIA,
    UAV_LENGTH_SQ, UAV_MASS, UAV_NODE_DRAG, UAV_NODE_MASS, UAV_PAYLOAD_ATTACH)
from multilift_sim.wind.gusts import Gust


@dataclass(frozen=True, kw_only=True)
class FormationParams:
    """Physical and numerical parameters of the formation DAE (world frame, SI units)."""

    uavs: tuple[MultirotorParams, ...]       # UAV i = index i-1; UAV 1 is the leader
    cable_lengths: tuple[float, ...]         # l_i [m], one per UAV
    payload_mass: float                      # m_p [kg]
    payload_drag_coefficient: float          # c_pd of seed Eq. 2.53 [N s^2/m^2]
    baumgarte_alpha: float                   # alpha_f of seed Eq. 2.59 [1/s]
    baumgarte_beta: float                    # beta_f of seed Eq. 2.59 [1/s]
    gusts: tuple[Gust, ...] = ()             # 1-cosine gusts acting on the payload
    gravity: float = 9.81                    # g [m/s^2], along -z of the world frame
    wind: tuple[float, float, float] = (0.0, 0.0, 0.0)  # steady wind [m/s], world, everywhere
    # a rigid-body payload (issue 20; physics.rigid_payload): its principal moments J_p
    # [kg m^2] and, per cable, where it holds the payload b_i [m], payload frame (both, or
    # neither: the seed's point mass)
    payload_inertia: tuple[float, float, float] | None = None
    payload_attach_points: tuple[tuple[float, float, float], ...] | None = None
    # where each cable holds its UAV, a_i [m] in its body frame FLU (None: every centre of mass)
    uav_attach_points: tuple[tuple[float, float, float], ...] | None = None
    # elastic cables (`cable_model: elastic`, physics.elastic_cables): each cable's axial
    # stiffness k_i [N/m] and damping c_i [N s/m] (None: the seed's rigid cables)
    cable_stiffness: tuple[float, ...] | None = None
    cable_damping: tuple[float, ...] | None = None
    substeps: int = 1                        # RK4 sub-steps per physics step (FORMATION_SUBSTEPS)
    # prescribed motion (issue 34; physics.prescribed): each UAV's drives.Drive or None (None:
    # no UAV's motion is prescribed)
    drives: tuple[Any, ...] | None = None
    # winches (issue 32; physics.winch): each UAV's cables.winch.Winch or None (None: no winch)
    winches: tuple[Any, ...] | None = None
    # heavy cables (`cable_model: chain`, physics.chain_cables): N links a cable (0: none), its
    # mass per length mu [kg/m] (the N - 1 inner nodes carry mu l_i / (N - 1) each) and its
    # drag per length 0.5 rho C_d d [kg/m^2] (a node's drag: that times l_i / N)
    chain_links: int = 0
    cable_mass_per_length: float = 0.0
    cable_drag_per_length: float = 0.0

    def __post_init__(self) -> None:
        uavs = tuple(self.uavs)
        if not uavs:
            raise ValueError('FormationParams.uavs must hold at least one MultirotorParams')
        for i, uav in enumerate(uavs):
            if not isinstance(uav, MultirotorParams):
                raise ValueError(f'FormationParams.uavs[{i}] must be a MultirotorParams, got '
                                 f'{type(uav).__name__}')
        lengths = tuple(float(v) for v in self.cable_lengths)
        if len(lengths) != len(uavs):
            raise ValueError(f'FormationParams.cable_lengths has {len(lengths)} entries for '
                             f'{len(uavs)} UAVs')
        for i, length in enumerate(lengths):
            if not (math.isfinite(length) and length > 0):
                raise ValueError(f'FormationParams.cable_lengths[{i}] (cable {i + 1}) must be '
                                 f'finite and > 0 [m], got {length!r}')
        gusts = tuple(self.gusts)
        for i, gust in enumerate(gusts):
            if not isinstance(gust, Gust):
                raise ValueError(f'FormationParams.gusts[{i}] must be a Gust, got '
                                 f'{type(gust).__name__}')
        checks = (('payload_mass', lambda v: v > 0, '> 0'),
                  ('payload_drag_coefficient', lambda v: v >= 0, '>= 0'),
                  ('baumgarte_alpha', lambda v: v >= 0, '>= 0'),
                  ('baumgarte_beta', lambda v: v >= 0, '>= 0'),
                  ('gravity', lambda v: v >= 0, '>= 0'))
        for name, rule, text in checks:
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and rule(value)):
                raise ValueError(f'FormationParams.{name} must be finite and {text}, got '
                                 f'{value!r}')
        object.__setattr__(self, 'uavs', uavs)
        object.__setattr__(self, 'cable_lengths', lengths)
        object.__setattr__(self, 'gusts', gusts)
        wind = tuple(float(v) for v in self.wind)
        if len(wind) != 3 or not all(math.isfinite(v) for v in wind):
            raise ValueError(f'FormationParams.wind must be a finite 3-vector [m/s], got '
                             f'{self.wind!r}')
        object.__setattr__(self, 'wind', wind)
        if (self.payload_inertia is None) != (self.payload_attach_points is None):
            raise ValueError('FormationParams.payload_inertia and payload_attach_points go '
                             'together (a rigid payload) or not at all (a point payload)')
        if self.payload_inertia is not None:
            inertia = tuple(float(v) for v in self.payload_inertia)
            if len(inertia) != 3 or not all(math.isfinite(v) and v > 0 for v in inertia):
                raise ValueError(f'FormationParams.payload_inertia must be 3 finite moments '
                                 f'> 0 [kg m^2], got {self.payload_inertia!r}')
            object.__setattr__(self, 'payload_inertia', inertia)
            self._check_points('payload_attach_points', 'cable')
        if self.uav_attach_points is not None:
            self._check_points('uav_attach_points', 'UAV')

    def _check_points(self, name: str, each: str) -> None:
        """Field `name` as one finite (x, y, z) [m] per UAV (`each` names what one holds),
        stored as a tuple of float triples; ValueError otherwise."""
        value = getattr(self, name)
        points = tuple(tuple(float(v) for v in point) for point in value)
        if len(points) != len(self.uavs) or any(len(point) != 3 or not all(
                math.isfinite(v) for v in point) for point in points):
            raise ValueError(f'FormationParams.{name} must give one finite (x, y, z) [m] per '
                             f'{each} ({len(self.uavs)}), got {value!r}')
        object.__setattr__(self, name, points)

    @property
    def n_uavs(self) -> int:
        return len(self.uavs)

    @property
    def rigid_payload(self) -> bool:
        """Whether the payload is a rigid body (its attitude in the state)."""
        return self.payload_inertia is not None

    @property
    def chain_nodes(self) -> int:
        """Inner nodes per cable (N - 1 of a chain's N links; 0: no chain)."""
        return max(0, self.chain_links - 1)


@dataclass(frozen=True)
class StateLayout:
    """Named views into the packed formation state x (docs/conventions.md): the translations
    q = (r_1, ..., r_n, r_p) [m] and their velocities q_dot [m/s], then each UAV's attitude
    block and a rigid payload's (`physics.layout` BODY_*: the unit quaternion (w, x, y, z),
    body -> world, and the body rates [rad/s]).

    Each accessor takes one state (size,) or a stack of them (..., size) (a batch, a run's
    record) and returns a view (writable when x is a contiguous float array), not a copy, but
    `uav_euler`, computed from the quaternions; the shapes below are one state's, a stack's
    have its leading axes first. The one place of these offsets outside the compiled functions
    (which use physics.state_slots).
    """

    n_uavs: int
    rigid_payload: bool = False
    chain_nodes: int = 0    # each cable's inner nodes (`cable_model: chain`: N - 1), after all

    def __post_init__(self) -> None:
        if self.n_uavs < 1:
            raise ValueError(f'StateLayout.n_uavs must be >= 1, got {self.n_uavs}')

    @property
    def n_coordinates(self) -> int:
        """Length of q: 3n + 3."""
        return slots.n_coordinates(self.n_uavs)

    @property
    def size(self) -> int:
        """Length of the state x: 2 (3n + 3) + 7n, plus 7 with a rigid payload, plus a chain's
        6 n (N - 1) (its inner nodes' blocks)."""
        return slots.attitude_slot(self.n_uavs) + (
            slots.BODY_ATTITUDE if self.rigid_payload else 0) + (
                slots.NODE_STATE * self.n_uavs * self.chain_nodes)

    def chain_positions(self, x: np.ndarray) -> np.ndarray:
        """A chain's inner nodes' positions [m], world, shape (n, N - 1, 3)."""
        return self._chain_blocks(x)[..., slots.NODE_POSITION:slots.NODE_POSITION + 3]

    def chain_velocities(self, x: np.ndarray) -> np.ndarray:
        """A chain's inner nodes' velocities [m/s], world, shape (n, N - 1, 3)."""
        return self._chain_blocks(x)[..., slots.NODE_VELOCITY:slots.NODE_VELOCITY + 3]

    def _chain_blocks(self, x: np.ndarray) -> np.ndarray:
        start = slots.chain_node_slot(self.size, self.n_uavs, self.chain_nodes, 0, 1)
        return x[..., start:start + slots.NODE_STATE * self.n_uavs * self.chain_nodes].reshape(
            x.shape[:-1] + (self.n_uavs, self.chain_nodes, slots.NODE_STATE))

    def coordinates(self, x: np.ndarray) -> np.ndarray:
        """q, the translations (r_1, ..., r_n, r_p) [m], shape (3n + 3,)."""
        return x[..., :self.n_coordinates]

    def rates(self, x: np.ndarray) -> np.ndarray:
        """q_dot, their velocities [m/s], shape (3n + 3,)."""
        return x[..., self.n_coordinates:slots.uav_attitude_slot(self.n_uavs, 0)]

    def payload_quaternion(self, x: np.ndarray) -> np.ndarray:
        """A rigid payload's attitude, the unit quaternion (w, x, y, z), shape (4,)."""
        base = slots.attitude_slot(self.n_uavs) + slots.BODY_QUATERNION
        return x[..., base:base + 4]

    def payload_body_rates(self, x: np.ndarray) -> np.ndarray:
        """A rigid payload's angular velocity omega_p [rad/s], payload frame, shape (3,)."""
        base = slots.attitude_slot(self.n_uavs) + slots.BODY_RATES
        return x[..., base:base + 3]

    def _uav_block(self, q: np.ndarray) -> np.ndarray:
        return q[..., :slots.payload_slot(self.n_uavs)].reshape(
            q.shape[:-1] + (self.n_uavs, slots.UAV_COORDINATES))

    def uav_attitudes(self, x: np.ndarray) -> np.ndarray:
        """Every UAV's attitude block (quaternion, body rates), shape (n, 7)."""
        blocks = x[..., slots.uav_attitude_slot(self.n_uavs, 0):slots.attitude_slot(self.n_uavs)]
        return blocks.reshape(x.shape[:-1] + (self.n_uavs, slots.BODY_ATTITUDE))

    def uav_positions(self, x: np.ndarray) -> np.ndarray:
        """UAV centres of mass r_i [m], world, shape (n, 3)."""
        return self._uav_block(self.coordinates(x))[..., slots.POSITION:slots.POSITION + 3]

    def uav_quaternions(self, x: np.ndarray) -> np.ndarray:
        """UAV attitudes, unit quaternions (w, x, y, z), body FLU -> world, shape (n, 4)."""
        return self.uav_attitudes(x)[..., slots.BODY_QUATERNION:slots.BODY_QUATERNION + 4]

    def uav_body_rates(self, x: np.ndarray) -> np.ndarray:
        """UAV body rates omega_i [rad/s], body FLU, shape (n, 3)."""
        return self.uav_attitudes(x)[..., slots.BODY_RATES:slots.BODY_RATES + 3]

    def uav_euler(self, x: np.ndarray) -> np.ndarray:
        """UAV ZYX Euler angles eta_i (roll, pitch, yaw) [rad] of their quaternions, shape
        (n, 3): a new array (physics.measurement.quaternion_euler), not a view."""
        quaternions = np.asarray(self.uav_quaternions(np.asarray(x, dtype=float)))
        return euler_from_quaternion(quaternions[..., [1, 2, 3, 0]])

    def payload_position(self, x: np.ndarray) -> np.ndarray:
        """Payload position r_p [m], world, shape (3,)."""
        return self.coordinates(x)[..., slots.payload_slot(self.n_uavs):]

    def uav_velocities(self, x: np.ndarray) -> np.ndarray:
        """UAV velocities [m/s], world, shape (n, 3)."""
        return self._uav_block(self.rates(x))[..., slots.POSITION:slots.POSITION + 3]

    def payload_velocity(self, x: np.ndarray) -> np.ndarray:
        """Payload velocity [m/s], world, shape (3,)."""
        return self.rates(x)[..., slots.payload_slot(self.n_uavs):]

    def pack(self, uav_positions: ArrayLike, uav_euler: ArrayLike, payload_position: ArrayLike,
             uav_velocities: ArrayLike | None = None, uav_body_rates: ArrayLike | None = None,
             payload_velocity: ArrayLike | None = None,
             payload_quaternion: ArrayLike | None = None,
             payload_body_rates: ArrayLike | None = None) -> np.ndarray:
        """Packed state from its parts (world frame, SI; the UAVs' attitudes as ZYX Euler
        angles [rad], stored as their quaternions); omitted rates are zero, a rigid payload's
        omitted attitude the identity."""
        x = np.zeros(self.size)
        if self.rigid_payload:
            self.payload_quaternion(x)[:] = (1.0, 0.0, 0.0, 0.0) if payload_quaternion is None \
                else payload_quaternion
            if payload_body_rates is not None:
                self.payload_body_rates(x)[:] = payload_body_rates
        self.uav_positions(x)[:] = np.reshape(uav_positions, (self.n_uavs, 3))
        self.set_uav_euler(x, uav_euler)
        self.payload_position(x)[:] = payload_position
        if uav_velocities is not None:
            self.uav_velocities(x)[:] = np.reshape(uav_velocities, (self.n_uavs, 3))
        if uav_body_rates is not None:
            self.uav_body_rates(x)[:] = np.reshape(uav_body_rates, (self.n_uavs, 3))
        if payload_velocity is not None:
            self.payload_velocity(x)[:] = payload_velocity
        return x

    def set_uav_euler(self, x: np.ndarray, uav_euler: ArrayLike) -> None:
        """The UAVs' quaternions of x (or of a stack of states) set to the ZYX Euler angles
        uav_euler (n, 3) [rad] (physics.measurement.euler_quaternion)."""
        angles = np.reshape(np.asarray(uav_euler, dtype=float), x.shape[:-1] + (self.n_uavs, 3))
        self.uav_quaternions(x)[:] = quaternion_from_euler(angles)[..., [3, 0, 1, 2]]


def constant_arrays(params: FormationParams) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The constants the physics functions read (slots: multilift_sim.physics.layout):
    (per-UAV rows (n, UAV_COLUMNS), gust rows (k, GUST_COLUMNS), the formation's scalars
    (FORMATION_SCALARS,))."""
    n = params.n_uavs
    uavs = np.empty((n, UAV_COLUMNS))
    moments = np.array([uav.inertia for uav in params.uavs], dtype=float).T      # (3, n)
    uavs[:, UAV_MASS] = [uav.mass for uav in params.uavs]
    uavs[:, UAV_LENGTH_SQ] = np.array(params.cable_lengths) ** 2
    uavs[:, UAV_INV_INERTIA:UAV_INV_INERTIA + 3] = (1.0 / moments).T
    # Euler's equation J omega_dot = tau - omega x J omega, per axis:
    # omega_dot_x = tau_x / I_xx - (I_zz - I_yy) / I_xx omega_y omega_z, and cyclically.
    uavs[:, UAV_DRAG] = [uav.drag_coefficient for uav in params.uavs]
    uavs[:, UAV_GYRO:UAV_GYRO + 3] = np.array([(moments[2] - moments[1]) / moments[0],
                                               (moments[0] - moments[2]) / moments[1],
                                               (moments[1] - moments[0]) / moments[2]]).T
    gusts = np.empty((len(params.gusts), GUST_COLUMNS))
    for k, gust in enumerate(params.gusts):
        gusts[k, GUST_CENTER:GUST_CENTER + 2] = gust.center
        gusts[k, GUST_DIRECTION:GUST_DIRECTION + 3] = gust.direction
        gusts[k, GUST_GRADIENT_DISTANCE] = gust.gradient_distance
        gusts[k, GUST_REFERENCE_SPEED] = gust.reference_speed
    formation = np.empty(FORMATION_SCALARS)
    formation[FORMATION_PAYLOAD_MASS] = params.payload_mass
    formation[FORMATION_INV_PAYLOAD_MASS] = 1.0 / float(params.payload_mass)
    formation[FORMATION_GRAVITY] = params.gravity
    formation[FORMATION_TWO_ALPHA] = 2.0 * params.baumgarte_alpha
    formation[FORMATION_BETA_SQ] = params.baumgarte_beta ** 2
    formation[FORMATION_DRAG] = params.payload_drag_coefficient
    formation[FORMATION_WIND:FORMATION_WIND + 3] = params.wind
    formation[FORMATION_NULL_SPACE] = 0.0  # the multipliers' form (nullspace.NullSpaceModel: 1)
    formation[FORMATION_PROJECTION_STEPS] = 0.0   # no projection (nullspace.NullSpaceModel's)
    formation[FORMATION_PROJECTION_TOLERANCE] = 0.0
    formation[FORMATION_SUBSTEPS] = float(params.substeps)   # RK4 steps per physics step
    elastic = params.cable_stiffness is not None
    # (a chain's elastic links are its own: chain_cables reads their stiffness and damping)
    formation[FORMATION_ELASTIC] = 1.0 if elastic and not params.chain_links else 0.0
    uavs[:, UAV_CABLE_STIFFNESS] = params.cable_stiffness if elastic else 0.0
    uavs[:, UAV_CABLE_DAMPING] = (params.cable_damping or 0.0) if elastic else 0.0
    formation[FORMATION_PAYLOAD_INERTIA:FORMATION_PAYLOAD_INERTIA + 3] = (
        params.payload_inertia if params.rigid_payload else 0.0)
    uavs[:, UAV_PAYLOAD_ATTACH:UAV_PAYLOAD_ATTACH + 3] = (
        params.payload_attach_points if params.rigid_payload else 0.0)
    uavs[:, UAV_ATTACH:UAV_ATTACH + 3] = (0.0 if params.uav_attach_points is None
                                          else params.uav_attach_points)
    formation[FORMATION_PRESCRIBED] = 0.0 if params.drives is None else 1.0
    formation[FORMATION_TIME] = 0.0
    formation[FORMATION_WINCH] = 0.0 if params.winches is None else 1.0
    uavs[:, UAV_WINCH_RATE_LIMIT:UAV_COLUMNS] = 0.0   # no winch
    # the reel slots a period's copy sets (physics.winch.reel_period): here each cable at its
    # own length, at rest, so that a solve of the constants alone sees the start's lengths
    uavs[:, UAV_REEL_LENGTH] = params.cable_lengths
    for i, winch in enumerate(params.winches or ()):
        if winch is not None:
            uavs[i, [UAV_WINCH_RATE_LIMIT, UAV_WINCH_ACCELERATION_LIMIT, UAV_WINCH_MIN_LENGTH,
                     UAV_WINCH_MAX_LENGTH]] = (winch.rate_limit, winch.acceleration_limit,
                                               winch.min_length, winch.max_length)
    formation[FORMATION_CHAIN_LINKS] = float(params.chain_links)
    lengths = np.array(params.cable_lengths)
    uavs[:, UAV_NODE_MASS] = (params.cable_mass_per_length * lengths / params.chain_nodes
                              if params.chain_nodes else 0.0)
    uavs[:, UAV_NODE_DRAG] = (params.cable_drag_per_length * lengths / params.chain_links
                              if params.chain_nodes else 0.0)
    if params.drives is not None:  # the drive table after the scalars (physics.layout DRIVE_*)
        from multilift_sim.drives import drive_table
        formation = np.concatenate([formation, drive_table(params.drives)])
    return uavs, gusts, formation


def actuator_array(params: FormationParams) -> np.ndarray:
    """Each UAV's rotor actuators (n, ACTUATOR_COLUMNS) (physics.layout ACTUATOR_*)."""
    actuators = np.empty((params.n_uavs, ACTUATOR_COLUMNS))
    actuators[:, ACTUATOR_TIME_CONSTANT] = [uav.motor_time_constant for uav in params.uavs]
    actuators[:, ACTUATOR_RATE_LIMIT] = [uav.motor_rate_limit for uav in params.uavs]
    return actuators
