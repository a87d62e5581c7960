"""Issue 22's throughput target: twin-lift `multilift/Hover-v0`, 256 environments in one
`gymnasium.make_vec` (one batched engine), environment steps per second on one core (target
>= 50,000), random actions; and the same with the baseline policy's actions (the seed's
controllers computed in the same compiled call per step). CPU time is printed beside wall
time (on a busy machine the CPU figure is the fairer one). Then the baseline's return over
whole episodes of each task, twin-lift and V, and what a tick pays the baseline, hovering
(action 0) and random actions (`reference_rewards`).

    python benchmarks/learning.py [--envs 256] [--steps 2000] [--rewards-only]
    MULTILIFT_PLAIN_REFCOUNTS=1 python benchmarks/learning.py ...   (plain reference counts,
    `multilift_sim.kernels.plain_reference_counts`: what a process that runs the environments
    from one thread may choose; the figures say which counts they had)
"""
from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

from multilift_sim import kernels  # noqa: E402 - NUMBA_CACHE_DIR before numba loads

import gymnasium  # noqa: E402
import numpy as np  # noqa: E402

import multilift_learning  # noqa: E402,F401 - registers the environments


def throughput(envs, steps: int, policy) -> tuple[float, float]:
    """(environment steps per wall second, per CPU second) over `steps` vector steps."""
    envs.reset(seed=0)
    envs.step(policy())  # compile and warm
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(steps):
        envs.step(policy())
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return steps * envs.num_envs / wall, steps * envs.num_envs / cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--envs', type=int, default=256)
    parser.add_argument('--steps', type=int, default=2000)
    parser.add_argument('--rewards-only', action='store_true',
                        help='only the per-tick rewards of the reference policies')
    args = parser.parse_args()
    if args.rewards_only:
        reference_rewards()
        return
    envs = gymnasium.make_vec('multilift/Hover-v0', num_envs=args.envs)
    rng = np.random.default_rng(0)
    for name, policy in (('random actions near hover (0.02 about action 0)',
                          lambda: np.clip(rng.normal(0, 0.02, (args.envs, 8)), -1, 1)),
                         ('baseline policy (expert_actions)', envs.expert_actions)):
        wall, cpu = throughput(envs, args.steps, policy)
        print(f'Hover-v0 twin_lift, {args.envs} envs, {name}: {wall:,.0f} env steps/s wall, '
              f'{cpu:,.0f} per CPU s (target >= 50,000; '
              f'{"plain" if kernels.plain_reference_counts() else "atomic"} reference counts)')
    baseline_returns()
    reference_rewards()


def reference_rewards(episodes: int = 64, duration: float = 20.0) -> None:
    """Twin-lift Hover-v0, `episodes` episodes of `duration` [s] (seeds 0..): the mean reward
    per tick, the mean episode length and the share flown to the end, for the baseline, action
    0 (hover) and uniform random actions, in each action mode."""
    rng = np.random.default_rng(0)
    for mode in ('rotor_speeds', 'thrust_body_rates'):
        envs = gymnasium.make_vec('multilift/Hover-v0', num_envs=episodes, duration=duration,
                                  action_mode=mode)
        size = envs.single_action_space.shape[0]
        policies = {'action 0 (hover)': lambda: np.zeros((episodes, size)),
                    'uniform random actions': lambda: rng.uniform(-1, 1, (episodes, size))}
        if mode == 'rotor_speeds':
            policies = {'baseline (expert_actions)': envs.expert_actions, **policies}
        for name, policy in policies.items():
            envs.reset(seed=0)
            alive = np.ones(episodes, dtype=bool)
            total, ticks = np.zeros(episodes), np.zeros(episodes)
            while alive.any():
                _, reward, terminated, truncated, _ = envs.step(policy())
                total += np.where(alive, reward, 0.0)
                ticks += alive
                alive &= ~(terminated | truncated)
            flown = np.mean(ticks == round(duration * 100))
            print(f'Hover-v0 twin_lift {mode}, {name}: {total.sum() / ticks.sum():.3f} per tick, '
                  f'episodes of {ticks.mean() / 100:.2f} s on average, {flown:.0%} flown to '
                  f'the end of {duration:g} s')


def baseline_returns() -> None:
    """The baseline policy's return over whole episodes (the scenario's duration) of each task,
    for the twin-lift and the V: the numbers a learned policy has to beat."""
    for env_id in ('multilift/Hover-v0', 'multilift/Mission-v0'):
        for scenario in ('twin_lift', 'multi_lift'):
            env = gymnasium.make(env_id, scenario=scenario).unwrapped
            env.reset(seed=0)
            total, steps, done = 0.0, 0, False
            while not done:
                _, reward, terminated, truncated, _ = env.step(env.expert_action())
                total, steps, done = total + reward, steps + 1, terminated or truncated
            print(f'{env_id} {scenario}: return of the baseline {total:,.1f} over {steps} steps '
                  f'({"truncated" if truncated else "terminated"})')


if __name__ == '__main__':
    main()
