"""The leader's live goals and paths over ROS (`multilift run SCENARIO --live`, issue 34):
`/formation/goal` (geometry_msgs/PoseStamped) and `/formation/path` (nav_msgs/Path), frame
`world`, stamped in simulated time, read into `multilift_control.live_goals` targets. A message
that cannot be flown (another frame, positions not finite, a path's stamps not increasing) is
logged as a warning and ignored."""
from __future__ import annotations

import math

import numpy as np
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Path
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from multilift_control.live_goals import LiveMission, LiveTarget
from multilift_sim.kinematics import euler_from_quaternion
from multilift_sim.topics import GOAL, PATH
from multilift_sim.wire.msgvalues import WORLD_FRAME

# Each topic is read twice: reliable volatile, which every publisher matches (the defaults of
# `create_publisher(T, topic, 10)`, Foxglove's), and reliable transient local, which matches
# publishers that keep their message (`multilift goal`): a reader that matched such a writer
# after it sent asks for the message again, so the sender's wait for acknowledgements is a
# wait for delivery. A message both readers deliver is taken once.
VOLATILE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)
KEPT = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                  durability=DurabilityPolicy.TRANSIENT_LOCAL)


def _seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def _yaw(q) -> float:
    """The heading [rad] of an orientation quaternion (its ZYX yaw, world z up:
    `kinematics.euler_from_quaternion`); NaN for the zero quaternion (an orientation left
    unset: keep the current heading)."""
    if q.x == q.y == q.z == q.w == 0.0:
        return math.nan
    return float(euler_from_quaternion([q.x, q.y, q.z, q.w])[2])


def _point(pose) -> list[float]:
    return [pose.position.x, pose.position.y, pose.position.z]


class LiveInput:
    """Subscribes `node` to the live topics and queues what arrives into `mission`."""

    def __init__(self, node: Node, mission: LiveMission):
        self.node, self.mission = node, mission
        self._seen: set[bytes] = set()  # the targets taken, as bytes (one delivery each)
        for qos in (VOLATILE, KEPT):
            node.create_subscription(PoseStamped, GOAL, self.on_goal, qos)
            node.create_subscription(Path, PATH, self.on_path, qos)

    def _offer(self, topic: str, frame: str, target: LiveTarget) -> None:
        log = self.node.get_logger()
        key = b''.join(np.ascontiguousarray(a, dtype=float).tobytes() for a in (
            [target.stamp], target.points, target.yaws, target.times)) + topic.encode()
        if key in self._seen:  # the same message from the other reader
            return
        self._seen.add(key)
        if frame != WORLD_FRAME:
            log.warning(f'{topic}: frame {frame!r} ignored (goals and paths are in '
                        f'{WORLD_FRAME!r})')
            return
        why = self.mission.offer(target)
        if why is not None:
            log.warning(f'{topic} ignored: {why}')
        else:
            log.info(f'{topic}: {target.kind} to {np.round(target.points[-1], 3).tolist()} '
                     f'from t = {target.stamp:.3f} s')

    def on_goal(self, msg: PoseStamped) -> None:
        self._offer(GOAL, msg.header.frame_id, LiveTarget(
            _seconds(msg.header.stamp), np.array([_point(msg.pose)]),
            np.array([_yaw(msg.pose.orientation)])))

    def on_path(self, msg: Path) -> None:
        frames = {f for f in [msg.header.frame_id] + [p.header.frame_id for p in msg.poses]
                  if f} or {''}
        self._offer(PATH, ','.join(sorted(frames)), LiveTarget(
            _seconds(msg.header.stamp), np.array([_point(p.pose) for p in msg.poses]
                                                 ).reshape(-1, 3),
            np.array([_yaw(p.pose.orientation) for p in msg.poses]),
            np.array([_seconds(p.header.stamp) for p in msg.poses])))

    def apply(self, t: float) -> None:
        """Targets stamped at or before t [s] take effect (see LiveMission.apply)."""
        for target in self.mission.apply(t):
            late = (f' (stamped {target.stamp:.3f} s: it came later)'
                    if target.stamp < t - 1e-9 else '')
            self.node.get_logger().info(f'{target.kind} flown from t = {t:.3f} s{late}')
