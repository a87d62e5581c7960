"""A leader controller of your own for `scripts/multilift run SCENARIO --external uav1`.

The simulator publishes the state of uav1 on /uav1/odom (nav_msgs/Odometry: pose in `world`,
twist in the body frame) and waits, at every control tick, for one /uav1/rotor_cmd
(multilift_msgs/RotorCommand: one angular velocity [rad/s] per rotor) stamped with the time of
the state it answers. This node answers with the project's cascade controller following the
scenario's mission; put your own control law in `control()`.

Written the usual way: default QoS (reliable, volatile, depth 10) on both topics.

    ros2 run multilift_example_leader leader --ros-args -p scenario:=single_lift
"""
from __future__ import annotations

import rclpy
import rclpy.logging
from multilift_msgs.msg import RotorCommand
from nav_msgs.msg import Odometry
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from multilift_control.cascade import FormationStates, UavState
from multilift_control.controllers import LeaderController
from multilift_sim import scenario as scenario_io
from multilift_sim.ros.common import odometry_arrays


class ExampleLeader(Node):
    def __init__(self) -> None:
        super().__init__('example_leader')
        name = self.declare_parameter('scenario', 'single_lift').value
        self.controller = LeaderController(scenario_io.load(name), index=0)
        self.command_pub = self.create_publisher(RotorCommand, '/uav1/rotor_cmd', 10)
        self.create_subscription(Odometry, '/uav1/odom', self.on_odometry, 10)
        self.answered = 0

    def control(self, t: float, msg: Odometry) -> list[float]:
        """Rotor speeds [rad/s] for the state `msg` at simulated time t [s]: your law here."""
        # the formation as this node sees it: its own state alone (no payload state, so the
        # scenario's control.payload_feedback must be off; /formation/snapshot carries it)
        states = FormationStates((UavState(*odometry_arrays(msg)),))
        output, _reference = self.controller.update(t, states)
        return [float(w) for w in output.rotor_speeds]

    def on_odometry(self, msg: Odometry) -> None:
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        command = RotorCommand(angular_velocity=self.control(t, msg))
        command.saturated = [False] * len(command.angular_velocity)
        command.header.stamp = msg.header.stamp  # the state this command answers
        command.header.frame_id = 'uav1/base_link'
        self.command_pub.publish(command)
        self.answered += 1


def main(args: list[str] | None = None) -> None:
    rclpy.init(args=args)
    node = ExampleLeader()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        # Ctrl-C (SIGINT) or SIGTERM has shut the context down by now (rclpy's signal handler),
        # and a node's logger would still try its /rosout publisher ("Failed to publish log
        # message to rosout"): the last line goes out after the node is destroyed, through a
        # logger no node owns (the console and the log file, not /rosout)
        answered = node.answered
        node.destroy_node()
        rclpy.logging.get_logger('example_leader').info(f'answered {answered} states')
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
