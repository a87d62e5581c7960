"""Train PPO (stable-baselines3, `scripts/setup --learning`) on a batched learning environment and
write the policy as a plain numpy MLP, then evaluate it on held-out seeds.

    nice -n 19 python examples/learning/train_ppo.py --env multilift/Hover-v0 --steps 2000000 \
        --out runs/ppo_hover_s0 --seed 0

Writes DIR/policy.npz (`multilift_learning.policies.load`: layers, activation, the observation
normalisation of SB3's VecNormalize), DIR/progress.csv (the learning curve: environment steps,
wall time [s], steps per second, mean episode return and length of the last 100 episodes),
DIR/evaluation.json (`evaluate`: the exported policy and the baseline on the same held-out
episodes). `--minutes M` stops learning after M minutes of wall time (the steps reached are
recorded in policy.npz). The environments are one `FormationVectorEnv` (SAME_STEP autoreset) behind
`multilift_learning.sb3.SB3VecEnv`; one torch thread.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import time
from pathlib import Path

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
# plain reference counts (multilift_sim.kernels.plain_reference_counts): this process steps the
# environments from one thread and runs no parallel numba code of its own
os.environ.setdefault('MULTILIFT_PLAIN_REFCOUNTS', '1')

from multilift_sim import kernels  # noqa: E402,F401 - NUMBA_CACHE_DIR before numba loads

import gymnasium  # noqa: E402
import numpy as np  # noqa: E402

import multilift_learning  # noqa: E402,F401 - registers the environments
from multilift_learning.policies import MlpPolicy, save, shared_by_agents  # noqa: E402

EVALUATION_SEED = 1_000_000  # held out: training seeds its streams with 1000 seed + k, k < envs


def env_arguments(args: argparse.Namespace) -> dict:
    """The environment's arguments (the ones policy.npz records; `agents`: a policy of one UAV
    that every UAV flies, the PettingZoo env's agent)."""
    return {'scenario': args.scenario, 'duration': args.duration, 'agents': args.agents,
            'options': {'action_mode': args.action_mode, 'start': 'rest',
                        'normalise': False}}


def train(args: argparse.Namespace) -> MlpPolicy:
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    from multilift_learning.sb3 import SB3AgentVecEnv, SB3VecEnv

    torch.set_num_threads(1)
    arguments = env_arguments(args)
    venv = (SB3AgentVecEnv if args.agents else SB3VecEnv).make(
        args.env, args.envs, scenario=args.scenario, duration=args.duration,
        **arguments['options'])
    agents = venv.n if args.agents else 1  # SB3 counts each agent's step
    venv.seed(args.seed * 1000)
    venv = VecNormalize(VecMonitor(venv), norm_obs=True, norm_reward=True, clip_obs=10.0,
                        gamma=args.gamma)
    model = PPO('MlpPolicy', venv, seed=args.seed, device='cpu', n_steps=args.rollout,
                batch_size=args.batch, n_epochs=args.epochs, learning_rate=3e-4,
                gamma=args.gamma, gae_lambda=args.gae_lambda, clip_range=0.2, ent_coef=0.0,
                policy_kwargs={'net_arch': [64, 64], 'activation_fn': torch.nn.Tanh,
                               'log_std_init': args.log_std}, verbose=0)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()

    class Curve(BaseCallback):
        """A row of progress.csv after every rollout."""
        def __init__(self, writer):
            super().__init__()
            self.writer = writer

        def _on_step(self) -> bool:  # False: out of --minutes, learning stops here
            return args.minutes is None or time.perf_counter() - start < 60 * args.minutes

        def _on_rollout_end(self) -> None:
            episodes = list(self.model.ep_info_buffer)
            wall = time.perf_counter() - start
            steps = self.num_timesteps // agents
            row = [steps, round(wall, 1), round(steps / wall),
                   round(float(np.mean([e['r'] for e in episodes])), 2) if episodes else '',
                   round(float(np.mean([e['l'] for e in episodes])), 1) if episodes else '']
            self.writer.writerow(row)
            handle.flush()
            print(' '.join(map(str, row)), flush=True)

    with open(out / 'progress.csv', 'w', newline='') as handle:
        writer = csv.writer(handle)
        writer.writerow(['steps', 'wall_s', 'steps_per_s', 'return_mean', 'length_mean'])
        model.learn(total_timesteps=args.steps * agents, callback=Curve(writer))
    args.steps = model.num_timesteps // agents  # fewer where --minutes ran out
    return exported(model, venv, args, arguments)


def exported(model, venv, args: argparse.Namespace, arguments: dict) -> MlpPolicy:
    """The PPO policy's deterministic action (the Gaussian's mean) as an MlpPolicy."""
    import torch
    layers = [m for m in model.policy.mlp_extractor.policy_net if isinstance(m, torch.nn.Linear)]
    layers.append(model.policy.action_net)
    weights = tuple(layer.weight.detach().numpy().T.astype(np.float64) for layer in layers)
    biases = tuple(layer.bias.detach().numpy().astype(np.float64) for layer in layers)
    rms = venv.obs_rms
    environment = dict(arguments, id=args.env, trained={'steps': args.steps, 'seed': args.seed,
                                                        'library': 'stable-baselines3 PPO'})
    return MlpPolicy(weights, biases, 'tanh', rms.mean.astype(np.float64),
                     np.sqrt(rms.var + venv.epsilon), float(venv.clip_obs), environment)


