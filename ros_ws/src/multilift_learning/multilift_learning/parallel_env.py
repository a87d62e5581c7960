"""`FormationParallelEnv`: a formation as a PettingZoo ParallelEnv, one agent per UAV
(`uav1` the leader, `uav2`.. the followers), decentralised: each agent sees its own UAV's
slots of the observation (`multilift_learning.batch`: position and velocity errors, attitude,
body rates, its cable's direction and tension) and the payload's errors, and commands its own
rotors (normalised speeds in [-1, 1]). The team shares one reward (the formation's).

    from multilift_learning.parallel_env import parallel_env
    env = parallel_env(scenario='multi_lift', task='mission')
"""
from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from pettingzoo import ParallelEnv

from multilift_learning.batch import observation_names
from multilift_learning.env import formation_batch, spaces
from multilift_learning.observations import agent_observation_slots
from multilift_sim.scenario import Scenario


class FormationParallelEnv(ParallelEnv):
    """`FormationEnv`'s formation with an agent per UAV (same arguments; action_mode
    rotor_speeds: each agent its rotors, thrust_body_rates: its thrust and body rates)."""

    metadata = {'name': 'multilift_formation_v0', 'render_modes': []}

    def __init__(self, scenario: str | Scenario = 'twin_lift', task: str = 'hover',
                 overrides: dict[str, Any] | None = None, **options):
        self.batch = formation_batch([scenario], task, overrides, options)
        n = self.batch.n
        self.possible_agents = [f'uav{i}' for i in range(1, n + 1)]
        self.agents: list[str] = []
        names = observation_names(n)
        self.agent_slots = agent_observation_slots(n)
        self.observation_names = {agent: [names[s] for s in self.agent_slots[k]]
                                  for k, agent in enumerate(self.possible_agents)}
        self._observation_space, self._action_space = agent_spaces(self.batch)
        self.action_per_agent = self._action_space.shape[0]
        self._seeded = False  # the batch's random draws seeded (at the first reset)

    def observation_space(self, agent: str) -> gymnasium.spaces.Box:
        return self._observation_space

    def action_space(self, agent: str) -> gymnasium.spaces.Box:
        return self._action_space

    def _split(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        return {agent: observation[self.agent_slots[k]]
                for k, agent in enumerate(self.possible_agents)}

    def reset(self, seed: int | None = None, options: dict | None = None):
        if seed is not None or not self._seeded:
            self.batch.seed([seed])
            self._seeded = True
        self.batch.reset()
        self.agents = list(self.possible_agents)
        observation, _ = self.batch.observe()
        return self._split(observation[0]), {agent: {} for agent in self.agents}

    def step(self, actions: dict[str, np.ndarray]):
        flat = np.concatenate([np.asarray(actions[agent], dtype=float)
                               for agent in self.possible_agents])[None]
        speeds = self.batch.step(flat)
        observation, seen = self.batch.observe()
        terminated, truncated, reasons = self.batch.ends(seen)
        reward, terms = self.batch.reward(seen, speeds, terminated)
        agents = self.agents
        observations = self._split(observation[0])
        error = float(np.linalg.norm(seen['position_error'][0]))
        infos = {agent: {'reward_terms': {k: float(v[0]) for k, v in terms.items()},
                         'payload_error': error, 'termination': reasons[0]}
                 for agent in agents}
        result = (observations, {agent: float(reward[0]) for agent in agents},
                  {agent: bool(terminated[0]) for agent in agents},
                  {agent: bool(truncated[0]) for agent in agents}, infos)
        if terminated[0] or truncated[0]:
            self.agents = []
        return result

    def expert_actions(self) -> dict[str, np.ndarray]:
        """The seed's controllers' answers, per agent (the baseline)."""
        flat = self.batch.expert_actions()[0]
        size = self.action_per_agent
        return {agent: flat[k * size:(k + 1) * size]
                for k, agent in enumerate(self.possible_agents)}


def agent_spaces(batch) -> tuple[gymnasium.spaces.Box, gymnasium.spaces.Box]:
    """One agent's observation and action spaces in a formation of `batch`'s shape (its UAV's
    slots and the payload's; its UAV's actions)."""
    whole_observation, _ = spaces(batch)
    slots = agent_observation_slots(batch.n)[0]
    observation = gymnasium.spaces.Box(whole_observation.low[slots],
                                       whole_observation.high[slots], (len(slots),), np.float32)
    return observation, gymnasium.spaces.Box(-1.0, 1.0, (batch.action_size // batch.n,),
                                             np.float64)


def parallel_env(**kwargs) -> FormationParallelEnv:
    """PettingZoo's usual constructor name."""
    return FormationParallelEnv(**kwargs)
