"""Follower node: UAV i (2..n) keeps the formation through virtual constraints (seed §3.2).

For the state at t it needs `/formation/snapshot` stamped t (every UAV's state, and the rotor
speeds the simulator applied up to t: the other followers' previous answers) and the leader's
`/uav1/rotor_cmd` answering t: two messages a tick whatever n, so a tick of the graph costs
O(n) deliveries. It publishes `/uav{i}/rotor_cmd`, `/uav{i}/attitude_setpoint` and
`/uav{i}/formation_error` (its rows of g_vc and their rates). The law, the thrust
bookkeeping and the statistics are the controller runtime's (multilift_control.runtime),
shared with the headless loop. Parameters: scenario, uav_index, record, summary_dir.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import NoReturn

import numpy as np
from multilift_msgs.msg import (AttitudeSetpoint, FormationSnapshot, RotorCommand,
                                VirtualConstraintError)
from rclpy.node import Node

from multilift_control.answer_messages import AnswerMessages
from multilift_control.cascade import UavState
from multilift_control.ros.common import SNAPSHOT_TOPIC, SnapshotReader, serve
from multilift_control.runtime import ControllerRuntime, prepare_node_laws
from multilift_sim import scenario as scenario_io
from multilift_sim.ros.common import (FIRST_ACK_TIMEOUT, PUBLISHER_QOS, SUBSCRIBER_QOS, Fatal,
                                      RawPublishers, controller_peers_missing, ns_from_stamp,
                                      run_nodes)
from multilift_sim.topics import ATTITUDE_SETPOINT, FORMATION_ERROR, ROTOR_CMD, uav_topic


class FollowerNode(Node):
    def __init__(self, node_name: str = 'follower', **options) -> None:
        """A run names each one followerN (`--ros-args -r __node:=follower2`, or `node_name`);
        `options`: rclpy Node's (parameter_overrides, ...: `controllers_node` composes)."""
        super().__init__(node_name, **options)
        name = self.declare_parameter('scenario', '').value
        self.index = int(self.declare_parameter('uav_index', 2).value)
        self.record = bool(self.declare_parameter('record', False).value)
        self.summary_dir = self.declare_parameter('summary_dir', '').value
        if not name:
            raise Fatal('parameter "scenario" is required (a name in scenarios/ or a path)')
        scenario = scenario_io.load(name)
        n = scenario.n_uavs
        if not 2 <= self.index <= n:
            raise Fatal(f'uav_index {self.index} must be a follower: 2..{n}')
        self.n = n
        self.period_ns = int(round(1e9 / scenario.simulation.control_rate))
        prepare_node_laws(scenario, self.index - 1)  # before our topics appear
        self.runtime = ControllerRuntime(scenario, self.index - 1)
        self.packer = AnswerMessages(scenario)  # the answer as CDR bytes
        self.states: dict[int, Sequence[UavState]] = {}   # t_ns -> every UAV's state
        self.read_snapshot = SnapshotReader(scenario)
        self.create_subscription(FormationSnapshot, SNAPSHOT_TOPIC, self.on_snapshot,
                                 SUBSCRIBER_QOS, raw=True)
        self.create_subscription(RotorCommand, uav_topic(1, ROTOR_CMD), self.on_leader,
                                 SUBSCRIBER_QOS)
        i = self.index
        self.cmd_pub = self.create_publisher(RotorCommand, uav_topic(i, ROTOR_CMD),
                                             PUBLISHER_QOS)
        self.setpoint_pub = self.create_publisher(AttitudeSetpoint,
                                                  uav_topic(i, ATTITUDE_SETPOINT), PUBLISHER_QOS)
        self.error_pub = self.create_publisher(VirtualConstraintError,
                                               uav_topic(i, FORMATION_ERROR), PUBLISHER_QOS)
        self.outputs = RawPublishers(self.cmd_pub, self.setpoint_pub, self.error_pub,
                                     confirm_first=FIRST_ACK_TIMEOUT if self.record else 0.0)

    def missing_peers(self) -> str | None:
        return controller_peers_missing(self, self.cmd_pub, self.record)

    def on_leader(self, msg: RotorCommand) -> None:
        t_ns = ns_from_stamp(msg.header.stamp)
        self.runtime.note_command(0, t_ns, np.asarray(msg.angular_velocity, dtype=float))
        self.try_answer(t_ns)

    def on_snapshot(self, data: bytes) -> None:
        t_ns, states, previous = self.read_snapshot(data)
        for j, speeds in enumerate(previous[1:], start=1):  # the followers' answers to t - 1
            self.runtime.note_command(j, t_ns - self.period_ns, speeds)
        self.states[t_ns] = states
        self.try_answer(t_ns)

    def try_answer(self, t_ns: int) -> None:
        if t_ns not in self.states or not self.runtime.ready(t_ns):
            return
        states = self.states.pop(t_ns)
        for stamp in [k for k in self.states if k < t_ns]:
            del self.states[stamp]
        self.outputs.send(self.packer.of(self.runtime.answer(t_ns, states)))


def main(args: list[str] | None = None) -> NoReturn:
    run_nodes(lambda: [FollowerNode()], serve, args)


if __name__ == '__main__':
    main()
