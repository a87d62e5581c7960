"""A headless run recorded to the same bag a ROS run gives: the same topics, the same messages,
stamped with simulated time. No ROS graph and no rclpy: the bytes are the ones the nodes
publish (multilift_sim.wire.tick_messages for the simulator's, multilift_control.answer_messages
for the controllers'), CDR packed straight from the tick's numbers with the padding zeroed, so
two runs of a scenario write byte-identical bags.

`record_headless` flies the run through the engine (`multilift_control.engine`), CHUNK_TICKS
ticks per compiled call into a `TickRecord`, and packs each tick's messages from the record's
rows (`EngineBag`): the state at t and every answer to it, then `/formation/state` (the
tension of the integration that starts at t, g and g_dot at t) and every MARKER_DECIMATION-th
tick the markers; each topic's messages of the CHUNK_TICKS ticks at once (numpy rows,
`cdr_layout.Layout.pack_rows`), written as one block (`BagWriter.write_block`). The state at
t_max has no answers; its `/formation/state` is solved under the commands held since the tick
before, as the simulator node does. `HeadlessBag` writes the same
bag tick by tick from `run_headless` (the objects the nodes use).
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Callable

import numpy as np

from multilift_control.answer_messages import AnswerMessages
from multilift_control.engine import Engine
from multilift_control.engine.arrays import TickRecord
from multilift_control.headless import FlownRun, HeadlessRun, progress_ticker, run_headless
from multilift_control.runtime import ControllerAnswer
from multilift_sim.bag import BagWriter, Column
from multilift_sim.bag.metadata_yaml import OfferedQos, qos_yaml
from multilift_sim.formation_params import StateLayout
from multilift_sim import kernels
from multilift_sim.physics import tick as physics_tick
from multilift_sim.physics.tick import period_winds
from multilift_sim.physics.layout import EVENT_TICK, REEL_LENGTH
from multilift_sim.tick_arrays import PhysicsArrays, PhysicsMemory
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import (FormationSimulator, SimulationStopped, Snapshot, TickCables,
                                      payload_attitude)
from multilift_sim.estimators.published import ESTIMATE_COLUMNS
from multilift_sim.wire.tick_messages import (SimulatorMessages, measured_odometry, payload_motion,
                                              state_rows)
from multilift_sim.topics import (FORMATION_SNAPSHOT, MARKER_DECIMATION, MARKERS,
                                  scenario_topics)

# ticks per compiled call (and between two progress reports): 2.5 s of a 100 Hz mission
CHUNK_TICKS = 250

# progress(t, t_max) [s], as multilift_control.headless.fly takes it
Progress = Callable[[float, float], None]


def _add_topics(scenario: Scenario, writer: BagWriter, controllers: bool = True) -> None:
    qos = qos_yaml([OfferedQos(history='keep_last', depth=100)])
    for topic, kind in scenario_topics(scenario, controllers):
        writer.add_topic(topic, kind, qos)


class EngineBag:
    """Writes one engine-flown run's messages to a BagWriter from its TickRecords (see the
    module docstring): the same messages, in the same order and the same groups (`write_many`
    calls or a block's groups: a chunk of the MCAP is finished after a group) as
    `HeadlessBag`, so the same bytes (tests/unit/test_headless_bag.py). With
    `controllers=False` (answers that are a policy's rotor speeds) only the rotor commands of
    the answers are written, and the bag has no controller topic."""

    def __init__(self, scenario: Scenario, engine: Engine, writer: BagWriter,
                 controllers: bool = True) -> None:
        _add_topics(scenario, writer, controllers)
        self._controllers = controllers
        self._commands = scenario.controlled  # none when every UAV's motion is prescribed
        self._scenario, self._engine = scenario, engine
        self._write, self._write_block = writer.write_many, writer.write_block
        self._simulator = SimulatorMessages(scenario)
        self._answers = AnswerMessages(scenario)
        self._n = scenario.n_uavs
        arrays = engine.arrays
        self._period_ns = int(arrays.period_ns[0])
        self._own_rows = arrays.own_rows[0].tolist()
        self._reference = bool(arrays.leader_tracks[0])  # its part's TRACKS_MISSION
        # each UAV's rotors of the record's padded (n, rotors) rows: all, or (mixed rotor
        # counts) the real ones (`engine.arrays.ControlArrays`)
        counts = arrays.rotor_counts[0].tolist()
        rotors = arrays.allocation.shape[-1]
        self._counts = None if min(counts) == rotors else counts
        self._real = np.concatenate([i * rotors + np.arange(c) for i, c in enumerate(counts)])
        self._held: np.ndarray | None = None  # the rotor speeds held up to the next tick
        self._last_speeds: list | None = None  # each UAV's answer to the last tick written
        self._sensors = scenario.measures  # /uav{i}/measured_odom
        self._rigid = scenario.payload.type == 'rigid_body'  # its pose in /payload/odom, /tf
        # a heavy cable's inner nodes per cable (cable_model: chain; 0: none), in its markers
        self._chain_nodes = scenario.cable['links'] - 1 if scenario.cable_model == 'chain' else 0
        # /formation/wind by tick (physics.tick.period_winds), where the air moves everywhere
        self._wind = None
        if scenario.has_wind:
            self._wind = np.empty((int(arrays.tick_count[0]) + 1, 3))
            kernels.runnable(period_winds)(arrays.formation[0], arrays.wind_series[0],
                                           self._wind)

    def ticks(self, first: int, record: TickRecord, count: int) -> None:
        """Write ticks first .. first + count - 1 of formation 0 from `record`'s rows: each
        topic's messages of the `count` ticks packed at once (`state_rows_of`, `answer_rows`,
        ...), written a block of ticks at a time (`BagWriter.write_block`) between the ticks
        that differ, which are written message by message from the same rows: the run's first
        tick (its snapshot holds no rotor speeds yet) and the ticks events fall on."""
        if count <= 0:
            return
        n = self._n
        t_ns = (first + np.arange(count, dtype=np.int64)) * self._period_ns
        states = record.states[:count, 0]
        received = record.measured[:count, 0]  # what the controllers received
        payload_estimates = record.payload_estimate[:count, 0] \
            if record.payload_estimate.shape[2] else None  # /payload/estimate
        snapshots, odometry = state_rows(states, n, received, payload_estimates)
        speeds, saturated = record.speeds[:count, 0], record.saturated[:count, 0]
        flat = speeds.reshape(count, -1)
        if self._counts is not None:
            flat = flat[:, self._real]
        specials = set()  # ticks written message by message (`_tick`)
        first_snapshot = None  # the run's first, without rotor speeds
        if self._held is None:  # from t = 0: no rotor speeds held yet
            first_snapshot = self._simulator.snapshot_of(int(t_ns[0]), snapshots[0].tolist(),
                                                         0)[1]
            specials.add(0)
        held = np.zeros_like(flat[:1]) if self._held is None else self._held[None]
        snapshots = np.concatenate((snapshots, np.concatenate((held, flat[:-1]))), axis=1)
        self._held = flat[-1].copy()
        events = self._engine.arrays.events[0][:, EVENT_TICK] - first
        specials.update(int(k) for k in events if 0 <= k < count)
        layout = StateLayout(n, self._rigid, self._chain_nodes)
        payload_position = layout.payload_position(states)
        payload_velocity = layout.payload_velocity(states)
        pose, orientations = None, [None] * count  # a rigid payload's, for the markers
        if self._rigid:  # its pose and its twist in its frame, as the per-object path packs
            motions = [payload_motion(payload_attitude(state, n), velocity)
                       for state, velocity in zip(states, payload_velocity)]
            payload_velocity = np.array([motion[0] for motion in motions])
            orientations = [motion[1][0] for motion in motions]
            pose = (np.array(orientations), np.array([motion[1][1] for motion in motions]))
        counts = self._counts or [speeds.shape[2]] * n
        uav_speeds = [speeds[:, i, :c] for i, c in enumerate(counts)]
        uav_saturated = [saturated[:, i, :c] for i, c in enumerate(counts)]
        state = self._simulator.state_rows_of(
            t_ns, snapshots, flat.shape[1], odometry, payload_position, payload_velocity,
            record.gust[:count, 0],
            measured_odometry(received) if self._sensors else None,
            None if self._wind is None else self._wind[first:first + count], pose,
            record.cable_length[:count, 0],
            record.estimate[:count, 0] if record.estimate.shape[3] else None,
            payload_estimates)
        answers = []
        if self._commands:
            rows = self._own_rows
            answers = self._answers.answer_rows(
                t_ns, uav_speeds, uav_saturated,
                *((record.setpoints[:count, 0], record.thrust[:count, 0],
                   record.reference[:count, 0] if self._reference else None,
                   [record.errors[:count, 0, i, :rows[i]] for i in range(n)],
                   [record.rates[:count, 0, i, :rows[i]] for i in range(n)])
                  if self._controllers else ()))
        tension, g = record.tension[:count, 0], record.g[:count, 0]
        g_dot, taut = record.g_dot[:count, 0], record.taut[:count, 0]
        formation = [self._simulator.formation_rows_of(t_ns, tension, g, g_dot, taut)]
        formation += self._simulator.margin_rows(uav_speeds if self._commands else [])
        marker_ticks = np.flatnonzero((first + np.arange(count)) % MARKER_DECIMATION == 0)
        euler = layout.uav_euler(states[marker_ticks])
        chains = layout.chain_positions(states[marker_ticks]) if self._chain_nodes \
            else [None] * len(marker_ticks)
        markers = [self._simulator.markers_of(
            int(t_ns[k]), odometry[k, :, :3].tolist(), euler[m].tolist(),
            payload_position[k].tolist(), tension[k].tolist(), taut[k].tolist(),
            orientations[k], chains[m])[1] for m, k in enumerate(marker_ticks)]
        start = 0
        for stop in sorted(specials) + [count]:
            if stop > start:
                self._block(t_ns, start, stop, state + answers, formation, markers,
                            marker_ticks)
            if stop < count:
                tick_state = [(topic, first_snapshot if first_snapshot is not None and
                               stop == 0 and topic == FORMATION_SNAPSHOT
                               else rows[stop].tobytes()) for topic, rows in state]
                marker = [(MARKERS, markers[m]) for m in np.flatnonzero(marker_ticks == stop)]
                self._write(tick_state + self._events_at(first + stop, int(t_ns[stop]))
                            + [(topic, rows[stop].tobytes()) for topic, rows in answers],
                            int(t_ns[stop]))
                self._write([(topic, rows[stop].tobytes()) for topic, rows in formation]
                            + marker, int(t_ns[stop]))
            start = stop + 1
        self._last_speeds = [s[-1].tolist() for s in uav_speeds] if self._commands else None

    def _block(self, t_ns: np.ndarray, start: int, stop: int, first: list, second: list,
               markers: list[bytes], marker_ticks: np.ndarray) -> None:
        """Ticks start .. stop - 1 of `t_ns` in one `write_block`: each tick's `first` group
        (the state and the answers), then its `second` (`/formation/state`, the margins and,
        every MARKER_DECIMATION-th tick, the markers)."""
        second = [Column(topic, rows[start:stop]) for topic, rows in second]
        shown = np.flatnonzero((marker_ticks >= start) & (marker_ticks < stop))
        if len(shown):
            second.append(Column(MARKERS, np.frombuffer(b''.join(markers[m] for m in shown),
                                                        np.uint8).reshape(len(shown), -1),
                                 marker_ticks[shown] - start))
        self._write_block(t_ns[start:stop], [
            [Column(topic, rows[start:stop]) for topic, rows in first], second])

    def last(self) -> None:
        """Write the state at t_max (the engine's current state, which nothing answers) and
        its `/formation/state` under the commands held since the tick before (solved here)."""
        engine, n = self._engine, self._n
        memory, tick = engine.memory, int(engine.memory.tick[0])
        t_ns = tick * self._period_ns
        state = memory.state[0]
        _, odometry = state_rows(state[None], n)
        odometry = odometry[0].tolist()
        layout = StateLayout(n, self._rigid, self._chain_nodes)
        payload_position = layout.payload_position(state).tolist()
        measured = measured_odometry(engine.measured()[:1])[0].tolist() if self._sensors \
            else None
        estimates = memory.estimator_memory[0, 0, :, :ESTIMATE_COLUMNS].tolist() \
            if memory.estimator_memory.shape[1] else None  # after measured(): this tick's
        payload_estimate = memory.payload_estimator_memory[0, 0, :ESTIMATE_COLUMNS].tolist() \
            if memory.payload_estimator_memory.shape[1] else None
        velocity, pose = payload_motion(payload_attitude(state, n) if self._rigid else None,
                                        layout.payload_velocity(state))
        self._write(self._simulator.state_of(t_ns, None, None, odometry, payload_position,
                                             velocity, memory.gust[0].tolist(), measured,
                                             None if self._wind is None
                                             else self._wind[tick].tolist(), pose,
                                             memory.reel[0, :, REEL_LENGTH].tolist(),
                                             estimates, payload_estimate)
                    + self._events_at(tick, t_ns), t_ns)
        # the tension under the commands held since the tick before, as the simulator node's
        # last tick solves it (physics.tick.tension_at, on the physics' arrays of the engine's)
        tension = np.empty(n)
        kernels.runnable(physics_tick.tension_at)(
            PhysicsArrays(*engine.arrays[:len(PhysicsArrays._fields)]),
            PhysicsMemory(*memory[:len(PhysicsMemory._fields)]), 0, memory.held[0], tension)
        self._formation(tick, t_ns, tension.tolist(), memory.g[0].tolist(),
                        memory.g_dot[0].tolist(), memory.taut[0].tolist(), odometry,
                        layout.uav_euler(state).tolist(), payload_position,
                        None if pose is None else pose[0],
                        layout.chain_positions(state) if self._chain_nodes else None,
                        self._last_speeds)

    def _events_at(self, tick: int, t_ns: int) -> list:
        """/formation/events of the events that fall on `tick` (the state there shows them)."""
        rows = self._engine.arrays.events[0]
        return self._simulator.events(t_ns, rows[rows[:, EVENT_TICK] == tick]) if len(rows) \
            else []

    def _formation(self, tick: int, t_ns: int, tension: list, g: list, g_dot: list,
                   taut: list, odometry: list, euler: list, payload_position: list,
                   payload_orientation=None, chain_points=None, speeds=None) -> None:
        """`/formation/state` of a tick, the thrust margins of its commands `speeds` (each
        UAV's [rad/s]; a reorganising formation's) and, every MARKER_DECIMATION-th, its
        markers."""
        messages = [self._simulator.formation_of(t_ns, tension, g, g_dot, taut)]
        messages += self._simulator.margins(speeds)
        if tick % MARKER_DECIMATION == 0:
            messages.append(self._simulator.markers_of(
                t_ns, [u[:3] for u in odometry], euler, payload_position, tension, taut,
                payload_orientation, chain_points))
        self._write(messages, t_ns)


class HeadlessBag:
    """Writes one run's messages to a BagWriter, tick by tick, as a `run_headless` observer.

    The tick's work is done once: `/formation/state` and the markers of tick t need the cable
    tension at t under the answers to t, which is what integrating from t computes
    (`Integration.cable_tension`), and g, g_dot at t, which the previous integration (or the
    simulator's start check) computed. So they are written when the next tick arrives (they
    are the last records of tick t, so the order of the bag is unchanged); the last tick, and a
    tick whose integration stopped the run, solve once more."""

    def __init__(self, scenario: Scenario, writer: BagWriter) -> None:
        _add_topics(scenario, writer)
        self._write = writer.write_many  # a tick's messages, all stamped with its time
        self._simulator = SimulatorMessages(scenario)
        self._answers = AnswerMessages(scenario)
        self._applied = None  # the rotor speeds held up to this tick (None at t = 0)
        self._pending: tuple[Snapshot, TickCables] | None = None  # of the tick before

    def tick(self, sim: FormationSimulator, snap: Snapshot,
             answers: list[ControllerAnswer]) -> None:
        """Write the state at tick t and every controller's answer to it (none at the last
        tick, whose cables are those of the commands held since the tick before)."""
        self.finish_pending(sim)
        messages = self._simulator.state(snap, sim.payload_gust, self._applied,
                                         last=sim.finished, wind=sim.wind)
        messages += self._simulator.events(snap.t_ns, sim.happened_rows())
        if answers:
            self._applied = [a.output.rotor_speeds for a in answers]
        elif not sim.scenario.controlled:  # every UAV prescribed: the idle commands held
            self._applied = sim.idle_commands()[0]
        for answer in answers:
            messages += self._answers.of(answer)
        self._write(messages, snap.t_ns)
        self._pending = (snap, sim.tick_cables(self._applied))

    def finish_pending(self, sim: FormationSimulator) -> None:
        """Write `/formation/state` (and the markers) of the tick before: from the integration
        that left it when the simulator has moved on, else solved here (the last tick)."""
        if self._pending is None:
            return
        snap, held = self._pending
        self._pending = None
        tension, g, g_dot = sim.cables_of(held)
        messages = [self._simulator.formation(snap.t_ns, tension, g, g_dot, held.taut)]
        messages += self._simulator.margins(held.rotor_speeds)
        if held.tick % MARKER_DECIMATION == 0:
            messages.append(self._simulator.markers(snap, tension, held.taut))
        self._write(messages, snap.t_ns)


def record_headless(scenario: Scenario, bag_dir: Path, progress: Progress | None = None,
                    raise_on_stop: bool = True) -> FlownRun:
    """Fly `scenario` without ROS and write every topic of a ROS run to `bag_dir`: the
    simulator's state and every controller's answer as the nodes publish them;
    `progress(t, t_max)` [s] every CHUNK_TICKS ticks. A simulation that stops itself raises
    SimulationStopped once its ticks are written, or with raise_on_stop=False ends the run with
    `error` set (as `multilift_control.headless.fly`)."""
    start = time.monotonic()
    engine = Engine(scenario)
    run = FlownRun(scenario, engine)
    writer = BagWriter(bag_dir)
    try:
        if engine.stopped[0]:  # at the start: as FormationSimulator's, whatever raise_on_stop
            raise SimulationStopped(run.error)
        bag = EngineBag(scenario, engine, writer)
        record = engine.new_record(CHUNK_TICKS)
        t_max = float(engine.t_max[0])
        while engine.running[0]:
            first = int(engine.memory.tick[0])
            flown = int(engine.step(CHUNK_TICKS, record)[0])
            bag.ticks(first, record, flown)
            if progress is not None:
                progress(float(engine.t[0]), t_max)
        if engine.finished[0]:
            bag.last()
    finally:
        try:
            writer.close()
        finally:
            run.wall_time = time.monotonic() - start
    if raise_on_stop and engine.stopped[0]:
        raise SimulationStopped(run.error)
    return run


def _record_per_object(scenario: Scenario, bag_dir: Path, progress: Progress | None = None,
                       raise_on_stop: bool = True) -> HeadlessRun:
    """`record_headless` tick by tick through the objects the nodes use (`run_headless`
    observed by `HeadlessBag`): the reference the engine's bag is tested against."""
    writer = BagWriter(bag_dir)
    bag = HeadlessBag(scenario, writer)
    simulator: list[FormationSimulator] = []
    report = None if progress is None else progress_ticker(progress, CHUNK_TICKS)

    def tick(sim: FormationSimulator, snap: Snapshot, answers: list[ControllerAnswer]) -> None:
        if not simulator:
            simulator.append(sim)
        bag.tick(sim, snap, answers)
        if report is not None:
            report(sim)

    try:
        return run_headless(scenario, tick, raise_on_stop)
    finally:
        try:
            if simulator:
                bag.finish_pending(simulator[0])
        finally:
            writer.close()
