"""The simulation loop of seed Algorithm 1, free of ROS: state at each control tick in, rotor
speeds in, the formation DAE integrated to the next tick, the constraints checked.

The simulator node and the headless runner both drive this class, so they compute the same
thing. World frame, SI units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multilift_sim import kernels
from multilift_sim.dynamics import Integration, initial_state_single_lift
from multilift_sim.formation_geometry import (hanging_payload, nominal_positions,
                                              swing_about_uav_axis)
from multilift_sim.formation_params import StateLayout
from multilift_sim.formulations import make_formulation
from multilift_sim.physics.events import apply_events, held_commands
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_COLUMNS, MEASURED_EULER,
                                          MEASURED_POSITION, MEASURED_VELOCITY,
                                          ODOMETRY_BODY_VELOCITY, ODOMETRY_COLUMNS,
                                          ODOMETRY_QUATERNION, ODOMETRY_ROTATION)
from multilift_sim.physics.measurement import odometry_states
from multilift_sim.physics.rigid_payload import payload_rotation
from multilift_sim.physics.sensors import sensed_states
from multilift_sim.scenario import Scenario
from multilift_sim.schedules import event_array, event_records, sensor_arrays, wind_series
from multilift_sim.statistics import RunStatistics
from multilift_sim.statistics.layout import CHECK_G, CHECK_G_DOT, CHECK_NON_FINITE


class SimulationStopped(RuntimeError):
    """The run cannot go on; the message names what, where and when."""


@dataclass(frozen=True)
class UavSnapshot:
    position: np.ndarray     # world [m]
    velocity: np.ndarray     # world [m/s]
    euler: np.ndarray        # ZYX (roll, pitch, yaw) [rad]
    rotation: np.ndarray     # R, body -> world (3, 3)
    body_rates: np.ndarray   # FLU [rad/s]
    body_velocity: np.ndarray  # R^T velocity, FLU [m/s]
    orientation: np.ndarray  # quaternion (x, y, z, w) of R


@dataclass(frozen=True)
class Snapshot:
    """The formation at one control tick."""
    t_ns: int
    uavs: tuple[UavSnapshot, ...]
    payload_position: np.ndarray  # world [m]
    payload_velocity: np.ndarray  # world [m/s]
    odometry: np.ndarray  # every UAV's row (n, ODOMETRY_COLUMNS), physics.layout ODOMETRY_*
    # what the controllers receive of every UAV (n, MEASURED_COLUMNS): the odometry's
    # MEASURED_* slots, or with `sensors:` their measurement (physics.sensors)
    measured: np.ndarray
    # a rigid payload's (orientation (x, y, z, w), body rates [rad/s], R_p (3, 3) payload frame
    # -> world); None for a point payload
    payload_attitude: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None


def stop_message(status: int, cable: int, value: float, t: float, sim) -> str:
    """Why Algorithm 1 stopped a run (a `statistics.accumulators.run_check` status other than
    CHECK_OK): the non-finite state, or the cable (from 0) whose |g| [m^2] or |g_dot| [m^2/s]
    `value` left its tolerance (`sim`: the scenario's SimulationConfig), at t [s]."""
    if status == CHECK_NON_FINITE:
        return f'the formation state became non-finite at t = {t:.3f} s'
    if status == CHECK_G:
        return (f'cable {cable + 1}: constraint residual |g| = {value:.3g} m^2 exceeds '
                f'the tolerance {sim.constraint_tolerance:g} m^2 at t = {t:.3f} s '
                '(Algorithm 1: change the step or the Baumgarte gains)')
    return (f'cable {cable + 1}: constraint rate |g_dot| = {value:.3g} m^2/s '
            f'exceeds the tolerance {sim.constraint_rate_tolerance:g} m^2/s at t = {t:.3f} s')


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
    """Initial formation state on the constraint manifold, at rest."""
    if scenario.n_uavs == 1:
        uav = scenario.uavs[0]
        return initial_state_single_lift(np.asarray(uav.position, dtype=float),
                                         np.array([0.0, 0.0, uav.yaw]), uav.cable_length,
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
    return hanging_payload(uavs, [u.cable_length for u in scenario.uavs],
                           scenario.payload.attach_points, uav_offsets(scenario))


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


def payload_attitude(state: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A rigid payload's (orientation (x, y, z, w), body rates [rad/s], R_p (3, 3) payload
    frame -> world) in a state of n UAVs (Snapshot.payload_attitude; the engine's bag too)."""
    base = 2 * (6 * n + 3)
    w, x, y, z = state[base:base + 4]
    return (np.array([x, y, z, w]), state[base + 4:base + 7].copy(),
            payload_rotation(state, base))


@dataclass(frozen=True)
class TickCables:
    """What `/formation/state` of a tick needs, kept while the tick is integrated: its
    commands, g [m^2] and g_dot [m^2/s] at the tick, and which cables are taut."""
    tick: int
    rotor_speeds: list[np.ndarray]
    constraint: np.ndarray
    constraint_rate: np.ndarray
    taut: np.ndarray


class FormationSimulator:
    """Steps the formation DAE from control tick to control tick (seed Algorithm 1)."""

    def __init__(self, scenario: Scenario, baumgarte_alpha: float | None = None,
                 baumgarte_beta: float | None = None):
        self.scenario = scenario
        sim = scenario.simulation
        params = scenario.formation_params(baumgarte_alpha, baumgarte_beta)
        self.model = make_formulation(sim.integrator, params, scenario.cable_model)
        self.n = scenario.n_uavs
        self.state = initial_state(scenario)
        self.tick = 0
        self.tick_count = sim.tick_count
        self.period_ns = int(round(1e9 / sim.control_rate))
        self.steps_per_tick = sim.physics_steps_per_tick
        self.dt = 1.0 / sim.physics_rate
        self.stats = RunStatistics(self.n)
        # the last integration (its cable_tension is the tension at the tick it started from)
        # and (g, g_dot) at the current state, for whoever reports them (the headless bag)
        self.last_step: Integration | None = None
        self.residuals: tuple[np.ndarray, np.ndarray] | None = None
        # the air velocity at the payload in the current state [m/s], world (/payload/gust)
        self.payload_gust: np.ndarray = np.zeros(3)
        self._reach = cable_reach(scenario)
        self._all_taut = np.ones(self.n, dtype=bool)  # a formulation without a taut set's
        self._swing_every = swing_sampling(self.n)
        # the scenario's events (physics.events), the row of the next one to come and the rows
        # of those that happened at the current tick
        self.events = event_array(scenario)
        self.next_event = 0
        self.happened = range(0)
        # the commands applied last (held while a controller is silent: physics.events)
        rotors = max(u.vehicle.n_rotors for u in scenario.uavs)
        self.silent_until = np.zeros(self.n, dtype=np.int64)
        self.held = np.full((self.n, rotors), math.nan)
        self.held_saturated = np.zeros((self.n, rotors), dtype=bool)
        self._silences = any(e.type == 'controller_silence' for e in scenario.events)
        # the wind of each period: the steady wind plus the unsteady wind of its tick
        self._wind_series = wind_series(scenario)
        self._steady_wind = np.array(scenario.wind, dtype=float)
        self._set_wind()
        # what the controllers receive (physics.sensors): its arrays and memory
        self.sensors = sensor_arrays(scenario)
        # the functions of events and sensors, compiled or not as MULTILIFT_KERNEL says now
        self._sensed_states = kernels.runnable(sensed_states)
        self._held_commands = kernels.runnable(held_commands)
        self._apply_events_function = kernels.runnable(apply_events)
        self._sensor_history, self._sensor_seen = self.sensors.memory()
        self._apply_events()
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
        """The formation at the current tick: every UAV's numbers from one call of
        physics.measurement.odometry_states, viewed from a fresh array (none of the
        simulator's state), and what the controllers receive of them (with `sensors:`,
        physics.sensors.sensed_states; call it once a tick, or more: the same result)."""
        n = self.n
        nq = 6 * n + 3
        rows = np.empty((1, n, ODOMETRY_COLUMNS))
        odometry_states(self.state.reshape(1, -1), n, rows)
        odometry = rows[0]
        measured = odometry[:, :MEASURED_COLUMNS].copy()
        sensors = self.sensors
        if sensors.on:
            self._sensed_states(
                measured, self.tick, sensors.errors, sensors.delivered, sensors.every,
                sensors.latency, self._sensor_history, self._sensor_seen)
        uavs = tuple(UavSnapshot(
            position=row[MEASURED_POSITION:MEASURED_POSITION + 3],
            velocity=row[MEASURED_VELOCITY:MEASURED_VELOCITY + 3],
            euler=row[MEASURED_EULER:MEASURED_EULER + 3],
            rotation=row[ODOMETRY_ROTATION:ODOMETRY_ROTATION + 9].reshape(3, 3),
            body_rates=row[MEASURED_BODY_RATES:MEASURED_BODY_RATES + 3],
            body_velocity=row[ODOMETRY_BODY_VELOCITY:ODOMETRY_BODY_VELOCITY + 3],
            orientation=row[ODOMETRY_QUATERNION:ODOMETRY_QUATERNION + 4]) for row in odometry)
        attitude = payload_attitude(self.state, n) if self.model.layout.rigid_payload else None
        return Snapshot(self.t_ns, uavs, self.state[6 * n:nq].copy(),
                        self.state[nq + 6 * n:2 * nq].copy(), odometry, measured, attitude)

    @property
    def taut(self) -> np.ndarray:
        """Which cables are taut, (n,) bool (always all with cable_model: rigid)."""
        taut = getattr(self.model, 'taut', None)
        return np.ones(self.n, dtype=bool) if taut is None else taut.copy()

    def cable_state(self, rotor_speeds: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray,
                                                                    np.ndarray]:
        """(tension [N], g [m^2], g_dot [m^2/s]) at the current tick under `rotor_speeds`."""
        tension = self.model.cable_tension(self.t, self.state, rotor_speeds)
        g, g_dot = self.model.constraint_residuals(self.state)
        return np.asarray(tension), np.asarray(g), np.asarray(g_dot)

    def tick_cables(self, rotor_speeds: list[np.ndarray]) -> TickCables:
        """This tick's cable facts under `rotor_speeds`, before `advance`; the tension follows
        from `cables_of`."""
        g, g_dot = self.residuals
        return TickCables(self.tick, rotor_speeds, g, g_dot, self.taut)

    def cables_of(self, held: TickCables) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tension [N], g [m^2], g_dot [m^2/s]) at the tick of `held`: the tension from the
        integration that left it when the simulator has moved on by one tick (no second solve
        of the DAE), else solved here (the run ended at that tick)."""
        if self.tick == held.tick + 1 and self.last_step is not None:
            return self.last_step.cable_tension, held.constraint, held.constraint_rate
        tension = np.asarray(self.model.cable_tension(self.t, self.state, held.rotor_speeds))
        return tension, held.constraint, held.constraint_rate

    def advance(self, rotor_speeds: list[np.ndarray], saturated: list[np.ndarray]) -> None:
        """Hold `rotor_speeds` over one control period and integrate to the next tick."""
        speeds = self._checked_speeds(rotor_speeds)
        if self._silences:
            speeds, saturated = self._held(speeds, saturated)
        self.stats.add_commands(speeds, saturated, self.period_ns * 1e-9)
        step = self.model.integrate(self.state, speeds, self.dt, self.steps_per_tick)
        self.state = step.state
        self.last_step = step
        self.stats.add_tensions(step.cable_tension)
        if self.scenario.cable_model == 'slack':
            self.stats.add_slack(self.taut, self.period_ns * 1e-9)
        self.tick += 1
        self._apply_events()
        self._set_wind()
        self._check(self.t, (step.constraint, step.constraint_rate))

    def _held(self, speeds, saturated) -> tuple:
        """The commands applied over this period: a silent controller's held
        (`physics.events.held_commands`), as (n, rotors) arrays, or lists of each UAV's own
        where the rotor counts differ."""
        padded = np.zeros_like(self.held)
        flags = np.zeros_like(self.held_saturated)
        for i, (own, own_flags) in enumerate(zip(speeds, saturated)):
            padded[i, :len(own)] = own
            flags[i, :len(own)] = own_flags
        self._held_commands(padded, flags, self.tick, self.silent_until, self.held,
                                        self.held_saturated)
        if self._uniform_rotors is not None:
            return self.held.copy(), self.held_saturated.copy()
        counts = [u.vehicle.n_rotors for u in self.scenario.uavs]
        return ([self.held[i, :c].copy() for i, c in enumerate(counts)],
                [self.held_saturated[i, :c].copy() for i, c in enumerate(counts)])

    def _set_wind(self) -> None:
        """The model's wind for the period from the current tick: the steady wind plus the
        tick's unsteady wind (`wind_series`), as the engine's tick adds them."""
        if len(self._wind_series):
            self.model.set_wind(self.wind)

    @property
    def wind(self) -> np.ndarray:
        """The air's velocity everywhere over the period from the current tick [m/s], world:
        the steady wind plus the tick's unsteady wind (`wind_series`)."""
        return self._steady_wind + (self._wind_series[self.tick] if len(self._wind_series)
                                    else 0.0)

    def happened_rows(self) -> np.ndarray:
        """The rows (physics.layout EVENT_*) of the events the current tick is the first to
        show."""
        return self.events[self.happened.start:self.happened.stop]

    def events_summary(self) -> list[dict]:
        """The events that have happened, as the run's summary names them."""
        return event_records(self.events[:self.next_event])

    def _apply_events(self) -> None:
        """The scenario's events of the current tick, applied to the model before the tick's
        state is checked and sent (`physics.events.apply_events`); their rows in `happened`."""
        first = self.next_event
        if first < len(self.events):
            model = self.model
            self.next_event = self._apply_events_function(
                self.events, first, self.tick, model.effectiveness, model.taut,
                model.released, self.silent_until)
        self.happened = range(first, self.next_event)

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
            if stacked is not None and np.isfinite(stacked).all():
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

    def _check(self, t: float,
               residuals: tuple[np.ndarray, np.ndarray] | None = None) -> None:
        """Algorithm 1, lines 10-13: stop when a cable leaves its tolerance (or the state is
        no longer finite); `residuals`: (g, g_dot) at this state when already computed. The
        check and the figures it accumulates are `statistics.accumulators.run_check`."""
        g, g_dot = residuals if residuals is not None else \
            self.model.constraint_residuals(self.state)
        taut = getattr(self.model, 'taut', None)
        sim = self.scenario.simulation
        status, cable = self.stats.check(
            self.state, g, g_dot, self._all_taut if taut is None else taut,
            sim.constraint_tolerance, sim.constraint_rate_tolerance, t, self.tick,
            self._swing_every, self._reach)
        if status == CHECK_NON_FINITE:
            raise SimulationStopped(stop_message(status, cable, 0.0, t, sim))
        self.residuals = (g, g_dot)
        gust = self.payload_gust = self.model.gust_velocity_at_payload(t, self.state)
        if self.scenario.gusts:
            east, north, up = gust.tolist()  # the engine's arithmetic (engine.tick.check)
            self.stats.add_gust_speed(math.sqrt(east * east + north * north + up * up))
        if status in (CHECK_G, CHECK_G_DOT):
            value = abs(g[cable]) if status == CHECK_G else abs(g_dot[cable])
            raise SimulationStopped(stop_message(status, cable, value, t, sim))
