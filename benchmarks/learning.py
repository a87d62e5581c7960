"""Issue 22's throughput target: twin-lift `multilift/Hover-v0`, 256 environments in one
`gymnasium.make_vec` (one batched engine), environment steps per second on one core (target
>= 50,000), random actions; and the same with the baseline policy's actions (the seed's
controllers computed in the same compiled call per step). CPU time is printed beside wall
time (on a busy machine the CPU figure is the fairer one). Then the baseline's return over
whole episodes of each task, twin-lift and V.

    python benchmarks/learning.py [--envs 256] [--steps 2000]
"""
from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

from multilift_sim import kernels  # noqa: E402,F401 - NUMBA_CACHE_DIR before numba loads

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
    args = parser.parse_args()
    envs = gymnasium.make_vec('multilift/Hover-v0', num_envs=args.envs)
    rng = np.random.default_rng(0)
    hover = envs.batch.actions(np.broadcast_to(envs.batch.speed_hover,
                                               (args.envs, envs.batch.n, envs.batch.rotors)))
    for name, policy in (('random actions near hover',
                          lambda: np.clip(hover + rng.normal(0, 0.02, hover.shape), -1, 1)),
                         ('baseline policy (expert_actions)', envs.expert_actions)):
        wall, cpu = throughput(envs, args.steps, policy)
        print(f'Hover-v0 twin_lift, {args.envs} envs, {name}: {wall:,.0f} env steps/s wall, '
              f'{cpu:,.0f} per CPU s (target >= 50,000)')
    baseline_returns()


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
