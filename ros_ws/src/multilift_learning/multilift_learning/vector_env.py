"""`FormationVectorEnv`: N formations of a task stepped by one call of the batched engine
(`gymnasium.make_vec('multilift/Hover-v0', num_envs=N)`), with Gymnasium 1.x's autoreset modes:

- NEXT_STEP (the default): the step after an episode's end resets that environment (its
  action ignored, reward 0, neither terminated nor truncated);
- SAME_STEP (`autoreset_mode=AutoresetMode.SAME_STEP`): an environment whose episode ends in a
  step is reset in that step; the step returns its first observation, the last one in
  `info['final_obs']` (with `info['_final_obs']` the mask of those that ended);
- and in any mode `reset(options={'reset_mask': mask})` resets only the environments in mask
  (the others go on untouched; their observations returned as they are).

Every step's info: 't' [s], 'tension' [N], 'payload_error' [m] (the payload's distance from
its target), 'termination' (each environment's reason, '' where it did not terminate).
"""
from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from multilift_learning.batch import REWARD_WEIGHTS, observation_names
from multilift_learning.env import formation_batch, spaces
from multilift_sim.scenario import Scenario


class FormationVectorEnv(VectorEnv):
    """`num_envs` formations of `FormationEnv`'s arguments (one scenario for all, or
    `scenarios`: one per environment, of the same shape) on one engine; `autoreset_mode`
    NEXT_STEP or SAME_STEP (see the module)."""

    metadata = {'render_modes': [], 'autoreset_mode': AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, scenario: str | Scenario = 'twin_lift',
                 task: str = 'hover', overrides: dict[str, Any] | None = None,
                 scenarios: list[str | Scenario] | None = None,
                 autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP, **options):
        if not isinstance(num_envs, int) or num_envs < 1:
            raise ValueError(f'num_envs must be >= 1, got {num_envs}')
        modes = (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP)
        if AutoresetMode(autoreset_mode) not in modes:
            raise ValueError(f'autoreset_mode {autoreset_mode!r}: NEXT_STEP or SAME_STEP')
        self.metadata = dict(self.metadata, autoreset_mode=AutoresetMode(autoreset_mode))
        if scenarios is None:
            scenarios = [scenario] * num_envs
        elif len(scenarios) != num_envs:
            raise ValueError(f'{len(scenarios)} scenarios for num_envs={num_envs}')
        options.pop('render_mode', None)  # make_vec passes it; nothing renders a batch
        self.num_envs = num_envs
        self.batch = formation_batch(list(scenarios), task, overrides, options)
        self.single_observation_space, self.single_action_space = spaces(self.batch)
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_names = observation_names(self.batch.n)
        self.reward_weights = dict(REWARD_WEIGHTS)
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._seeded = False  # the batch's random draws seeded (at the first reset)

    @property
    def autoreset_mode(self) -> AutoresetMode:
        return self.metadata['autoreset_mode']

    def reset(self, *, seed: int | list[int | None] | None = None,
              options: dict | None = None):
        """Every environment (or those of `options['reset_mask']`, (num_envs,) bool) to a new
        episode; `seed` an int (environment k: seed + k) or one per environment."""
        super().reset(seed=seed if isinstance(seed, int) else None)
        mask = np.ones(self.num_envs, dtype=bool)
        if options and 'reset_mask' in options:
            mask = np.asarray(options['reset_mask'])
            if mask.shape != (self.num_envs,) or mask.dtype != bool:
                raise ValueError(f'reset_mask must be ({self.num_envs},) bool, got '
                                 f'{mask.shape} {mask.dtype}')
        if seed is None:
            seeds: list[int | None] = [None] * self.num_envs
        elif isinstance(seed, int):
            seeds = [seed + k for k in range(self.num_envs)]
        else:
            seeds = list(seed)
        seeds = [s if m else None for s, m in zip(seeds, mask)]
        if seed is not None or not self._seeded:
            # a new stream where a seed is given (or at the first reset); the others go on
            self.batch.rngs = [np.random.default_rng(s) if s is not None or not self._seeded
                               else old for s, old in zip(seeds, self.batch.rngs)]
            self._seeded = True
        self.batch.reset(mask)
        self._autoreset[mask] = False
        observation, seen = self.batch.observe()
        return observation, self._infos(seen, [''] * self.num_envs)

    def step(self, actions):
        actions = np.asarray(actions, dtype=float).reshape(self.num_envs, -1)
        restart = self._autoreset.copy()
        speeds = self.batch.step(actions, ~restart)
        if restart.any():
            self.batch.reset(restart)
        observation, seen = self.batch.observe()
        terminated, truncated, reasons = self.batch.ends(seen)
        reward, _terms = self.batch.reward(seen, speeds, terminated)
        reward[restart] = 0.0
        terminated[restart] = False
        truncated[restart] = False
        infos = self._infos(seen, [r if not restart[k] else '' for k, r in enumerate(reasons)])
        ended = terminated | truncated
        if self.autoreset_mode == AutoresetMode.SAME_STEP:
            if ended.any():
                final = np.empty(self.num_envs, dtype=object)
                for k in np.flatnonzero(ended):
                    final[k] = observation[k].copy()
                self.batch.reset(ended)
                observation, _ = self.batch.observe()
                infos['final_obs'], infos['_final_obs'] = final, ended.copy()
        else:
            self._autoreset = ended
        return observation, reward, terminated, truncated, infos

    def expert_actions(self) -> np.ndarray:
        """The seed's controllers' answers (num_envs, n * rotors): the baseline policy."""
        return self.batch.expert_actions()

    def _infos(self, seen: dict, reasons: list[str]) -> dict:
        return {'t': self.batch.engine.t.copy(), 'tension': self.batch.tension.copy(),
                'payload_error': np.linalg.norm(seen['position_error'], axis=1),
                'termination': np.array(reasons, dtype=object)}