def evaluate(env_id: str, arguments: dict, policy, episodes: int, last: float) -> dict:
    """Fly `episodes` held-out episodes (seeds EVALUATION_SEED + k) at once with `policy`
    (observations -> actions, batched; None: the baseline): the share flown to their end (not
    terminated), and the payload's distance from its target [m] averaged over each episode's
    last `last` seconds (of those flown to the end), mean and worst."""
    envs = gymnasium.make_vec(env_id, num_envs=episodes, scenario=arguments['scenario'],
                              duration=arguments['duration'],
                              **(arguments['options'] if policy is not None else {}))
    if policy is not None and arguments['agents']:
        policy = shared_by_agents(policy, envs.batch.n)
    observations, _ = envs.reset(seed=EVALUATION_SEED)
    steps = int(round(arguments['duration'] * 100))
    errors = np.full((steps, episodes), np.nan)
    alive = np.ones(episodes, dtype=bool)
    for k in range(steps):
        actions = envs.expert_actions() if policy is None else policy(observations)
        observations, _, terminated, truncated, infos = envs.step(actions)
        errors[k, alive] = infos['payload_error'][alive]
        alive &= ~terminated
        if (terminated | truncated).all():
            break
    tail = errors[-int(last * 100):, alive]
    per_episode = tail.mean(axis=0) if alive.any() else np.array([np.nan])
    return {'episodes': episodes, 'flown_to_end': float(alive.mean()),
            'payload_error_last_s': last, 'payload_error_mean': float(np.mean(per_episode)),
            'payload_error_worst': float(np.max(per_episode))}


def evaluate_parallel(env_id: str, arguments: dict, policy, episodes: int, last: float) -> dict:
    """`evaluate`'s figures for an agent's policy flown by every agent of the PettingZoo env
    (`multilift_learning.parallel_env`), one episode after another: episode k is seeded as
    `evaluate`'s environment k (EVALUATION_SEED + k), so these are its first `episodes`."""
    from multilift_learning.parallel_env import parallel_env
    env = parallel_env(scenario=arguments['scenario'], task=gymnasium.spec(env_id).kwargs['task'],
                       duration=arguments['duration'], **arguments['options'])
    flown, per_episode = 0, []
    for k in range(episodes):
        observations, _ = env.reset(seed=EVALUATION_SEED + k)
        errors, ended = [], False
        while env.agents:
            observations, _, terminated, _, infos = env.step(
                {agent: policy(observations[agent]) for agent in env.agents})
            errors.append(infos['uav1']['payload_error'])
            ended = terminated['uav1']
        if not ended:
            flown += 1
            per_episode.append(np.mean(errors[-int(last * 100):]))
    return {'episodes': episodes, 'flown_to_end': flown / episodes, 'payload_error_last_s': last,
            'payload_error_mean': float(np.mean(per_episode)) if per_episode else None,
            'payload_error_worst': float(np.max(per_episode)) if per_episode else None}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--env', default='multilift/Hover-v0')
    parser.add_argument('--steps', type=int, required=True, help='environment steps')
    parser.add_argument('--out', required=True, help='folder for policy.npz and the curve')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--scenario', default='twin_lift')
    parser.add_argument('--duration', type=float, default=20.0, help='episode length [s]')
    parser.add_argument('--action-mode', default='thrust_body_rates')
    parser.add_argument('--envs', type=int, default=32, help='formations in the batch')
    parser.add_argument('--agents', action='store_true',
                        help='one policy per UAV, its parameters shared (the PettingZoo '
                             'env\'s agents, multilift_learning.sb3.SB3AgentVecEnv)')
    parser.add_argument('--rollout', type=int, default=256, help='steps per env per update')
    parser.add_argument('--batch', type=int, default=512, help='PPO minibatch')
    parser.add_argument('--epochs', type=int, default=10, help='PPO epochs per update')
    parser.add_argument('--gamma', type=float, default=0.998,
                        help='discount per tick (100 Hz: 0.998 looks 5 s ahead)')
    parser.add_argument('--gae-lambda', type=float, default=0.98)
    parser.add_argument('--log-std', type=float, default=-2.0,
                        help='initial log standard deviation of the actions (-2: 0.14)')
    parser.add_argument('--eval-episodes', type=int, default=50)
    parser.add_argument('--minutes', type=float, default=None,
                        help='stop learning after this wall time (then export, evaluate)')
    args = parser.parse_args()
    if args.steps <= 0:
        parser.error(f'--steps must be > 0, got {args.steps}')
    policy = train(args)
    path = save(Path(args.out) / 'policy.npz', policy)
    arguments = env_arguments(args)
    result = {'policy': evaluate(args.env, arguments, policy, args.eval_episodes, 10.0),
              'baseline': evaluate(args.env, arguments, None, args.eval_episodes, 10.0)}
    if args.agents:  # the same policy in the PettingZoo env itself, its first episodes
        result['parallel_env'] = evaluate_parallel(args.env, arguments, policy,
                                                   min(args.eval_episodes, 5), 10.0)
    (Path(args.out) / 'evaluation.json').write_text(json.dumps(result, indent=1))
    print(f'{path}: {json.dumps(result)}')


if __name__ == '__main__':
    main()
