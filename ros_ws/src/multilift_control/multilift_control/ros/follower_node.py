"""Follower node: UAV i (2..n) keeps the formation through virtual constraints (seed §3.2).

For the state at t it needs every UAV's `/uav{j}/odom` stamped t and the leader's
`/uav1/rotor_cmd` answering t: the thrust vectors u_f,r of Eq. 3.9-3.12 are R_j(t) e_z u_T,j
with u_T,j = k_T sum(omega^2) of the leader's command at t and of the other followers' latest
commands (the previous tick's). It publishes `/uav{i}/rotor_cmd`, `/uav{i}/attitude_setpoint`
and `/uav{i}/formation_error` (its rows of g_vc and their rates). Parameters: scenario,
uav_index, record, summary_dir.
"""
from __future__ import annotations

import numpy as np
from multilift_msgs.msg import AttitudeSetpoint, RotorCommand, VirtualConstraintError
from nav_msgs.msg import Odometry
from rclpy.node import Node

from multilift_control.cascade import UavState
from multilift_control.formation import FormationFollower
from multilift_sim.ros import messages
from multilift_sim import scenario as scenario_io
from multilift_sim.kinematics import rotation_matrix
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
        self.scenario = scenario_io.load(name)
        n = self.scenario.n_uavs
        if not 2 <= self.index <= n:
            raise Fatal(f'uav_index {self.index} must be a follower: 2..{n}')
        self.controller = FormationFollower.from_scenario(self.scenario, self.index - 1)
        self.thrust_coefficients = [u.vehicle.thrust_coefficient for u in self.scenario.uavs]
        share = self.scenario.payload.mass / n
        g = self.scenario.simulation.gravity
        self.thrusts = [(u.vehicle.mass + share) * g for u in self.scenario.uavs]  # [N]
        self.odometry: dict[int, dict[int, Odometry]] = {}
        self.leader_cmd: dict[int, RotorCommand] = {}
        self.pending_thrusts: dict[int, dict[int, float]] = {}
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
        self.max_abs_error = 0.0
        self.error_sum = 0.0
        self.samples = 0

    def missing_peers(self) -> str | None:
        return controller_peers_missing(self, self.cmd_pub, self.record)

    def on_command(self, j: int, msg: RotorCommand) -> None:
        t_ns = ns_from_stamp(msg.header.stamp)
        if j == 1:
            self.leader_cmd[t_ns] = msg
            self.try_answer(t_ns)
        else:  # another follower: its thrust is used from the next tick on (deterministic)
            speeds = np.asarray(msg.angular_velocity, dtype=float)
            self.pending_thrusts.setdefault(t_ns, {})[j] = \
                self.thrust_coefficients[j - 1] * float(np.sum(speeds ** 2))

    def on_odometry(self, j: int, msg: Odometry) -> None:
        t_ns = ns_from_stamp(msg.header.stamp)
        self.odometry.setdefault(t_ns, {})[j] = msg
        self.try_answer(t_ns)

    def try_answer(self, t_ns: int) -> None:
        odoms = self.odometry.get(t_ns, {})
        if len(odoms) < self.scenario.n_uavs or t_ns not in self.leader_cmd:
            return
        del self.odometry[t_ns]
        leader = self.leader_cmd.pop(t_ns)
        for stamp in sorted(k for k in self.pending_thrusts if k < t_ns):
            for j, thrust in self.pending_thrusts.pop(stamp).items():
                self.thrusts[j - 1] = thrust
        for old in [k for k in self.odometry if k < t_ns]:
            del self.odometry[old]
        self.thrusts[0] = self.thrust_coefficients[0] * float(
            np.sum(np.asarray(leader.angular_velocity) ** 2))
        states = [UavState(*odometry_arrays(odoms[j + 1])) for j in range(len(odoms))]
        thrust_vectors = np.array([rotation_matrix(s.euler)[:, 2] * u
                                   for s, u in zip(states, self.thrusts)])
        out, errors, rates = self.controller.update(t_ns * 1e-9, states, thrust_vectors)
        self.thrusts[self.index - 1] = self.thrust_coefficients[self.index - 1] * float(
            np.sum(out.rotor_speeds ** 2))
        self.cmd_pub.publish(messages.rotor_command(t_ns, self.index, out))
        self.setpoint_pub.publish(messages.attitude_setpoint(t_ns, self.index, out))
        self.error_pub.publish(messages.formation_error(t_ns, errors, rates))
        self.max_abs_error = max(self.max_abs_error, float(np.max(np.abs(errors))))
        self.error_sum += float(np.linalg.norm(errors))
        self.samples += 1

    def summary(self) -> dict:
        return {'max_abs_formation_error': self.max_abs_error,
                'mean_formation_error_norm': self.error_sum / max(self.samples, 1),
                'answered_states': self.samples}


def main(args: list[str] | None = None) -> int:
    return run_node(FollowerNode, lambda node: serve_controller(
        node, f'follower{node.index}', node.summary), args)


if __name__ == '__main__':
    raise SystemExit(main())
