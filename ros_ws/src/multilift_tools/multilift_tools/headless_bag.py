"""A headless run recorded to the same bag a ROS run gives: the same topics, the same messages
(built by multilift_sim.ros.messages), stamped with simulated time. No ROS graph is involved; rclpy
is used only to serialise the messages to CDR.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from rclpy.serialization import serialize_message

from multilift_control.headless import HeadlessRun, run_headless
from multilift_control.runtime import ControllerAnswer
from multilift_sim.bag import BagWriter
from multilift_sim.bagyaml import OfferedQos, qos_yaml
from multilift_sim.ros import messages
from multilift_sim.ros.common import MARKER_DECIMATION
from multilift_sim.topics import run_topics, uav_topic
from multilift_sim.ros.markers import formation_markers
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import FormationSimulator, Snapshot


def record_headless(scenario: Scenario, bag_dir: Path,
                    on_tick: Callable[[FormationSimulator], None] | None = None
                    ) -> HeadlessRun:
    """Fly `scenario` without ROS and write every topic of a ROS run to `bag_dir`: the
    simulator's state and every controller's answer as the nodes publish them."""
    writer = BagWriter(bag_dir)
    qos = qos_yaml([OfferedQos(history='keep_last', depth=100)])
    for topic, kind in run_topics(scenario.n_uavs):
        writer.add_topic(topic, kind, qos)

    rotor_counts = [u.vehicle.n_rotors for u in scenario.uavs]
    applied: list = [None]  # the rotor speeds held up to this tick (None at t = 0)

    def write(topic: str, msg, t_ns: int) -> None:
        writer.write(topic, serialize_message(msg), t_ns)

    def tick(sim: FormationSimulator, snap: Snapshot, answers: list[ControllerAnswer]) -> None:
        t_ns = snap.t_ns
        write('/clock', messages.clock(t_ns), t_ns)
        write('/formation/snapshot',
              messages.formation_snapshot(snap, applied[0], rotor_counts), t_ns)
        applied[0] = [a.output.rotor_speeds for a in answers]
        for i, uav in enumerate(snap.uavs):
            write(uav_topic(i + 1, 'odom'), messages.uav_odometry(t_ns, i + 1, uav), t_ns)
        write('/payload/odom', messages.payload_odometry(t_ns, snap.payload_position,
                                                         snap.payload_velocity), t_ns)
        gust = sim.model.gust_velocity_at_payload(sim.t, sim.state)
        write('/payload/gust', messages.gust(t_ns, gust), t_ns)
        for answer in answers:
            i, out = answer.index + 1, answer.output
            write(uav_topic(i, 'rotor_cmd'), messages.rotor_command(t_ns, i, out), t_ns)
            write(uav_topic(i, 'attitude_setpoint'), messages.attitude_setpoint(t_ns, i, out),
                  t_ns)
            if answer.reference is not None:
                write(uav_topic(i, 'reference'),
                      messages.tracking_reference(t_ns, answer.reference), t_ns)
            if answer.formation_error is not None:
                write(uav_topic(i, 'formation_error'),
                      messages.formation_error(t_ns, answer.formation_error,
                                               answer.formation_error_rate), t_ns)
        tension, g, g_dot = sim.cable_state([a.output.rotor_speeds for a in answers])
        write('/formation/state', messages.formation_state(t_ns, tension, g, g_dot), t_ns)
        if sim.tick % MARKER_DECIMATION == 0:
            write('/visualization/markers',
                  formation_markers(snap, tension, scenario, t_ns), t_ns)
        if on_tick is not None:
            on_tick(sim)

    try:
        return run_headless(scenario, tick)
    finally:
        writer.close()
