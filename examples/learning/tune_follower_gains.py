"""Improve the follower law's gains on `multilift/Mission-v0` with a cross-entropy search, no
learning library needed: each generation's candidates (alpha_vc, beta_vc: seed Eq. 3.11's
derivative and proportional gains) are one batch of the vectorised environment (one engine
call per step for the whole population), each flown by the baseline policy, that is the
seed's controllers with the candidate's gains; the elite's mean and spread seed the next
generation.

    source scripts/env.sh
    python examples/learning/tune_follower_gains.py [--scenario twin_lift] [--duration 30]
        [--population 32] [--generations 6] [--seed 0]
"""
from __future__ import annotations

import argparse

import numpy as np

from multilift_sim import kernels  # noqa: F401 - NUMBA_CACHE_DIR before numba loads
from multilift_learning.tasks import scenario_of
from multilift_learning.vector_env import FormationVectorEnv


def returns(scenario: str, duration: float, gains: np.ndarray) -> np.ndarray:
    """Each candidate's return (one episode of Mission-v0 under the baseline policy)."""
    scenarios = [scenario_of(scenario, {'formation.alpha_vc': float(a),
                                        'formation.beta_vc': float(b)}, duration)
                 for a, b in gains]
    envs = FormationVectorEnv(len(scenarios), task='mission', scenarios=scenarios)
    envs.reset(seed=0)
    total = np.zeros(len(scenarios))
    done = np.zeros(len(scenarios), dtype=bool)
    while not done.all():
        _, reward, terminated, truncated, _ = envs.step(envs.expert_actions())
        total += np.where(done, 0.0, reward)
        done |= terminated | truncated
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--scenario', default='twin_lift')
    parser.add_argument('--duration', type=float, default=30.0)
    parser.add_argument('--population', type=int, default=32)
    parser.add_argument('--generations', type=int, default=6)
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args()
    base = scenario_of(args.scenario).formation
    rng = np.random.default_rng(args.seed)
    mean = np.array([base.alpha_vc, base.beta_vc])
    spread = 0.5 * mean
    elite_count = max(2, args.population // 4)
    seed_return = returns(args.scenario, args.duration, mean[None])[0]
    print(f'{args.scenario}, Mission-v0, {args.duration:g} s: the seed\'s gains alpha_vc = '
          f'{mean[0]:.2f}, beta_vc = {mean[1]:.2f}: return {seed_return:.1f}')
    for generation in range(1, args.generations + 1):
        gains = np.clip(rng.normal(mean, spread, (args.population, 2)), 0.05, 20.0)
        scores = returns(args.scenario, args.duration, gains)
        elite = gains[np.argsort(scores)[-elite_count:]]
        mean, spread = elite.mean(axis=0), elite.std(axis=0) + 0.02
        print(f'generation {generation}: best {scores.max():.1f}, mean {scores.mean():.1f}; '
              f'elite mean alpha_vc = {mean[0]:.2f}, beta_vc = {mean[1]:.2f}')
    final = returns(args.scenario, args.duration, mean[None])[0]
    print(f'the search\'s gains alpha_vc = {mean[0]:.2f}, beta_vc = {mean[1]:.2f}: return '
          f'{final:.1f} (the seed\'s: {seed_return:.1f})')


if __name__ == '__main__':
    main()
