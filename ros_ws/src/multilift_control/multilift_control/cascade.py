"""Cascade multirotor control (seed Ch. 3): position -> attitude setpoint and thrust -> torques
-> rotor speeds, saturated to the vehicle's [omega_min, omega_max].

World frame z up, body frame FLU, ZYX Euler angles (docs/conventions.md). The classes here
build the laws' constant and memory arrays once (`multilift_control.laws.layout`) and call
the laws (`laws.cascade`, `laws.mixer`), compiled or not as MULTILIFT_KERNEL says
(`laws.runnable`).
"""
from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from multilift_control import laws
from multilift_control.laws.cascade import attitude_from_force as attitude_from_force_law
from multilift_control.laws.cascade import attitude_torque as attitude_torque_law
from multilift_control.laws.cascade import cascade_update, command
from multilift_control.laws.cascade import position_force as position_force_law
from multilift_control.laws.layout import (CASCADE_ATT_KD, CASCADE_ATT_KP, CASCADE_GRAVITY,
                                           CASCADE_HOVER_MASS, CASCADE_INERTIA,
                                           CASCADE_INTEGRAL, CASCADE_INTEGRAL_LIMIT, CASCADE_KD,
                                           CASCADE_KI, CASCADE_KP, CASCADE_LAST_T,
                                           CASCADE_MAX_TILT, CASCADE_MEMORY_SIZE, CASCADE_SIZE,
                                           CASCADE_SQUARE_MAX, CASCADE_SQUARE_MIN,
                                           CASCADE_SWING_DAMPING, CASCADE_SWING_LIMIT,
                                           CASCADE_SWING_REST,
                                           CASCADE_SWING_STIFFNESS, CASCADE_THRUST_COEFFICIENT,
                                           MIXER_COLLECTIVE,
                                           MIXER_SIZE, MIXER_WRENCH, REFERENCE_ACCELERATION,
                                           REFERENCE_POSITION, REFERENCE_SIZE,
                                           REFERENCE_VELOCITY, UAV_BODY_RATES, UAV_EULER,
                                           UAV_POSITION, UAV_STATE_SIZE, UAV_VELOCITY)
from multilift_control.laws.mixer import rotor_speeds
from multilift_sim.allocation import allocation_matrix
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.scenario import ControlConfig


@dataclass(frozen=True)
class UavState:
    """What a controller measures of one UAV, world frame."""
    position: np.ndarray    # [m]
    velocity: np.ndarray    # [m/s]
    euler: np.ndarray       # (roll, pitch, yaw) [rad]
    body_rates: np.ndarray  # body angular velocity, FLU [rad/s]

    def row(self) -> np.ndarray:
        """The state as the laws read it: (UAV_STATE_SIZE,) in the `laws.layout` UAV_* slots."""
        out = np.empty(UAV_STATE_SIZE)
        out[UAV_POSITION:UAV_POSITION + 3] = self.position
        out[UAV_VELOCITY:UAV_VELOCITY + 3] = self.velocity
        out[UAV_EULER:UAV_EULER + 3] = self.euler
        out[UAV_BODY_RATES:UAV_BODY_RATES + 3] = self.body_rates
        return out


class FormationStates(tuple):
    """Every UAV's UavState at one tick, from the leader on, stacked once into the laws' (n,
    UAV_STATE_SIZE) array (`array`, read-only): the followers of one process share it instead
    of each stacking n states (O(n^2) a tick). `payload_velocity`: the payload's v_p [m/s],
    world, at the same tick as the snapshot carries it, and `payload_position` r_p [m] (None
    where not given: a leader with `control.payload_feedback` refuses to answer without them).
    """

    payload_position: np.ndarray | None
    payload_velocity: np.ndarray | None

    def __new__(cls, states=(), payload_position=None, payload_velocity=None):
        self = super().__new__(cls, states)
        self.payload_position, self.payload_velocity = (
            None if value is None else np.asarray(value, dtype=float).reshape(3)
            for value in (payload_position, payload_velocity))
        return self

    @classmethod
    def of(cls, states) -> FormationStates:
        """`states` itself when it is one, a lone UavState as the formation of one (a leader's
        node that reads only its own odometry), else its UavStates as one."""
        if isinstance(states, cls):
            return states
        return cls((states,)) if isinstance(states, UavState) else cls(states)

    @functools.cached_property
    def array(self) -> np.ndarray:
        out = np.array([state.row() for state in self]).reshape(len(self), UAV_STATE_SIZE)
        return out


