"""`SB3VecEnv`: a `FormationVectorEnv` as stable-baselines3's `VecEnv` (installed by
`scripts/setup --learning`), through the vector environment's public calls only: its SAME_STEP
autoreset (`info['final_obs']`) and its seeded `reset`. Step for step what SB3's own
`DummyVecEnv` of as many `FormationEnv`s gives (a test), at the batched engine's speed.

    from multilift_learning.sb3 import SB3VecEnv
    venv = SB3VecEnv.make('multilift/Hover-v0', num_envs=64, duration=20.0)
    model = stable_baselines3.PPO('MlpPolicy', venv)

`SB3AgentVecEnv`: the PettingZoo env's agents (one per UAV) of a batch of formations, for one
policy with its parameters shared among the UAVs.
"""
from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode
from stable_baselines3.common.vec_env import VecEnv

from multilift_learning.observations import agent_observation_slots
from multilift_learning.parallel_env import agent_spaces
from multilift_learning.vector_env import FormationVectorEnv


class _OneVectorEnv(VecEnv):
    """What SB3's VecEnv asks of attributes and methods, answered by the one FormationVectorEnv
    (`self.vector_env`) behind all of its environments."""

    def close(self) -> None:
        self.vector_env.close()

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        return [getattr(self.vector_env, attr_name)] * len(self._indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        setattr(self.vector_env, attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs):
        method = getattr(self.vector_env, method_name)
        return [method(*method_args, **method_kwargs)] * len(self._indices(indices))

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False] * len(self._indices(indices))

    def _indices(self, indices) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        return [indices] if isinstance(indices, int) else list(indices)


class SB3VecEnv(_OneVectorEnv):
    """SB3's VecEnv over `vector_env`, a FormationVectorEnv in AutoresetMode.SAME_STEP. Each
    environment's info carries the vector env's ('t', 'tension', 'payload_error',
    'termination'), SB3's 'TimeLimit.truncated' and, at an episode's end,
    'terminal_observation'."""

    def __init__(self, vector_env: FormationVectorEnv):
        if vector_env.autoreset_mode != AutoresetMode.SAME_STEP:
            raise ValueError('SB3VecEnv needs a FormationVectorEnv with '
                             'autoreset_mode=AutoresetMode.SAME_STEP (SB3 resets in the step)')
        self.vector_env = vector_env
        super().__init__(vector_env.num_envs, vector_env.single_observation_space,
                         vector_env.single_action_space)
        self._actions: np.ndarray | None = None

    @classmethod
    def make(cls, env_id: str, num_envs: int, **kwargs: Any) -> 'SB3VecEnv':
        """The SB3VecEnv of `gymnasium.make_vec(env_id, num_envs, **kwargs)` (SAME_STEP)."""
        vector_env = gymnasium.make_vec(env_id, num_envs=num_envs,
                                        autoreset_mode=AutoresetMode.SAME_STEP, **kwargs)
        return cls(vector_env)

    def reset(self) -> np.ndarray:
        seeds = self._seeds
        seed = None if all(s is None for s in seeds) else list(seeds)
        observations, infos = self.vector_env.reset(seed=seed)
        self.reset_infos = self._split(infos, np.zeros(self.num_envs, dtype=bool))
        self._reset_seeds()
        self._reset_options()
        return observations

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        observations, rewards, terminated, truncated, infos = self.vector_env.step(self._actions)
        dones = terminated | truncated
        split = self._split(infos, dones)
        for k in np.flatnonzero(dones):
            split[k]['terminal_observation'] = infos['final_obs'][k]
        for k, info in enumerate(split):
            info['TimeLimit.truncated'] = bool(truncated[k] and not terminated[k])
        return observations, rewards.astype(np.float32), dones, split

    def _split(self, infos: dict, dones: np.ndarray) -> list[dict]:
        keys = [key for key in ('t', 'tension', 'payload_error', 'termination') if key in infos]
        return [{key: infos[key][k] for key in keys} for k in range(self.num_envs)]


class SB3AgentVecEnv(_OneVectorEnv):
    """The PettingZoo env's agents over a FormationVectorEnv (SAME_STEP) of B formations, as B n
    environments of SB3's VecEnv, so that one policy, its parameters shared, learns to fly
    every UAV (`multilift_learning.parallel_env`: agent k sees its UAV's slots and the
    payload's, `observations.agent_observation_slots`, commands its UAV's actions, and shares
    the formation's reward). Formation b's agent k is environment b n + k; an agent's episode
    ends with its formation's."""

    def __init__(self, vector_env: FormationVectorEnv):
        self.formations = SB3VecEnv(vector_env)
        self.vector_env = vector_env
        self.n = n = vector_env.batch.n
        self.slots = agent_observation_slots(n)
        observation, action = agent_spaces(vector_env.batch)
        super().__init__(vector_env.num_envs * n, observation, action)

    @classmethod
    def make(cls, env_id: str, num_formations: int, **kwargs: Any) -> 'SB3AgentVecEnv':
        """The agents of `gymnasium.make_vec(env_id, num_formations, **kwargs)` (SAME_STEP)."""
        return cls(SB3VecEnv.make(env_id, num_formations, **kwargs).vector_env)

    def _agents(self, observations: np.ndarray) -> np.ndarray:
        """Formations' observations (B, size) -> the agents' (B n, agent size)."""
        return observations[:, self.slots].reshape(self.num_envs, -1)

    def reset(self) -> np.ndarray:
        self.formations._seeds = self._seeds[::self.n]  # formation b: its agent 0's seed
        observations = self.formations.reset()
        self.reset_infos = [dict(info) for info in self.formations.reset_infos
                            for _ in range(self.n)]
        self._reset_seeds()
        self._reset_options()
        return self._agents(observations)

    def step_async(self, actions: np.ndarray) -> None:
        self.formations.step_async(np.asarray(actions).reshape(self.formations.num_envs, -1))

    def step_wait(self):
        observations, rewards, dones, infos = self.formations.step_wait()
        split = []
        for info in infos:
            for k in range(self.n):
                agent = dict(info)
                if 'terminal_observation' in info:
                    agent['terminal_observation'] = info['terminal_observation'][self.slots[k]]
                split.append(agent)
        return (self._agents(observations), np.repeat(rewards, self.n),
                np.repeat(dones, self.n), split)
