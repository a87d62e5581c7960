"""A headless run recorded to the same bag a ROS run gives: the same topics, the same messages,
stamped with simulated time. No ROS graph and no rclpy: the CDR is packed straight from the
tick's numbers (multilift_sim.cdr, from the values multilift_sim.msgvalues and .scene compute
for the nodes' messages too), padding zeroed, so two runs of a scenario write byte-identical
bags.

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

from multilift_control.headless import HeadlessRun, run_headless
from multilift_control.runtime import ControllerAnswer
from multilift_sim import cdr
from multilift_sim.bag import BagWriter
from multilift_sim.bagyaml import OfferedQos, qos_yaml
from multilift_sim.msgvalues import (IDENTITY, PAYLOAD_FRAME, formation_snapshot, odometry,
                                     quaternion, uav_frame, vec3)
from multilift_sim.scenario import Scenario
from multilift_sim.scene import FormationScene
from multilift_sim.simulation import FormationSimulator, Snapshot, TickCables
from multilift_sim.topics import MARKER_DECIMATION, run_topics, uav_topic

TF_TOPIC = '/tf'


class HeadlessBag:
    """Packs one run's messages into a BagWriter, tick by tick (see the module docstring)."""

    def __init__(self, scenario: Scenario, writer: BagWriter) -> None:
        self.scenario = scenario
        n = scenario.n_uavs
        self._writer = writer
        self._topics = dict(run_topics(n))
        qos = qos_yaml([OfferedQos(history='keep_last', depth=100)])
        for topic, kind in self._topics.items():
            writer.add_topic(topic, kind, qos)
        self._write = writer.write
        self._clock = cdr.Clock()
        self._gust = cdr.Vector3Stamped()
        self._payload_odom = cdr.Odometry(PAYLOAD_FRAME)
        self._state = cdr.formation_state(n)
        self._snapshot = cdr.FormationSnapshot([u.vehicle.n_rotors for u in scenario.uavs])
        self._applied = None  # the rotor speeds held up to this tick (None at t = 0)
        self._scene = FormationScene(scenario)
        self._markers = cdr.MarkerArray(self._scene.specs)
        self._reference = cdr.TrackingReference()
        self._uavs = [(uav_topic(i, 'odom'), cdr.Odometry(uav_frame(i)),
                       uav_topic(i, 'rotor_cmd'),
                       cdr.RotorCommand(scenario.uavs[i - 1].vehicle.n_rotors, uav_frame(i)),
                       uav_topic(i, 'attitude_setpoint'), cdr.AttitudeSetpoint(uav_frame(i)),
                       uav_topic(i, 'reference'), uav_topic(i, 'formation_error'))
                      for i in range(1, n + 1)]
        self._errors: dict[int, cdr.FloatSequences] = {}
        self._tf = (cdr.TFMessage([uav_frame(i) for i in range(1, n + 1)] + [PAYLOAD_FRAME])
                    if TF_TOPIC in self._topics else None)
        self._pending: tuple[Snapshot, TickCables] | None = None  # of the tick before

    def tick(self, sim: FormationSimulator, snap: Snapshot,
             answers: list[ControllerAnswer]) -> None:
        """Write the state at tick t and every controller's answer to it."""
        self.finish_pending(sim)
        t_ns, write = snap.t_ns, self._write
        write('/clock', self._clock.pack(t_ns), t_ns)
        write('/formation/snapshot', self._snapshot.pack(
            t_ns, *formation_snapshot(snap, self._applied)), t_ns)
        self._applied = [a.output.rotor_speeds for a in answers]
        for uav, (odom_topic, odom, *_rest) in zip(snap.uavs, self._uavs):
            write(odom_topic, odom.pack(t_ns, *odometry(uav.position, uav.velocity, uav.euler,
                                                        uav.rotation, uav.body_rates)), t_ns)
        write('/payload/odom', self._payload_odom.pack(
            t_ns, *odometry(snap.payload_position, snap.payload_velocity, None, None, None)),
            t_ns)
        if self._tf is not None:
            write(TF_TOPIC, self._tf.pack(
                t_ns, [vec3(u.position) for u in snap.uavs] + [vec3(snap.payload_position)],
                [quaternion(u.euler) for u in snap.uavs] + [IDENTITY]),
                t_ns)
        gust = sim.model.gust_velocity_at_payload(sim.t, sim.state)
        write('/payload/gust', self._gust.pack(t_ns, *gust), t_ns)
        for answer in answers:
            (_, _, cmd_topic, cmd, sp_topic, setpoint, ref_topic,
             error_topic) = self._uavs[answer.index]
            out = answer.output
            write(cmd_topic, cmd.pack(t_ns, out.rotor_speeds.tolist(),
                                      [bool(s) for s in out.saturated]), t_ns)
            roll, pitch, yaw = out.attitude_setpoint
            write(sp_topic, setpoint.pack(t_ns, roll, pitch, yaw, out.thrust), t_ns)
            ref = answer.reference
            if ref is not None:
                write(ref_topic, self._reference.pack(t_ns, *ref.position, *ref.velocity,
                                                      *ref.acceleration), t_ns)
            if answer.formation_error is not None:
                errors = answer.formation_error
                packer = self._errors.get(len(errors))
                if packer is None:
                    packer = self._errors[len(errors)] = cdr.virtual_constraint_error(
                        len(errors))
                write(error_topic, packer.pack(t_ns, answer.formation_error.tolist(),
                                               answer.formation_error_rate.tolist()), t_ns)
        self._pending = (snap, sim.tick_cables([a.output.rotor_speeds for a in answers]))

    def finish_pending(self, sim: FormationSimulator) -> None:
        """Write `/formation/state` (and the markers) of the tick before: from the integration
        that left it when the simulator has moved on, else solved here (the last tick)."""
        if self._pending is None:
            return
        snap, held = self._pending
        self._pending = None
        tension, g, g_dot = sim.cables_of(held)
        t_ns, taut = snap.t_ns, held.taut
        self._write('/formation/state', self._state.pack(t_ns, tension.tolist(), g.tolist(),
                                                         g_dot.tolist(), taut.tolist()), t_ns)
        if held.tick % MARKER_DECIMATION == 0:
            self._scene.update([u.position for u in snap.uavs], [u.euler for u in snap.uavs],
                               snap.payload_position, tension, taut)
            self._write('/visualization/markers', self._markers.pack(t_ns), t_ns)


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
