"""Cascade multirotor control (seed Ch. 3): position -> attitude setpoint and thrust -> torques
-> rotor speeds, saturated to the vehicle's [omega_min, omega_max].

World frame z up, body frame FLU, ZYX Euler angles (docs/conventions.md). The methods here
are the reference; when the compiled kernels are on (`multilift_sim.kernels`) a tick runs the
same arithmetic compiled (`multilift_control._numba_laws`, tests/unit/test_compiled_laws.py).
"""
from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from multilift_sim import kernels
from multilift_sim.allocation import allocation_matrix
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.scenario import ControlConfig

E_Z = np.array([0.0, 0.0, 1.0])
COMPILED_LAWS = 'multilift_control._numba_laws'  # the compiled per-tick arithmetic


@dataclass(frozen=True)
class UavState:
    """What a controller measures of one UAV, world frame."""
    position: np.ndarray    # [m]
    velocity: np.ndarray    # [m/s]
    euler: np.ndarray       # (roll, pitch, yaw) [rad]
    body_rates: np.ndarray  # body angular velocity, FLU [rad/s]


class FormationStates(tuple):
    """Every UAV's UavState at one tick, from the leader on, with their positions and
    velocities stacked once, (n, 3) [m] and [m/s], world, read-only: the followers of one
    process share them instead of each stacking n states (O(n^2) a tick)."""

    @classmethod
    def of(cls, states) -> FormationStates:
        """`states` itself when it is one, else its UavStates as one."""
        return states if isinstance(states, cls) else cls(states)

    @functools.cached_property
    def positions(self) -> np.ndarray:
        return _stacked([s.position for s in self])

    @functools.cached_property
    def velocities(self) -> np.ndarray:
        return _stacked([s.velocity for s in self])


def _stacked(rows) -> np.ndarray:
    out = np.array(rows, dtype=float)
    out.flags.writeable = False
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
    """Roll and pitch setpoints that point the thrust along `force` (world) at heading `yaw`.

    Seed Eq. 3.13 with u_T = |force|: R e_z = (c_phi s_theta c_psi + s_phi s_psi,
    c_phi s_theta s_psi - s_phi c_psi, c_phi c_theta) for ZYX angles. The tilt is limited to
    `max_tilt` by shrinking the horizontal part. Returns (roll [rad], pitch [rad], thrust [N]).
    """
    fx, fy, fz = np.asarray(force, dtype=float).tolist()  # plain floats: the per-tick path
    fz = max(fz, 1e-6)
    horizontal = math.hypot(fx, fy)
    limit = fz * math.tan(max_tilt)
    if horizontal > limit:
        fx, fy = fx * (limit / horizontal), fy * (limit / horizontal)
    thrust = math.sqrt(fx * fx + fy * fy + fz * fz)
    s_psi, c_psi = math.sin(yaw), math.cos(yaw)
    roll = math.asin(max(-1.0, min(1.0, (fx * s_psi - fy * c_psi) / thrust)))
    pitch = math.atan2(fx * c_psi + fy * s_psi, fz)
    return roll, pitch, thrust


def wrap_angle(angle: np.ndarray | float) -> np.ndarray | float:
    """Angle wrapped to [-pi, pi) (a float stays a float)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


class RotorMixer:
    """Body wrench -> rotor speeds with saturation (inverse of seed Eq. 2.14, Eq. 2.15).

    Attitude comes first: when a rotor would leave [omega_min, omega_max], the collective part is
    shifted (equal omega^2 on every rotor changes thrust only) to bring the request inside; what
    still does not fit is clipped. `saturated` flags the rotors whose request was out of range.
    """

    def __init__(self, vehicle: MultirotorParams):
        self.matrix = allocation_matrix(vehicle.frame_type, vehicle.arm_length,
                                        vehicle.thrust_coefficient, vehicle.moment_coefficient)
        self.pinv = np.linalg.pinv(self.matrix)
        self.square_min = vehicle.rotor_speed_min ** 2
        self.square_max = vehicle.rotor_speed_max ** 2
        self.collective = self.pinv @ np.array([1.0, 0.0, 0.0, 0.0])  # omega^2 per newton

    def rotor_speeds(self, thrust: float, torque: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(omega [rad/s], saturated) for collective thrust [N] and body torque [N m]."""
        request = self.pinv @ np.array((thrust, *torque))
        high, low = request.max(), request.min()
        saturated = (request > self.square_max) | (request < self.square_min)
        squares = request
        if high > self.square_max or low < self.square_min:
            if high - low <= self.square_max - self.square_min:
                # shift along the collective direction until every rotor fits
                above = (high - self.square_max) / self.collective[np.argmax(request)]
                below = (self.square_min - low) / self.collective[np.argmin(request)]
                shift = -above if above > 0 else (below if below > 0 else 0.0)
                squares = request + shift * self.collective
            squares = np.minimum(np.maximum(squares, self.square_min), self.square_max)
        return np.sqrt(squares), saturated