@dataclass(frozen=True)
class ControlOutput:
    """One tick of a controller's answer."""
    rotor_speeds: np.ndarray      # after saturation [rad/s]
    saturated: np.ndarray         # True where the request left [omega_min, omega_max]
    attitude_setpoint: np.ndarray  # (roll, pitch, yaw) asked of the inner loop [rad]
    thrust: float                 # collective thrust asked of the rotors [N]


def attitude_from_force(force: np.ndarray, yaw: float,
                        max_tilt: float = math.radians(89.0)) -> tuple[float, float, float]:
    """Roll and pitch setpoints [rad] and the thrust [N] that point the thrust along `force`
    (world) [N] at heading `yaw` [rad], the tilt limited to `max_tilt` [rad] (seed Eq. 3.13:
    `laws.cascade.attitude_from_force`)."""
    return laws.runnable(attitude_from_force_law)(np.asarray(force, dtype=float), float(yaw),
                                                  float(max_tilt))


class RotorMixer:
    """Body wrench -> rotor speeds with saturation (inverse of seed Eq. 2.14, Eq. 2.15:
    `laws.mixer.rotor_speeds`, attitude first)."""

    def __init__(self, vehicle: MultirotorParams, effectiveness: np.ndarray | None = None):
        """`effectiveness` (n_rotors,) in [0, 1]: each rotor's share of its thrust and moment
        as the controller knows it (None: all intact); the wrench is allocated over what the
        rotors can give, a failed rotor's row left out (issue 21: reallocation after a rotor
        fails, the fault known at once)."""
        self.matrix = allocation_matrix(vehicle.frame_type, vehicle.arm_length,
                                        vehicle.thrust_coefficient, vehicle.moment_coefficient)
        if effectiveness is None or np.all(np.asarray(effectiveness) == 1.0):
            self.pinv = np.linalg.pinv(self.matrix)
        else:
            effectiveness = np.asarray(effectiveness, dtype=float)
            self.pinv = np.linalg.pinv(self.matrix * effectiveness)
            self.pinv[effectiveness == 0.0] = 0.0  # exactly out: `laws.mixer.rotor_speeds`
            # round-off of a share that is 0 (a hexa's rotor opposite the failed one) made 0
            self.pinv[np.abs(self.pinv) < 1e-9 * np.abs(self.pinv).max(axis=0)] = 0.0
        self.square_min = vehicle.rotor_speed_min ** 2
        self.square_max = vehicle.rotor_speed_max ** 2
        self.collective = self.pinv @ np.array([1.0, 0.0, 0.0, 0.0])  # omega^2 per newton
        # the laws' mixer rows (MIXER_* slots)
        self.rows = np.empty((len(self.pinv), MIXER_SIZE))
        self.rows[:, MIXER_WRENCH:MIXER_WRENCH + 4] = self.pinv
        self.rows[:, MIXER_COLLECTIVE] = self.collective
        self._law = laws.runnable(rotor_speeds)

    def rotor_speeds(self, thrust: float, torque: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(omega [rad/s], saturated) for collective thrust [N] and body torque [N m]."""
        wrench = np.array((thrust, *np.asarray(torque, dtype=float)))
        return self._law(self.rows, self.square_min, self.square_max, wrench)


class CascadeController:
    """Leader controller: tracks a position reference (seed Ch. 3 cascade, `laws.cascade`).

    Outer loop: PID on position with reference velocity and acceleration feed-forward gives the
    force the thrust must produce; the gravity feed-forward uses `hover_mass` (the UAV and its
    static share of the payload). The cable pull beyond that is a disturbance the integral
    absorbs, as in the seed. Inner loop: PD on Euler angles -> body torques (J-scaled) plus the
    gyroscopic term. Then `RotorMixer`.
    """

    def __init__(self, vehicle: MultirotorParams, gains: ControlConfig, hover_mass: float,
                 gravity: float, swing_rest: tuple[float, float] = (0.0, 0.0)):
        """swing_rest: s_0 of the swing feedback (`laws.swing`), the payload's x, y from the
        UAVs' mean position at the formation's hanging rest [m] (a leader's; else unused)."""
        self.vehicle = vehicle
        self.gains = gains
        self.hover_mass = hover_mass
        self.gravity = gravity
        self.inertia = np.asarray(vehicle.inertia, dtype=float)
        self.mixer = RotorMixer(vehicle)
        self.integral_limit = 0.5 * gravity  # [m/s^2] of integral authority
        self.constants = np.empty(CASCADE_SIZE)  # the CASCADE_* slots
        self.constants[CASCADE_KP:CASCADE_KP + 3] = gains.position_kp
        self.constants[CASCADE_KD:CASCADE_KD + 3] = gains.position_kd
        self.constants[CASCADE_KI:CASCADE_KI + 3] = gains.position_ki
        self.constants[CASCADE_INTEGRAL_LIMIT] = self.integral_limit
        self.constants[CASCADE_HOVER_MASS] = hover_mass
        self.constants[CASCADE_GRAVITY] = gravity
        self.constants[CASCADE_MAX_TILT] = gains.max_tilt
        self.constants[CASCADE_INERTIA:CASCADE_INERTIA + 3] = vehicle.inertia
        self.constants[CASCADE_ATT_KP:CASCADE_ATT_KP + 3] = gains.attitude_kp
        self.constants[CASCADE_ATT_KD:CASCADE_ATT_KD + 3] = gains.attitude_kd
        self.constants[CASCADE_SQUARE_MIN] = self.mixer.square_min
        self.constants[CASCADE_SQUARE_MAX] = self.mixer.square_max
        self.constants[CASCADE_THRUST_COEFFICIENT] = vehicle.thrust_coefficient
        # a leader's swing feedback (laws.swing); s_0 given by the leader that knows the formation
        self.constants[CASCADE_SWING_STIFFNESS] = gains.swing_stiffness
        self.constants[CASCADE_SWING_DAMPING] = gains.swing_damping
        self.constants[CASCADE_SWING_REST:CASCADE_SWING_REST + 2] = swing_rest
        self.constants[CASCADE_SWING_LIMIT] = gains.swing_limit
        # what the loop remembers (CASCADE_INTEGRAL, CASCADE_LAST_T: NaN before a tick)
        self.memory = np.zeros(CASCADE_MEMORY_SIZE)
        self.memory[CASCADE_LAST_T] = math.nan
        self._update = laws.runnable(cascade_update)
        self._command = laws.runnable(command)
        self._position_force = laws.runnable(position_force_law)
        self._attitude_torque = laws.runnable(attitude_torque_law)

    @property
    def integral(self) -> np.ndarray:
        """The position loop's integral term [m/s^2], world (x, y, z)."""
        return self.memory[CASCADE_INTEGRAL:CASCADE_INTEGRAL + 3]

    def position_force(self, t: float, state: UavState, position_ref: np.ndarray,
                       velocity_ref: np.ndarray, acceleration_ref: np.ndarray) -> np.ndarray:
        """Force the thrust should produce, world frame [N]; advances the integral to t [s]."""
        return self._position_force(self.constants, self.memory, float(t), state.row(),
                                    _reference(position_ref, velocity_ref, acceleration_ref))

    def attitude_torque(self, state: UavState, setpoint: Sequence[float]) -> np.ndarray:
        """Body torque [N m] driving the Euler angles to `setpoint` (roll, pitch, yaw) [rad]."""
        return self._attitude_torque(self.constants, state.row(),
                                     np.asarray(setpoint, dtype=float))

    def command(self, state: UavState, force: np.ndarray, yaw: float) -> ControlOutput:
        """Rotor speeds that produce `force` (world) [N] at heading `yaw` [rad]."""
        return ControlOutput(*self._command(self.constants, self.mixer.rows, state.row(),
                                            np.asarray(force, dtype=float), float(yaw)))

    def update(self, t: float, state: UavState, position_ref: np.ndarray,
               velocity_ref: np.ndarray, acceleration_ref: np.ndarray,
               yaw_ref: float = 0.0) -> ControlOutput:
        """One control tick at simulated time t [s]."""
        return ControlOutput(*self._update(
            self.constants, self.mixer.rows, self.memory, float(t), state.row(),
            _reference(position_ref, velocity_ref, acceleration_ref), float(yaw_ref)))


def _reference(position: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray
               ) -> np.ndarray:
    """A reference in the laws' REFERENCE_* slots."""
    out = np.empty(REFERENCE_SIZE)
    out[REFERENCE_POSITION:REFERENCE_POSITION + 3] = position
    out[REFERENCE_VELOCITY:REFERENCE_VELOCITY + 3] = velocity
    out[REFERENCE_ACCELERATION:REFERENCE_ACCELERATION + 3] = acceleration
    return out


def balancing_rotor_speed(vehicle: MultirotorParams, supported_mass: float,
                          gravity: float) -> float:
    """Equal rotor speed whose thrust carries `supported_mass` [kg] in hover [rad/s]."""
    per_rotor = supported_mass * gravity / vehicle.n_rotors
    return math.sqrt(per_rotor / vehicle.thrust_coefficient)
