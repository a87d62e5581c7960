"""A headless run recorded to the same bag a ROS run gives: the same topics, the same messages,
stamped with simulated time. No ROS graph and no rclpy: the bytes are the ones the nodes
publish (multilift_sim.tick_messages for the simulator's, multilift_control.answer_messages
for the controllers'), CDR packed straight from the tick's numbers with the padding zeroed, so
two runs of a scenario write byte-identical bags.

The tick's work is done once: `/formation/state` and the markers of tick t need the cable
tension at t under the answers to t, which is what integrating from t computes
(`Integration.cable_tension`), and g, g_dot at t, which the previous integration (or the
simulator's start check) computed. So they are written when the next tick arrives (they are
the last records of tick t, so the order of the bag is unchanged); the last tick, and a tick
whose integration stopped the run, solve once more.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from multilift_control.answer_messages import AnswerMessages
from multilift_control.headless import HeadlessRun, run_headless
from multilift_control.runtime import ControllerAnswer
from multilift_sim.bag import BagWriter
from multilift_sim.bagyaml import OfferedQos, qos_yaml
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import FormationSimulator, Snapshot, TickCables
from multilift_sim.tick_messages import SimulatorMessages
from multilift_sim.topics import MARKER_DECIMATION, run_topics


class HeadlessBag:
    """Writes one run's messages to a BagWriter, tick by tick (see the module docstring)."""

    def __init__(self, scenario: Scenario, writer: BagWriter) -> None:
        qos = qos_yaml([OfferedQos(history='keep_last', depth=100)])
        for topic, kind in run_topics(scenario.n_uavs):
            writer.add_topic(topic, kind, qos)
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
                                         last=sim.finished)
        if answers:
            self._applied = [a.output.rotor_speeds for a in answers]
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
        if held.tick % MARKER_DECIMATION == 0:
            messages.append(self._simulator.markers(snap, tension, held.taut))
        self._write(messages, snap.t_ns)


def record_headless(scenario: Scenario, bag_dir: Path,
                    on_tick: Callable[[FormationSimulator], None] | None = None,
                    raise_on_stop: bool = True) -> HeadlessRun:
    """Fly `scenario` without ROS and write every topic of a ROS run to `bag_dir`: the
    simulator's state and every controller's answer as the nodes publish them.
    `raise_on_stop` as for `run_headless`."""
    writer = BagWriter(bag_dir)
    bag = HeadlessBag(scenario, writer)
    simulator: list[FormationSimulator] = []

    def tick(sim: FormationSimulator, snap: Snapshot, answers: list[ControllerAnswer]) -> None:
        if not simulator:
            simulator.append(sim)
        bag.tick(sim, snap, answers)
        if on_tick is not None:
            on_tick(sim)

    try:
        return run_headless(scenario, tick, raise_on_stop)
    finally:
        try:
            if simulator:
                bag.finish_pending(simulator[0])
        finally:
            writer.close()
