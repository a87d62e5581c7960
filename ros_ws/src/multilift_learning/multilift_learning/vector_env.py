"""`FormationVectorEnv`: N formations of a task stepped by one call of the batched engine
(`gymnasium.make_vec('multilift/Hover-v0', num_envs=N)`), autoreset as Gymnasium's
NEXT_STEP mode defines it: the step after an episode's end resets that environment (its
action ignored, reward 0, neither terminated nor truncated)."""
from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from multilift_learning.batch import REWARD_WEIGHTS, FormationBatch, observation_names
from multilift_learning.env import spaces
from multilift_learning.tasks import scenario_of
from multilift_sim.scenario import Scenario


class FormationVectorEnv(VectorEnv):
    """`num_envs` formations of `FormationEnv`'s arguments (one scenario for all, or
    `scenarios`: one per environment, of the same shape) on one engine."""

    metadata = {'render_modes': [], 'autoreset_mode': AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, scenario: str | Scenario = 'twin_lift',
                 task: str = 'hover', overrides: dict[str, Any] | None = None,
                 duration: float | None = None, target_radius: float = 0.5,
                 scenarios: list[Scenario] | None = None, **_ignored):
        if num_envs < 1:
            raise ValueError(f'num_envs must be >= 1, got {num_envs}')
        if scenarios is None:
            scenarios = [scenario_of(scenario, overrides, duration)] * num_envs
        elif len(scenarios) != num_envs:
            raise ValueError(f'{len(scenarios)} scenarios for num_envs={num_envs}')
        self.num_envs = num_envs
        self.batch = FormationBatch(list(scenarios), task, target_radius)
        self.single_observation_space, self.single_action_space = spaces(self.batch)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_names = observation_names(self.batch.n)
        self.reward_weights = dict(REWARD_WEIGHTS)
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._seeded = False  # the batch's random draws seeded (at the first reset)

    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict | None = None):
        super().reset(seed=seed)
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, int):
            seeds = [seed + k for k in range(self.num_envs)]
        else:
            seeds = list(seed)
        if seed is not None or not self._seeded:
            self.batch.seed(seeds)
            self._seeded = True
        self.batch.reset()
        self._autoreset[:] = False
        observation, _ = self.batch.observe()
        return observation, self._infos()

    def step(self, actions):
        actions = np.asarray(actions, dtype=float).reshape(self.num_envs, -1)
        restart = self._autoreset.copy()
        self.batch.step(actions, ~restart)
        if restart.any():
            self.batch.reset(restart)
        observation, seen = self.batch.observe()
        reward, _terms = self.batch.reward(seen, actions)
        terminated, truncated = self.batch.ends(seen)
        reward[restart] = 0.0
        terminated[restart] = False
        truncated[restart] = False
        self._autoreset = terminated | truncated
        return observation, reward, terminated, truncated, self._infos()

    def expert_actions(self) -> np.ndarray:
        """The seed's controllers' answers (num_envs, n * rotors): the baseline policy."""
        return self.batch.expert_actions()

    def _infos(self) -> dict:
        return {'t': self.batch.engine.t.copy(), 'tension': self.batch.tension.copy()}
