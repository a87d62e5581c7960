"""Follower node: UAV i (2..n) keeps the formation through virtual constraints (seed §3.2).

For the state at t it needs every UAV's `/uav{j}/odom` stamped t and the leader's
`/uav1/rotor_cmd` answering t; the other followers' commands are noted as they come (the
controller runtime uses them from the next tick on, multilift_control.runtime.ThrustBook).
It publishes `/uav{i}/rotor_cmd`, `/uav{i}/attitude_setpoint` and `/uav{i}/formation_error`
(its rows of g_vc and their rates). The law, the bookkeeping and the statistics are the
controller runtime's, shared with the headless loop. Parameters: scenario, uav_index,
record, summary_dir.
"""
from __future__ import annotations

import numpy as np
from multilift_msgs.msg import AttitudeSetpoint, RotorCommand, VirtualConstraintError
from nav_msgs.msg import Odometry
from rclpy.node import Node

from multilift_control.cascade import UavState
from multilift_control.runtime import ControllerRuntime
from multilift_sim import scenario as scenario_io
from multilift_sim.ros import messages
from multilift_sim.ros.common import (PUBLISHER_QOS, SUBSCRIBER_QOS, Fatal, ns_from_stamp,
                                      controller_peers_missing, odometry_arrays, run_node,
                                      serve_controller, uav_topic)


class FollowerNode(Node):
    def __init__(self) -> None:
        super().__init__('follower')  # a run names each one: --ros-args -r __node:=follower2
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
        self.runtime = ControllerRuntime(scenario, self.index - 1)
        self.odometry: dict[int, dict[int, Odometry]] = {}   # t_ns -> {uav: odometry}
        for j in range(1, n + 1):
            self.create_subscription(Odometry, uav_topic(j, 'odom'),
                                     lambda msg, j=j: self.on_odometry(j, msg), SUBSCRIBER_QOS)
            if j != self.index:
                self.create_subscription(RotorCommand, uav_topic(j, 'rotor_cmd'),
                                         lambda msg, j=j: self.on_command(j, msg),
                                         SUBSCRIBER_QOS)
        i = self.index
        self.cmd_pub = self.create_publisher(RotorCommand, uav_topic(i, 'rotor_cmd'),
                                             PUBLISHER_QOS)
        self.setpoint_pub = self.create_publisher(AttitudeSetpoint,
                                                  uav_topic(i, 'attitude_setpoint'), PUBLISHER_QOS)
        self.error_pub = self.create_publisher(VirtualConstraintError,
                                               uav_topic(i, 'formation_error'), PUBLISHER_QOS)

    def missing_peers(self) -> str | None:
        return controller_peers_missing(self, self.cmd_pub, self.record)

    def on_command(self, j: int, msg: RotorCommand) -> None:
        t_ns = ns_from_stamp(msg.header.stamp)
        self.runtime.note_command(j - 1, t_ns, np.asarray(msg.angular_velocity, dtype=float))
        if j == 1:
            self.try_answer(t_ns)

    def on_odometry(self, j: int, msg: Odometry) -> None:
        t_ns = ns_from_stamp(msg.header.stamp)
        self.odometry.setdefault(t_ns, {})[j] = msg
        self.try_answer(t_ns)

    def try_answer(self, t_ns: int) -> None:
        odoms = self.odometry.get(t_ns, {})
        if len(odoms) < self.n or not self.runtime.ready(t_ns):
            return
        for stamp in [k for k in self.odometry if k <= t_ns]:
            del self.odometry[stamp]
        states = [UavState(*odometry_arrays(odoms[j])) for j in range(1, self.n + 1)]
        answer = self.runtime.answer(t_ns, states)
        self.runtime.note_command(answer.index, t_ns, answer.output.rotor_speeds)
        i = self.index
        self.cmd_pub.publish(messages.rotor_command(t_ns, i, answer.output))
        self.setpoint_pub.publish(messages.attitude_setpoint(t_ns, i, answer.output))
        self.error_pub.publish(messages.formation_error(t_ns, answer.formation_error,
                                                        answer.formation_error_rate))


def main(args: list[str] | None = None) -> int:
    return run_node(FollowerNode, lambda node: serve_controller(
        node, node.runtime.name, node.runtime.summary), args)


if __name__ == '__main__':
    raise SystemExit(main())
