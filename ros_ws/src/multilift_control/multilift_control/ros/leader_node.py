"""Leader node: UAV 1 tracks the mission with the controller of `control.mode` (seed Ch. 3).

Subscribes `/formation/snapshot`; for every state it answers with `/uav1/rotor_cmd` stamped with the
state's time, and publishes what it aimed at on `/uav1/reference` (mission reference) and
`/uav1/attitude_setpoint` (outer-loop output). The control law and the statistics are the
controller runtime's (multilift_control.runtime), shared with the headless loop.
Parameters: scenario, record, summary_dir, live (`multilift run --live`: the mission's start
held until a goal on `/formation/goal` or a path on `/formation/path` arrives, `ros.live_input`).
"""
from __future__ import annotations

from typing import NoReturn

from multilift_msgs.msg import (AttitudeSetpoint, FormationSnapshot, RotorCommand,
                                TrackingReference)
from rclpy.node import Node

from multilift_control.answer_messages import AnswerMessages
from multilift_control.live_goals import LiveMission
from multilift_control.ros.common import SNAPSHOT_TOPIC, SnapshotReader, serve
from multilift_control.ros.live_input import LiveInput
from multilift_control.runtime import ControllerRuntime, prepare_node_laws
from multilift_sim import scenario as scenario_io
from multilift_sim.ros.common import (FIRST_ACK_TIMEOUT, PUBLISHER_QOS, SUBSCRIBER_QOS, Fatal,
                                      RawPublishers, controller_peers_missing, run_nodes)
from multilift_sim.topics import ATTITUDE_SETPOINT, REFERENCE, ROTOR_CMD, uav_topic


class LeaderNode(Node):
    def __init__(self, **options) -> None:
        """`options`: rclpy Node's (parameter_overrides, ...: `controllers_node` composes)."""
        super().__init__('leader', **options)
        name = self.declare_parameter('scenario', '').value
        self.record = bool(self.declare_parameter('record', False).value)
        self.summary_dir = self.declare_parameter('summary_dir', '').value
        if not name:
            raise Fatal('parameter "scenario" is required (a name in scenarios/ or a path)')
        scenario = scenario_io.load(name)
        prepare_node_laws(scenario, 0)  # before our topics appear
        self.runtime = ControllerRuntime(scenario, 0)
        self.packer = AnswerMessages(scenario)  # the answer as CDR bytes
        self.cmd_pub = self.create_publisher(RotorCommand, uav_topic(1, ROTOR_CMD),
                                             PUBLISHER_QOS)
        self.ref_pub = self.create_publisher(TrackingReference, uav_topic(1, REFERENCE),
                                             PUBLISHER_QOS)
        self.setpoint_pub = self.create_publisher(AttitudeSetpoint,
                                                  uav_topic(1, ATTITUDE_SETPOINT), PUBLISHER_QOS)
        self.outputs = RawPublishers(self.cmd_pub, self.ref_pub, self.setpoint_pub,
                                     confirm_first=FIRST_ACK_TIMEOUT if self.record else 0.0)
        self.read_snapshot = SnapshotReader(scenario)
        self.live = (LiveInput(self, LiveMission(self.runtime.leader, scenario))
                     if self.declare_parameter('live', False).value else None)
        self.create_subscription(FormationSnapshot, SNAPSHOT_TOPIC, self.on_snapshot,
                                 SUBSCRIBER_QOS, raw=True)

    def missing_peers(self) -> str | None:
        return controller_peers_missing(self, self.cmd_pub, self.record)

    def on_snapshot(self, data: bytes) -> None:
        t_ns, states, _ = self.read_snapshot(data)
        if self.live is not None:
            self.live.apply(t_ns * 1e-9)
        self.outputs.send(self.packer.of(self.runtime.answer(t_ns, states)))


def main(args: list[str] | None = None) -> NoReturn:
    run_nodes(lambda: [LeaderNode()], serve, args)


if __name__ == '__main__':
    main()
