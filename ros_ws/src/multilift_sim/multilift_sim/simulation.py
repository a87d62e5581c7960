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
from multilift_sim.nullspace import make_model
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
    # payload swing: horizontal distance of the payload from where it hung at t = 0 relative
    # to the UAVs' centroid (the payload's tracking error with respect to the formation) [m]
    max_payload_swing: float = 0.0
    sum_sq_payload_swing: float = 0.0
    swing_samples: int = 0

    def __post_init__(self) -> None:
        self.max_rotor_speed = [0.0] * self.n_uavs
        self.saturated_time = [0.0] * self.n_uavs

    def add_swing(self, swing: float) -> None:
        self.max_payload_swing = max(self.max_payload_swing, swing)
        self.sum_sq_payload_swing += swing * swing
        self.swing_samples += 1

    def as_dict(self) -> dict:
        out = {k: v for k, v in self.__dict__.items()
               if k not in ('sum_sq_payload_swing', 'swing_samples')}
        out['rms_payload_swing'] = math.sqrt(self.sum_sq_payload_swing
                                             / max(self.swing_samples, 1))
        return out


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
        self.model = make_model(scenario.formation_params(baumgarte_alpha, baumgarte_beta),
                                sim.integrator)
        self.n = scenario.n_uavs
        self.state = initial_state(scenario, model=self.model)
        self.tick = 0
        self.tick_count = sim.tick_count
        self.period_ns = int(round(1e9 / sim.control_rate))
        self.steps_per_tick = sim.physics_steps_per_tick
        self.dt = 1.0 / sim.physics_rate
        self.stats = RunStatistics(self.n)
        self._rest_offset: tuple[float, float] | None = None
        self._lengths = [u.cable_length for u in scenario.uavs]          # l_i [m]
        rotor_counts = {u.vehicle.n_rotors for u in scenario.uavs}
        self._uniform_rotors = rotor_counts.pop() if len(rotor_counts) == 1 else None
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
        nq = 6 * n + 3
        # one copy of the UAV block; every UavSnapshot field is a view into it
        uav_q = self.state[:6 * n].reshape(n, 6).copy()
        uav_qd = self.state[nq:nq + 6 * n].reshape(n, 6).copy()
        euler = uav_q[:, 3:]
        sines, cosines = np.sin(euler.T), np.cos(euler.T)
        s_phi, s_th, s_psi = sines
        c_phi, c_th, c_psi = cosines
        # R = Rz(psi) Ry(theta) Rx(phi), body -> world, as kinematics.rotation_matrix
        rotations = np.empty((n, 3, 3))
        rotations[:, 0, 0] = c_psi * c_th
        rotations[:, 0, 1] = c_psi * s_th * s_phi - s_psi * c_phi
        rotations[:, 0, 2] = c_psi * s_th * c_phi + s_psi * s_phi
        rotations[:, 1, 0] = s_psi * c_th
        rotations[:, 1, 1] = s_psi * s_th * s_phi + c_psi * c_phi
        rotations[:, 1, 2] = s_psi * s_th * c_phi - c_psi * s_phi
        rotations[:, 2, 0] = -s_th
        rotations[:, 2, 1] = c_th * s_phi
        rotations[:, 2, 2] = c_th * c_phi
        phi_dot, theta_dot, psi_dot = uav_qd[:, 3], uav_qd[:, 4], uav_qd[:, 5]
        rates = np.empty((n, 3))  # omega = W(eta) eta_dot, seed Eq. 2.7
        rates[:, 0] = phi_dot - s_th * psi_dot
        rates[:, 1] = c_phi * theta_dot + s_phi * c_th * psi_dot
        rates[:, 2] = -s_phi * theta_dot + c_phi * c_th * psi_dot
        uavs = tuple(UavSnapshot(position=uav_q[i, :3], velocity=uav_qd[i, :3],
                                 euler=euler[i], rotation=rotations[i], body_rates=rates[i])
                     for i in range(n))
        return Snapshot(self.t_ns, uavs, self.state[6 * n:nq].copy(),
                        self.state[nq + 6 * n:].copy())

    def cable_state(self, rotor_speeds: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray,
                                                                    np.ndarray]:
        """(tension [N], g [m^2], g_dot [m^2/s]) at the current tick under `rotor_speeds`."""
        tension = self.model.cable_tension(self.t, self.state, rotor_speeds)
        g, g_dot = self.model.constraint_residuals(self.state)
        return np.asarray(tension), np.asarray(g), np.asarray(g_dot)

    def advance(self, rotor_speeds: list[np.ndarray], saturated: list[np.ndarray]) -> None:
        """Hold `rotor_speeds` over one control period and integrate to the next tick."""
        speeds = self._checked_speeds(rotor_speeds)
        stats = self.stats
        peaks = np.max(np.abs(speeds), axis=1) if isinstance(speeds, np.ndarray) \
            else [float(np.max(np.abs(s))) for s in speeds]
        period = self.period_ns * 1e-9
        for i, (peak, flags) in enumerate(zip(peaks, saturated)):
            if peak > stats.max_rotor_speed[i]:
                stats.max_rotor_speed[i] = float(peak)
            if np.any(flags):
                stats.saturated_time[i] += period
        model = self.model
        t0 = self.t
        if isinstance(model, FormationModel) and model.uses_float_kernel:
            # the wrenches formed once per tick (the speeds are held) and the tension taken
            # from the first stage of the first step (the multipliers at this state)
            wrenches = model.wrenches(speeds).tolist()
            x, multipliers = model.rk4_floats(self.state.tolist(), wrenches, self.dt)
            for _ in range(self.steps_per_tick - 1):
                x = model.rk4_floats(x, wrenches, self.dt)[0]
            self.state = np.array(x)
            tension = [2.0 * length * lam for length, lam in zip(self._lengths, multipliers)]
            residuals = self._residuals_floats(x)
        elif isinstance(model, FormationModel):
            residuals = None
            wrenches = model.wrenches(speeds)
            _, multipliers = model.accelerations_from_wrenches(self.state, wrenches)
            tension = 2.0 * model.cable_lengths * multipliers
            x = self.state
            for _ in range(self.steps_per_tick):
                x = model._rk4_arrays(x, wrenches, self.dt)
            self.state = x
        else:
            residuals = None
            tension = np.asarray(model.cable_tension(t0, self.state, speeds))
            for k in range(self.steps_per_tick):
                self.state = model.step(t0 + k * self.dt, self.state, speeds, self.dt)
        stats.min_tension = min(stats.min_tension, float(min(tension)))
        stats.max_tension = max(stats.max_tension, float(max(tension)))
        self.tick += 1
        stats.simulated_time = self.t
        self._check(self.t, residuals)

    def _residuals_floats(self, x: list[float]) -> tuple[list[float], list[float]] | None:
        """(g [m^2], g_dot [m^2/s]) per cable from the state as a list (the arithmetic of
        FormationModel.constraint_residuals in floats), or None when x is not finite."""
        if not all(map(math.isfinite, x)):
            return None
        n = self.n
        nq, p = 6 * n + 3, 6 * n
        px, py, pz = x[p:p + 3]
        pvx, pvy, pvz = x[nq + p:nq + p + 3]
        g, g_dot = [], []
        for i, length in enumerate(self._lengths):
            b = 6 * i
            dx, dy, dz = px - x[b], py - x[b + 1], pz - x[b + 2]
            dvx, dvy, dvz = pvx - x[nq + b], pvy - x[nq + b + 1], pvz - x[nq + b + 2]
            g.append(dx * dx + dy * dy + dz * dz - length * length)
            g_dot.append(2.0 * (dx * dvx + dy * dvy + dz * dvz))
        return g, g_dot

    def _checked_speeds(self, rotor_speeds: list[np.ndarray]) -> np.ndarray | list[np.ndarray]:
        """The commands as one (n, n_r) array (a list when the rotor counts differ), or
        SimulationStopped naming the UAV whose command has the wrong size or is not finite."""
        stacked = None
        if self._uniform_rotors is not None and len(rotor_speeds) == self.n:
            try:
                stacked = np.asarray(rotor_speeds, dtype=float)
            except (ValueError, TypeError):  # ragged: the loop below names the UAV
                stacked = None
            if stacked is not None and stacked.shape != (self.n, self._uniform_rotors):
                stacked = None
            if stacked is not None and np.all(np.isfinite(stacked)):
                return stacked
        out = []
        for i, speeds in enumerate(rotor_speeds):
            speeds = np.asarray(speeds, dtype=float)
            if speeds.shape != (self.scenario.uavs[i].vehicle.n_rotors,):
                raise SimulationStopped(
                    f'uav{i + 1}: rotor command has {speeds.size} speeds, the vehicle has '
                    f'{self.scenario.uavs[i].vehicle.n_rotors} rotors (t = {self.t:.3f} s)')
            if not np.all(np.isfinite(speeds)):
                raise SimulationStopped(f'uav{i + 1}: rotor command is not finite '
                                        f'({speeds.tolist()}) at t = {self.t:.3f} s')
            out.append(speeds)
        if len(out) != self.n:
            raise SimulationStopped(f'{len(out)} rotor commands for {self.n} UAVs '
                                    f'(t = {self.t:.3f} s)')
        return out

    def _payload_offset(self) -> tuple[float, float]:
        """Horizontal payload position relative to the UAVs' centroid [m]."""
        n, x = self.n, self.state
        cx = sum(x[6 * i] for i in range(n)) / n
        cy = sum(x[6 * i + 1] for i in range(n)) / n
        return float(x[6 * n] - cx), float(x[6 * n + 1] - cy)

    def _check(self, t: float, residuals: tuple[list[float], list[float]] | None = None
               ) -> None:
        """Algorithm 1, lines 10-13: stop when a cable leaves its tolerance. `residuals`:
        (g, g_dot) already computed from a finite state (`_residuals_floats`)."""
        if residuals is None:
            if not np.all(np.isfinite(self.state)):
                raise SimulationStopped(f'the formation state became non-finite at '
                                        f't = {t:.3f} s')
            g, g_dot = (a.tolist() for a in self.model.constraint_residuals(self.state))
        else:
            g, g_dot = residuals
        sim = self.scenario.simulation
        offset = self._payload_offset()
        if self._rest_offset is None:
            self._rest_offset = offset
        self.stats.add_swing(math.hypot(offset[0] - self._rest_offset[0],
                                        offset[1] - self._rest_offset[1]))
        if self.scenario.gusts:
            gust = self.model.gust_velocity_at_payload(t, self.state)
            self.stats.max_gust_speed = max(self.stats.max_gust_speed,
                                            float(np.linalg.norm(gust)))
        abs_g, abs_g_dot = [abs(v) for v in g], [abs(v) for v in g_dot]
        peak, peak_rate = max(abs_g), max(abs_g_dot)
        worst, worst_rate = abs_g.index(peak), abs_g_dot.index(peak_rate)
        self.stats.max_abs_constraint = max(self.stats.max_abs_constraint, peak)
        self.stats.max_abs_constraint_rate = max(self.stats.max_abs_constraint_rate, peak_rate)
        if peak > sim.constraint_tolerance:
            raise SimulationStopped(
                f'cable {worst + 1}: constraint residual |g| = {peak:.3g} m^2 exceeds '
                f'the tolerance {sim.constraint_tolerance:g} m^2 at t = {t:.3f} s '
                '(Algorithm 1: change the step or the Baumgarte gains)')
        if peak_rate > sim.constraint_rate_tolerance:
            raise SimulationStopped(
                f'cable {worst_rate + 1}: constraint rate |g_dot| = {peak_rate:.3g} m^2/s '
                f'exceeds the tolerance {sim.constraint_rate_tolerance:g} m^2/s at t = {t:.3f} s')
