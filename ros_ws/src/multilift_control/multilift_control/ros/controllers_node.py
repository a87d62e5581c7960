"""Every controller node of a run in one process (ROS 2 composition, by hand): the leader and
the followers of a scenario, but those flown elsewhere (`external`), the very nodes
`leader_node` and `follower_node` run one per process, here on one rclpy context (one DDS
participant) and one executor. Their names (`leader`, `follower2`, ...), topics and QoS are
those of separate processes: a user's tools see the same graph, one process fewer per UAV.
`multilift run SCENARIO --compose` starts it.

    ros2 run multilift_control controllers_node SCENARIO [--external uav1,uav3,...] [--record]
        [--live] [--summary-dir DIR] [--ros-args ...]

The lockstep is the one of separate processes: the nodes still talk through the topics (the
leader's command reaches the followers as a message), and a follower answers the state at t
once it holds both the snapshot at t and the leader's command for t, in whichever order the
executor delivers them; nothing a node computes depends on when its peers in the process ran,
so the answers, and the bag, are those of separate processes (tests/ros/test_compose.py).
"""
from __future__ import annotations

import argparse
from collections.abc import Iterator
from typing import NoReturn

from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.utilities import remove_ros_args

from multilift_control.ros.common import serve
from multilift_control.ros.follower_node import FollowerNode
from multilift_control.ros.leader_node import LeaderNode
from multilift_sim import scenario as scenario_io
from multilift_sim.ros.common import Fatal, run_nodes
from multilift_sim.topics import parse_external


def controller_nodes(scenario: str, external: str = '', record: bool = False,
                     summary_dir: str = '', live: bool = False) -> Iterator[Node]:
    """The controller nodes of `scenario` (a name in scenarios/ or a YAML path), but those of
    the UAVs in `external` (`uav1,uav3`), with the parameters each would get alone."""
    n = scenario_io.load(scenario).n_uavs
    try:
        skipped = parse_external(external, n)
    except ValueError as error:
        raise Fatal(f'--external: {error}') from None
    if len(skipped) == n:
        raise Fatal(f'every UAV of {scenario} is external: no controller to compose')
    common = [Parameter('scenario', value=scenario), Parameter('record', value=record),
              Parameter('summary_dir', value=summary_dir)]
    for i in range(1, n + 1):
        if i == 1 and i not in skipped:
            yield LeaderNode(parameter_overrides=[*common, Parameter('live', value=live)])
        elif i not in skipped:
            yield FollowerNode(f'follower{i}', parameter_overrides=[
                *common, Parameter('uav_index', value=i)])


def main(args: list[str] | None = None) -> NoReturn:
    """`args`: the whole command line (sys.argv by default); what follows `--ros-args` is
    rclpy's and applies to every node of the process."""
    parser = argparse.ArgumentParser(prog='controllers_node', description=__doc__.split('\n')[0])
    parser.add_argument('scenario', help='a name in scenarios/ or a YAML path')
    parser.add_argument('--external', default='', metavar='uav1[,uav3,...]',
                        help='UAVs whose controllers run elsewhere: not composed here')
    parser.add_argument('--record', action='store_true',
                        help='a recorder records the run: wait for it before the first answer')
    parser.add_argument('--live', action='store_true',
                        help='the leader flies live goals and paths (multilift run --live)')
    parser.add_argument('--summary-dir', default='', metavar='DIR',
                        help="leave each node's run figures as DIR/<node>.json")
    options = parser.parse_args(remove_ros_args(args)[1:])
    run_nodes(lambda: controller_nodes(options.scenario, options.external, options.record,
                                       options.summary_dir, options.live), serve, args,
                           name='controllers')


if __name__ == '__main__':
    main()
