"""The simulation loop of seed Algorithm 1, free of ROS: state at each control tick in, rotor
speeds in, the formation DAE integrated to the next tick, the constraints checked.

The simulator node and the headless runner both drive this class, so they compute the same
thing. World frame, SI units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from multilift_sim.dynamics import FormationModel, StateLayout, initial_state_single_lift
from multilift_sim.formation_geometry import (hanging_payload, nominal_positions,
                                              swing_about_uav_axis)
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.scenario import Scenario


class SimulationStopped(RuntimeError):
    """The run cannot go on; the message names what, where and when."""


@dataclass(frozen=True)
class UavSnapshot:
    position: np.ndarray     # world [m]
    velocity: np.ndarray     # world [m/s]
    euler: np.ndarray        # ZYX (roll, pitch, yaw) [rad]
    rotation: np.ndarray     # body -> world
    body_rates: np.ndarray   # FLU [rad/s]


@dataclass(frozen=True)
class Snapshot:
    """The formation at one control tick."""
    t_ns: int
    uavs: tuple[UavSnapshot, ...]
    payload_position: np.ndarray  # world [m]
    payload_velocity: np.ndarray  # world [m/s]


@dataclass
class RunStatistics:
    """What the summary reports, accumulated tick by tick."""
    n_uavs: int
    max_abs_constraint: float = 0.0        # max_i,t |g_i| [m^2]
    max_abs_constraint_rate: float = 0.0   # max_i,t |g_i_dot| [m^2/s]
    max_rotor_speed: list = field(default_factory=list)   # per UAV [rad/s]
    saturated_time: list = field(default_factory=list)    # per UAV [s]
    min_tension: float = math.inf          # [N]
    max_tension: float = -math.inf         # [N]
    simulated_time: float = 0.0            # [s]
    max_gust_speed: float = 0.0            # peak gust speed met by the payload [m/s]

    def __post_init__(self) -> None:
        self.max_rotor_speed = [0.0] * self.n_uavs
        self.saturated_time = [0.0] * self.n_uavs

    def as_dict(self) -> dict:
        return {k: v for k, v in self.__dict__.items()}


def initial_state(scenario: Scenario, model: FormationModel) -> np.ndarray:
    """Initial formation state on the constraint manifold, at rest."""
    if scenario.n_uavs == 1:
        uav = scenario.uavs[0]
        return initial_state_single_lift(np.asarray(uav.position, dtype=float),
                                         np.array([0.0, 0.0, uav.yaw]), uav.cable_length,
                                         scenario.payload.alpha, scenario.payload.beta)
    formation = scenario.formation
    uavs, payload = formation_start(scenario)
    if scenario.payload.swing:
        payload = swing_about_uav_axis(payload, uavs[0], uavs[1], scenario.payload.swing)
    euler = np.array([[0.0, 0.0, u.yaw] for u in scenario.uavs])
    layout = StateLayout(scenario.n_uavs)
    assert formation is not None
    return layout.pack(uavs, euler, payload)


def formation_start(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """(UAV positions (n, 3), payload position) at t = 0, world [m]."""
    f = scenario.formation
    uavs = nominal_positions(f.geometry, scenario.n_uavs, scenario.uavs[0].position, f.offsets,
                             f.distance, f.half_angle)
    return hanging_payload(uavs, [u.cable_length for u in scenario.uavs])


class FormationSimulator:
    """Steps the formation DAE from control tick to control tick (seed Algorithm 1)."""

    def __init__(self, scenario: Scenario, baumgarte_alpha: float | None = None,
                 baumgarte_beta: float | None = None):
        self.scenario = scenario
        sim = scenario.simulation
        self.model = FormationModel(scenario.formation_params(baumgarte_alpha, baumgarte_beta))
        self.n = scenario.n_uavs
        self.state = initial_state(scenario, model=self.model)
        self.tick = 0
        self.tick_count = sim.tick_count
        self.period_ns = int(round(1e9 / sim.control_rate))
        self.steps_per_tick = sim.physics_steps_per_tick
        self.dt = 1.0 / sim.physics_rate
        self.stats = RunStatistics(self.n)
        self._check(0.0)

    @property
    def t_ns(self) -> int:
        return self.tick * self.period_ns

    @property
    def t(self) -> float:
        return self.t_ns * 1e-9

    @property
    def finished(self) -> bool:
        return self.tick >= self.tick_count

    def snapshot(self) -> Snapshot:
        n = self.n
        q = self.state[:6 * n + 3]
        qd = self.state[6 * n + 3:]
        uavs = []
        for i in range(n):
            eta = q[6 * i + 3:6 * i + 6]
            eta_dot = qd[6 * i + 3:6 * i + 6]
            s_phi, c_phi = math.sin(eta[0]), math.cos(eta[0])
            s_th, c_th = math.sin(eta[1]), math.cos(eta[1])
            w = np.array([[1.0, 0.0, -s_th], [0.0, c_phi, s_phi * c_th],
                          [0.0, -s_phi, c_phi * c_th]])  # seed Eq. 2.7
            uavs.append(UavSnapshot(position=q[6 * i:6 * i + 3].copy(),
                                    velocity=qd[6 * i:6 * i + 3].copy(), euler=eta.copy(),
                                    rotation=rotation_matrix(eta), body_rates=w @ eta_dot))
        return Snapshot(self.t_ns, tuple(uavs), q[6 * n:].copy(), qd[6 * n:].copy())

    def cable_state(self, rotor_speeds: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray,
                                                                    np.ndarray]:
        """(tension [N], g [m^2], g_dot [m^2/s]) at the current tick under `rotor_speeds`."""
        tension = self.model.cable_tension(self.t, self.state, rotor_speeds)
        g, g_dot = self.model.constraint_residuals(self.state)
        return np.asarray(tension), np.asarray(g), np.asarray(g_dot)

    def advance(self, rotor_speeds: list[np.ndarray], saturated: list[np.ndarray]) -> None:
        """Hold `rotor_speeds` over one control period and integrate to the next tick."""
        for i, (speeds, flags) in enumerate(zip(rotor_speeds, saturated)):
            speeds = np.asarray(speeds, dtype=float)
            if speeds.shape != (self.scenario.uavs[i].vehicle.n_rotors,):
                raise SimulationStopped(
                    f'uav{i + 1}: rotor command has {speeds.size} speeds, the vehicle has '
                    f'{self.scenario.uavs[i].vehicle.n_rotors} rotors (t = {self.t:.3f} s)')
            if not np.all(np.isfinite(speeds)):
                raise SimulationStopped(f'uav{i + 1}: rotor command is not finite '
                                        f'({speeds.tolist()}) at t = {self.t:.3f} s')
            self.stats.max_rotor_speed[i] = max(self.stats.max_rotor_speed[i],
                                                float(np.max(np.abs(speeds))))
            if np.any(flags):
                self.stats.saturated_time[i] += self.period_ns * 1e-9
        tension, _, _ = self.cable_state(rotor_speeds)
        self.stats.min_tension = min(self.stats.min_tension, float(np.min(tension)))
        self.stats.max_tension = max(self.stats.max_tension, float(np.max(tension)))
        t0 = self.t
        for k in range(self.steps_per_tick):
            self.state = self.model.step(t0 + k * self.dt, self.state, rotor_speeds, self.dt)
        self.tick += 1
        self.stats.simulated_time = self.t
        self._check(self.t)

    def _check(self, t: float) -> None:
        """Algorithm 1, lines 10-13: stop when a cable leaves its tolerance."""
        if not np.all(np.isfinite(self.state)):
            raise SimulationStopped(f'the formation state became non-finite at t = {t:.3f} s')
        g, g_dot = self.model.constraint_residuals(self.state)
        sim = self.scenario.simulation
        if self.scenario.gusts:
            gust = self.model.gust_velocity_at_payload(t, self.state)
            self.stats.max_gust_speed = max(self.stats.max_gust_speed,
                                            float(np.linalg.norm(gust)))
        self.stats.max_abs_constraint = max(self.stats.max_abs_constraint,
                                            float(np.max(np.abs(g))))
        self.stats.max_abs_constraint_rate = max(self.stats.max_abs_constraint_rate,
                                                 float(np.max(np.abs(g_dot))))
        worst = int(np.argmax(np.abs(g)))
        if abs(g[worst]) > sim.constraint_tolerance:
            raise SimulationStopped(
                f'cable {worst + 1}: constraint residual |g| = {abs(g[worst]):.3g} m^2 exceeds '
                f'the tolerance {sim.constraint_tolerance:g} m^2 at t = {t:.3f} s '
                '(Algorithm 1: change the step or the Baumgarte gains)')
        worst = int(np.argmax(np.abs(g_dot)))
        if abs(g_dot[worst]) > sim.constraint_rate_tolerance:
            raise SimulationStopped(
                f'cable {worst + 1}: constraint rate |g_dot| = {abs(g_dot[worst]):.3g} m^2/s '
                f'exceeds the tolerance {sim.constraint_rate_tolerance:g} m^2/s at t = {t:.3f} s')
