"""A trained policy's ROS run against its headless episode (issue 36 item 4): the bag that
`policy_node -p policy:=npz:PATH` flew (docs/learning.md, "From training to ROS") and the
same policy in `gymnasium.make(ENV, duration=..., target_radius=0.0, **its options)` from
`reset(seed=0)`, the same start and target.

    python examples/learning/ros_vs_headless.py runs/ppo_ros runs/ppo_hover_s0/policy.npz

Prints the largest payload position difference [m] over the ticks both flew, and the payload's
distance from its target averaged over the last 10 s of each (the issue's figure).
"""
from __future__ import annotations

import argparse

from multilift_sim import kernels  # noqa: F401 - NUMBA_CACHE_DIR before numba loads

import gymnasium  # noqa: E402
import numpy as np  # noqa: E402

import multilift_learning  # noqa: E402,F401 - registers the environments
from multilift_learning.policies import load  # noqa: E402
from multilift_tools.bagdata import load_run  # noqa: E402


def headless(policy, duration: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """The policy's episode: times [s], payload positions (T, 3) and target (3,) [m], world
    z up, and its termination ('' if flown to its end)."""
    arguments = policy.environment
    env = gymnasium.make(arguments['id'], scenario=arguments['scenario'], duration=duration,
                         **dict(arguments['options'], target_radius=0.0))
    observation, _ = env.reset(seed=0)
    batch = env.unwrapped.batch
    target = batch.targets.at(batch.engine.t)[0][0].copy()
    times, positions, reason = [], [], ''
    while True:
        observation, _, terminated, truncated, info = env.step(policy(observation[None])[0])
        times.append(info['t'])
        positions.append(batch.engine.payload_positions[0].copy())
        if terminated or truncated:
            reason = info['termination'] if terminated else ''
            break
    return np.array(times), np.array(positions), target, reason


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('bag', help='the ROS run\'s bag folder')
    parser.add_argument('policy', help='the policy.npz it flew')
    parser.add_argument('--duration', type=float, default=20.0, help='episode length [s]')
    parser.add_argument('--last', type=float, default=10.0, help='averaged over the last [s]')
    args = parser.parse_args()
    policy = load(args.policy)
    t, positions, target, reason = headless(policy, args.duration)
    run = load_run(args.bag)
    ros_t, ros_positions = run.payload_time, run.payload_position()
    index = np.searchsorted(ros_t, t - 1e-9)
    both = index < len(ros_t)
    difference = np.abs(ros_positions[index[both]] - positions[both]).max()
    print(f'ticks compared: {int(both.sum())}, max |payload position difference| '
          f'{difference:.3g} m')
    for name, times, path in (('headless', t, positions), ('ROS', ros_t, ros_positions)):
        tail = times > times[-1] - args.last
        error = np.linalg.norm(path[tail] - target, axis=1).mean()
        ended = f' ({reason})' if name == 'headless' and reason else ''
        print(f'{name}: flew {times[-1]:.2f} s{ended}, payload error over its last '
              f'{args.last:g} s {error:.4f} m')


if __name__ == '__main__':
    main()