class CascadeController:
    """Leader controller: tracks a position reference (seed Ch. 3 cascade).

    Outer loop: PID on position with reference velocity and acceleration feed-forward gives the
    force the thrust must produce; the gravity feed-forward uses `hover_mass` (the UAV and its
    static share of the payload). The cable pull beyond that is a disturbance the integral
    absorbs, as in the seed. Inner loop: PD on Euler angles -> body torques (J-scaled) plus the
    gyroscopic term. Then `RotorMixer`.
    """

    def __init__(self, vehicle: MultirotorParams, gains: ControlConfig, hover_mass: float,
                 gravity: float):
        self.vehicle = vehicle
        self.gains = gains
        self.hover_mass = hover_mass
        self.gravity = gravity
        self.inertia = np.asarray(vehicle.inertia, dtype=float)
        self.mixer = RotorMixer(vehicle)
        self.integral_limit = 0.5 * gravity  # [m/s^2] of integral authority
        # what the loop remembers: the integral (x, y, z) [m/s^2] and the time of the last
        # tick [s] (NaN: none yet), in one array both the methods and the compiled code update
        self._memory = np.array([0.0, 0.0, 0.0, math.nan])
        # the gains as arrays once (not per tick)
        self._kp = np.asarray(gains.position_kp, dtype=float)
        self._kd = np.asarray(gains.position_kd, dtype=float)
        self._ki = np.asarray(gains.position_ki, dtype=float)
        self._gravity_vector = gravity * E_Z
        # the attitude loop's constants as floats (it runs in plain floats)
        self._inertia = tuple(map(float, vehicle.inertia))
        self._att_kp = tuple(map(float, gains.attitude_kp))
        self._att_kd = tuple(map(float, gains.attitude_kd))
        laws = kernels.compiled_module(COMPILED_LAWS)  # None: the methods below
        self._compiled_command = None if laws is None else laws.cascade_command
        self._compiled_update = None if laws is None else laws.cascade_update
        # the compiled code's constants (the _numba_laws.CASCADE_* layout)
        self.compiled_constants = (
            np.array([*self._kp, *self._kd, *self._ki, self.integral_limit, hover_mass, gravity,
                      gains.max_tilt, *self._inertia, *self._att_kp, *self._att_kd,
                      self.mixer.square_min, self.mixer.square_max], dtype=float),
            np.ascontiguousarray(self.mixer.pinv), np.ascontiguousarray(self.mixer.collective))

    @property
    def integral(self) -> np.ndarray:
        """The position loop's integral term [m/s^2], world (x, y, z)."""
        return self._memory[:3]

    def position_force(self, t: float, state: UavState, position_ref: np.ndarray,
                       velocity_ref: np.ndarray, acceleration_ref: np.ndarray) -> np.ndarray:
        """Force the thrust should produce, world frame [N]."""
        t_prev = float(self._memory[3])
        dt = 0.0 if math.isnan(t_prev) else max(0.0, t - t_prev)
        self._memory[3] = t
        error = position_ref - state.position
        integral = np.minimum(np.maximum(self.integral + self._ki * error * dt,
                                         -self.integral_limit), self.integral_limit)
        self._memory[:3] = integral
        accel = (acceleration_ref + self._kp * error
                 + self._kd * (velocity_ref - state.velocity)
                 + integral)
        return self.hover_mass * (accel + self._gravity_vector)

    def attitude_torque(self, state: UavState, setpoint: Sequence[float]) -> np.ndarray:
        """Body torque [N m] driving the Euler angles to `setpoint` (roll, pitch, yaw) [rad]."""
        p, q, r = state.body_rates.tolist()   # plain floats: the per-tick path
        ix, iy, iz = self._inertia
        jp, jq, jr = ix * p, iy * q, iz * r
        gyro = (q * jr - r * jq, r * jp - p * jr, p * jq - q * jp)  # omega x J omega
        torque = []
        for axis, (wanted, angle, rate) in enumerate(zip(setpoint, state.euler.tolist(),
                                                         (p, q, r))):
            error = wrap_angle(wanted - angle)
            accel = self._att_kp[axis] * error - self._att_kd[axis] * rate
            torque.append(self._inertia[axis] * accel + gyro[axis])
        return np.array(torque)

    def command(self, state: UavState, force: np.ndarray, yaw: float) -> ControlOutput:
        """Rotor speeds that produce `force` (world) at heading `yaw`."""
        if self._compiled_command is not None:
            return ControlOutput(*self._compiled_command(
                *self.compiled_constants, state.euler, state.body_rates,
                np.asarray(force, dtype=float), float(yaw)))
        roll, pitch, thrust = attitude_from_force(force, yaw, self.gains.max_tilt)
        setpoint = (roll, pitch, float(yaw))
        # the thrust acts along the current body z: ask for the part along it
        torque = self.attitude_torque(state, setpoint)
        speeds, saturated = self.mixer.rotor_speeds(thrust, torque)
        return ControlOutput(speeds, saturated, np.array(setpoint), thrust)

    def update(self, t: float, state: UavState, position_ref: np.ndarray,
               velocity_ref: np.ndarray, acceleration_ref: np.ndarray,
               yaw_ref: float = 0.0) -> ControlOutput:
        """One control tick at simulated time t [s]."""
        if self._compiled_update is not None:
            return ControlOutput(*self._compiled_update(
                *self.compiled_constants, self._memory, t, state.position, state.velocity,
                state.euler, state.body_rates, position_ref, velocity_ref, acceleration_ref,
                float(yaw_ref)))
        force = self.position_force(t, state, position_ref, velocity_ref, acceleration_ref)
        return self.command(state, force, yaw_ref)


def balancing_rotor_speed(vehicle: MultirotorParams, supported_mass: float,
                          gravity: float) -> float:
    """Equal rotor speed whose thrust carries `supported_mass` [kg] in hover [rad/s]."""
    per_rotor = supported_mass * gravity / vehicle.n_rotors
    return math.sqrt(per_rotor / vehicle.thrust_coefficient)
