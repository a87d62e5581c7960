"""Write a scenario as a learning task flies it (slack cables, the payload at rest, hover's
mission a hold; `multilift_learning.tasks.task_scenario_yaml`), for `multilift run` to fly a
trained policy through ROS with the physics it learned on.

    python examples/learning/task_scenario.py twin_lift hover runs/twin_lift_hover.yaml \
        [--duration 20]
"""
from __future__ import annotations

import argparse
from pathlib import Path

from multilift_learning.tasks import TASKS, task_scenario_yaml


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('scenario', help='a name in scenarios/ or a YAML path')
    parser.add_argument('task', choices=sorted(TASKS))
    parser.add_argument('out', help='the YAML file to write')
    parser.add_argument('--duration', type=float, default=None, help='[s]')
    parser.add_argument('--start', default='rest', choices=('rest', 'scenario'))
    args = parser.parse_args()
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(task_scenario_yaml(args.scenario, args.task, args.start,
                                                 args.duration))
    print(args.out)


if __name__ == '__main__':
    main()
