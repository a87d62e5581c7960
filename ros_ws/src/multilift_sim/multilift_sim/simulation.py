"""The simulation loop of seed Algorithm 1, free of ROS: state at each control tick in, rotor
speeds in, the formation DAE integrated to the next tick, the constraints checked.

`FormationSimulator` is the physics' compiled tick (`physics.tick`) as a batch of one: the
simulator node and `run_headless` step it a tick a call with the commands their controllers
gave, the engine (`multilift_control.engine`) steps the same functions for B formations.
World frame, SI units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from multilift_sim import kernels
from multilift_sim.formation_params import StateLayout
from multilift_sim.formulations import make_formulation
from multilift_sim.physics import tick as physics_tick
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_COLUMNS, MEASURED_EULER,
                                          MEASURED_POSITION, attitude_slot, MEASURED_VELOCITY,
                                          ODOMETRY_BODY_VELOCITY, ODOMETRY_COLUMNS,
                                          ODOMETRY_QUATERNION, ODOMETRY_ROTATION, REEL_COMMAND,
                                          REEL_LENGTH)
from multilift_sim.estimators.published import ESTIMATE_COLUMNS
from multilift_sim.physics.measurement import odometry_states
from multilift_sim.physics.rigid_payload import payload_rotation
from multilift_sim.scenario import Scenario
from multilift_sim.schedules import event_records
from multilift_sim.statistics import RunStatistics
from multilift_sim.statistics.layout import (CHECK_G, CHECK_NON_FINITE, CHECK_QUATERNION,
                                             QUATERNION_NORM_TOLERANCE)
from multilift_sim.physics.layout import STATUS_CONTACT
from multilift_sim.statistics.clearance import clearance_figures, contact_message
from multilift_sim.tick_arrays import (STOP_CHECKS, PhysicsArrays, PhysicsMemory,
                                       physics_fields, stacked)


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
    # MEASURED_* slots, or with `sensors:` their measurement (multilift_sim.sensors)
    measured: np.ndarray
    # a rigid payload's (orientation (x, y, z, w), body rates [rad/s], R_p (3, 3) payload frame
    # -> world); None for a point payload
    payload_attitude: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    # every cable's length [m] (n,): reeled by a winch (physics.winch), else its own
    cable_lengths: np.ndarray = field(default_factory=lambda: np.zeros(0))
    # every UAV's estimate as /uav{i}/estimate carries it (n, ESTIMATE_COLUMNS:
    # estimators.published), None without an estimator
    estimate: np.ndarray | None = None
    # heavy cables' inner nodes (n, N - 1, 3) [m], world (`cable_model: chain`), else None
    chain_points: np.ndarray | None = None
    # the payload's estimate as /payload/estimate carries it (ESTIMATE_COLUMNS), None without
    # a payload estimator: what the controllers then read of the payload
    payload_estimate: np.ndarray | None = None


def stop_message(status: int, cable: int, value: float, t: float, sim, n_uavs: int) -> str:
    """Why Algorithm 1 stopped a run (a `statistics.accumulators.run_check` status other than
    CHECK_OK): the non-finite state, the body (from 0, in `cable`: a UAV, or n the rigid
    payload) whose quaternion's | |q| - 1 | is `value` (no attitude), or the cable (from 0) whose
    |g| [m^2] or |g_dot| [m^2/s]
    `value` left its tolerance (`sim`: the scenario's SimulationConfig), at t [s], in a
    formation of n_uavs."""
    if status == CHECK_NON_FINITE:
        return f'the formation state became non-finite at t = {t:.3f} s'
    if status == CHECK_QUATERNION:  # `cable`: the body, `value`: | |q| - 1 |
        body = f'uav{cable + 1}' if cable < n_uavs else 'the payload'
        return (f'{body}: its attitude quaternion\'s norm is {value:.3g} off 1 at t = {t:.3f} s '
                f'(beyond {QUATERNION_NORM_TOLERANCE:g}): the state no longer represents an '
                'attitude')
    if status == CHECK_G:
        return (f'cable {cable + 1}: constraint residual |g| = {value:.3g} m^2 exceeds '
                f'the tolerance {sim.constraint_tolerance:g} m^2 at t = {t:.3f} s '
                '(Algorithm 1: change the step or the Baumgarte gains)')
    return (f'cable {cable + 1}: constraint rate |g_dot| = {value:.3g} m^2/s '
            f'exceeds the tolerance {sim.constraint_rate_tolerance:g} m^2/s at t = {t:.3f} s')


def payload_attitude(state: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A rigid payload's (orientation (x, y, z, w), body rates [rad/s], R_p (3, 3) payload
    frame -> world) in a state of n UAVs (Snapshot.payload_attitude; the engine's bag too)."""
    layout = StateLayout(n, rigid_payload=True)
    w, x, y, z = layout.payload_quaternion(state)
    return (np.array([x, y, z, w]), layout.payload_body_rates(state).copy(),
            payload_rotation(state, attitude_slot(n)))


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
    """Steps the formation DAE from control tick to control tick (seed Algorithm 1): the
    compiled `physics.tick` on a batch of one (`arrays`, `memory`: `tick_arrays`)."""

    def __init__(self, scenario: Scenario, baumgarte_alpha: float | None = None,
                 baumgarte_beta: float | None = None):
        self.scenario = scenario
        sim = scenario.simulation
        params = scenario.formation_params(baumgarte_alpha, baumgarte_beta)
        # the formulation: its constants are the tick's; it answers the reporting queries
        # (energy, accelerations) the tick does not
        self.model = make_formulation(sim.integrator, params, scenario.cable_model)
        self.n = scenario.n_uavs
        arrays, memory = physics_fields(scenario, self.model)
        self.arrays = PhysicsArrays(**{name: stacked(name, [arrays[name]])
                                       for name in PhysicsArrays._fields})
        self.memory = PhysicsMemory(**{name: stacked(name, [memory[name]])
                                       for name in PhysicsMemory._fields})
        self.stats = RunStatistics(self.n, self.memory.run[0])
        self.tick_count = sim.tick_count
        self.period_ns = int(round(1e9 / sim.control_rate))
        self.steps_per_tick = sim.physics_steps_per_tick
        self.dt = 1.0 / sim.physics_rate  # the physics step [s]
        self._rotor_counts = [u.vehicle.n_rotors for u in scenario.uavs]
        # live reel rates stamped for a later tick: (tick [-], arrival, UAV from 0, rate)
        self._winch_queue: list[tuple[int, int, int, float]] = []
        self._winch_arrivals = 0
        # the tension of the last integration (at the tick it started from)
        self.last_tension: np.ndarray | None = None
        self._tension = np.zeros((1, self.n))
        # the compiled functions, or their uncompiled run, as MULTILIFT_KERNEL says now
        self._advance = kernels.runnable(physics_tick.advance)
        self._measure = kernels.runnable(physics_tick.measure)
        self._wind = kernels.runnable(physics_tick.period_wind)
        self._tension_at = kernels.runnable(physics_tick.tension_at)
        kernels.runnable(physics_tick.start)(self.arrays, self.memory, np.ones(1, dtype=bool))
        self.happened = range(0, int(self.memory.next_event[0]))
        self._raise_if_stopped()

    # -------------------------------------------------------------------------- the state
    @property
    def state(self) -> np.ndarray:
        """The formation state at the current tick (docs/conventions.md; a copy)."""
        return self.memory.state[0].copy()

    @state.setter
    def state(self, value: np.ndarray) -> None:
        self.memory.state[0, :] = value

    @property
    def tick(self) -> int:
        return int(self.memory.tick[0])

    @property
    def t_ns(self) -> int:
        return self.tick * self.period_ns

    @property
    def t(self) -> float:
        return self.t_ns * 1e-9

    @property
    def finished(self) -> bool:
        return self.tick >= self.tick_count

    @property
    def residuals(self) -> tuple[np.ndarray, np.ndarray]:
        """(g [m^2], g_dot [m^2/s]) at the current state, (n,) each."""
        return self.memory.g[0].copy(), self.memory.g_dot[0].copy()

    @property
    def payload_gust(self) -> np.ndarray:
        """The air velocity at the payload in the current state [m/s], world (/payload/gust)."""
        return self.memory.gust[0].copy()

    @property
    def taut(self) -> np.ndarray:
        """Which cables are taut, (n,) bool (all but released ones with cable_model: rigid)."""
        return self.memory.taut[0].copy()

    @property
    def rotors(self) -> np.ndarray:
        """Every rotor's speed [rad/s] (n, rotors; NaN before its first command)."""
        return self.memory.rotors[0].copy()

    @property
    def wind(self) -> np.ndarray:
        """The air's velocity everywhere over the period from the current tick [m/s], world:
        the steady wind plus the tick's unsteady wind (`schedules.wind_series`)."""
        wind = np.empty(3)
        self._wind(self.arrays.formation[0], self.arrays.wind_series[0], self.tick, wind)
        return wind

    def snapshot(self) -> Snapshot:
        """The formation at the current tick: every UAV's numbers from one call of
        physics.measurement.odometry_states, viewed from a fresh array (none of the
        simulator's state), and what the controllers receive of them (with `sensors:`,
        physics.tick.measure; call it once a tick, or more: the same result)."""
        n, layout = self.n, self.model.layout
        state = self.state
        rows = np.empty((1, n, ODOMETRY_COLUMNS))
        odometry_states(state.reshape(1, -1), n, rows)
        odometry = rows[0]
        measured = np.empty((n, MEASURED_COLUMNS))
        self._measure(self.arrays, self.memory, 0, measured)
        uavs = tuple(UavSnapshot(
            position=row[MEASURED_POSITION:MEASURED_POSITION + 3],
            velocity=row[MEASURED_VELOCITY:MEASURED_VELOCITY + 3],
            euler=row[MEASURED_EULER:MEASURED_EULER + 3],
            rotation=row[ODOMETRY_ROTATION:ODOMETRY_ROTATION + 9].reshape(3, 3),
            body_rates=row[MEASURED_BODY_RATES:MEASURED_BODY_RATES + 3],
            body_velocity=row[ODOMETRY_BODY_VELOCITY:ODOMETRY_BODY_VELOCITY + 3],
            orientation=row[ODOMETRY_QUATERNION:ODOMETRY_QUATERNION + 4]) for row in odometry)
        attitude = payload_attitude(state, n) if self.model.layout.rigid_payload else None
        return Snapshot(self.t_ns, uavs, layout.payload_position(state).copy(),
                        layout.payload_velocity(state).copy(), odometry, measured, attitude,
                        self.memory.reel[0, :, REEL_LENGTH].copy(),
                        self.memory.estimator_memory[0, 0, :, :ESTIMATE_COLUMNS].copy()
                        if self.memory.estimator_memory.shape[1] else None,
                        layout.chain_positions(state).copy() if layout.chain_nodes else None,
                        self.memory.payload_estimator_memory[0, 0, :ESTIMATE_COLUMNS].copy()
                        if self.memory.payload_estimator_memory.shape[1] else None)

    # ------------------------------------------------------------------------- the cables
    def cable_state(self, rotor_speeds: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray,
                                                                    np.ndarray]:
        """(tension [N], g [m^2], g_dot [m^2/s]) at the current tick under `rotor_speeds`."""
        speeds, _ = self._command_arrays(rotor_speeds, None)
        tension = np.empty(self.n)
        self._tension_at(self.arrays, self.memory, 0, speeds, tension)
        return (tension, *self.residuals)

    def tick_cables(self, rotor_speeds: list[np.ndarray]) -> TickCables:
        """This tick's cable facts under `rotor_speeds`, before `advance`; the tension follows
        from `cables_of`."""
        g, g_dot = self.residuals
        return TickCables(self.tick, rotor_speeds, g, g_dot, self.taut)

    def cables_of(self, held: TickCables) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(tension [N], g [m^2], g_dot [m^2/s]) at the tick of `held`: the tension from the
        integration that left it when the simulator has moved on by one tick (no second solve
        of the DAE), else solved here (the run ended at that tick)."""
        if self.tick == held.tick + 1 and self.last_tension is not None:
            return self.last_tension, held.constraint, held.constraint_rate
        return self.cable_state(held.rotor_speeds)[0], held.constraint, held.constraint_rate

    # ------------------------------------------------------------------------ the tick
    def advance(self, rotor_speeds: list[np.ndarray], saturated: list[np.ndarray]) -> None:
        """Hold `rotor_speeds` over one control period and integrate to the next tick
        (`physics.tick.advance`: a silent controller's commands held, the events of the new
        tick applied, Algorithm 1's check; SimulationStopped when it stops the run)."""
        speeds, flags = self._command_arrays(rotor_speeds, saturated)
        while self._winch_queue and self._winch_queue[0][0] <= self.tick:
            _, _, uav, rate = self._winch_queue.pop(0)
            self.memory.reel[0, uav, REEL_COMMAND] = rate
        first = int(self.memory.next_event[0])
        self._advance(self.arrays, self.memory, 0, speeds, flags, self._tension[0])
        self.last_tension = self._tension[0].copy()
        self.happened = range(first, int(self.memory.next_event[0]))
        self._raise_if_stopped()

    def command_winch(self, uav: int, rate: float, at_ns: int | None = None) -> int:
        """UAV `uav`'s (from 0) winch commanded to reel at `rate` [m/s] (positive pays out) from
        the period of the first tick at or after `at_ns` [ns] of simulated time on (a live
        /uav{i}/winch_cmd_stamped), or of the current tick (None, or a time already past: a
        live /uav{i}/winch_cmd); physics.winch keeps it within the winch's limits and stops.
        Returns the tick it takes effect at; ValueError for a UAV without a winch or a rate
        that is not finite."""
        if uav + 1 not in self.scenario.winches:
            raise ValueError(f'uav{uav + 1} has no winch')
        if not math.isfinite(rate):
            raise ValueError(f'a reel rate must be finite, got {rate!r}')
        tick = self.tick if at_ns is None else max(self.tick, -(-at_ns // self.period_ns))
        if tick == self.tick:
            self.memory.reel[0, uav, REEL_COMMAND] = rate
            return tick
        self._winch_arrivals += 1
        self._winch_queue.append((tick, self._winch_arrivals, uav, rate))
        self._winch_queue.sort()
        return tick

    def idle_commands(self) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """(rotor speeds [rad/s], saturation flags) of 0 for every UAV: what a formation whose
        UAVs' motion is all prescribed holds (no controller; the speeds move nothing)."""
        return ([np.zeros(count) for count in self._rotor_counts],
                [np.zeros(count, dtype=bool) for count in self._rotor_counts])

    def happened_rows(self) -> np.ndarray:
        """The rows (physics.layout EVENT_*) of the events the current tick is the first to
        show."""
        return self.arrays.events[0, self.happened.start:self.happened.stop]

    def events_summary(self) -> list[dict]:
        """The events that have happened, as the run's summary names them."""
        return event_records(self.arrays.events[0, :int(self.memory.next_event[0])])

    def clearance_summary(self) -> dict:
        """The clearances so far (`statistics.clearance.clearance_figures`; {} without a
        `world:` section)."""
        return clearance_figures(self.scenario, self.memory.clearance[0], self.memory.contact[0])

    def _raise_if_stopped(self) -> None:
        """SimulationStopped naming why, where Algorithm 1's check or a contact stopped the
        run."""
        status = int(self.memory.status[0])
        if status == STATUS_CONTACT:
            raise SimulationStopped(contact_message(self.scenario, self.memory.contact[0]))
        if status in STOP_CHECKS:
            raise SimulationStopped(stop_message(
                STOP_CHECKS[status], int(self.memory.worst_cable[0]),
                float(self.memory.worst_value[0]), self.t, self.scenario.simulation,
                self.scenario.n_uavs))

    def _command_arrays(self, rotor_speeds: list[np.ndarray],
                        saturated: list[np.ndarray] | None) -> tuple[np.ndarray, np.ndarray]:
        """The commands as (n, rotors) arrays, a smaller UAV's padded with zeros (not
        saturated), or SimulationStopped naming the UAV whose command has the wrong size or is
        not finite."""
        rotors = self.arrays.allocation.shape[-1]
        if len(rotor_speeds) != self.n:
            raise SimulationStopped(f'{len(rotor_speeds)} rotor commands for {self.n} UAVs '
                                    f'(t = {self.t:.3f} s)')
        speeds = np.zeros((self.n, rotors))
        flags = np.zeros((self.n, rotors), dtype=bool)
        for i, own in enumerate(rotor_speeds):
            own = np.asarray(own, dtype=float)
            count = self._rotor_counts[i]
            if own.shape != (count,):
                raise SimulationStopped(
                    f'uav{i + 1}: rotor command has {own.size} speeds, the vehicle has '
                    f'{count} rotors (t = {self.t:.3f} s)')
            if not np.all(np.isfinite(own)):
                raise SimulationStopped(f'uav{i + 1}: rotor command is not finite '
                                        f'({own.tolist()}) at t = {self.t:.3f} s')
            speeds[i, :count] = own
            if saturated is not None:
                flags[i, :count] = saturated[i]
        return speeds, flags
