"""`FormationEnv`: one formation of a task as a Gymnasium environment (`multilift/Hover-v0`,
`multilift/Mission-v0`); the spaces, rewards and ends are `multilift_learning.batch`'s."""
from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np

from multilift_learning.batch import REWARD_WEIGHTS, FormationBatch, observation_names
from multilift_learning.observations import OBSERVATION_CLIP
from multilift_learning.options import TaskOptions
from multilift_learning.tasks import scenario_of
from multilift_sim.registry import one_of
from multilift_sim.scenario import Scenario


def spaces(batch: FormationBatch) -> tuple[gymnasium.spaces.Box, gymnasium.spaces.Box]:
    """(observation space, action space) of one formation of `batch`: observations float32
    (within +-OBSERVATION_CLIP when normalised), actions float64 (the baseline's actions keep
    every bit of the controllers' rotor speeds)."""
    size = len(observation_names(batch.n))
    bound = OBSERVATION_CLIP if batch.options.normalise else np.inf
    observation = gymnasium.spaces.Box(-bound, bound, (size,), np.float32)
    action = gymnasium.spaces.Box(-1.0, 1.0, (batch.action_size,), np.float64)
    return observation, action


def formation_batch(scenarios: list[str | Scenario], task: str,
                    overrides: dict[str, Any] | None, options: dict[str, Any]) -> FormationBatch:
    """The FormationBatch of an environment's arguments: `options` the keyword arguments of
    TaskOptions (a bad one a ValueError naming it)."""
    try:
        task_options = TaskOptions(**options)
    except TypeError as error:  # an unknown keyword
        raise ValueError(f'{error}: the options are those of '
                         'multilift_learning.options.TaskOptions') from None
    return FormationBatch([scenario_of(s, overrides, task_options.duration) for s in scenarios],
                          task, task_options)


class FormationEnv(gymnasium.Env):
    """A formation carrying its payload, one control tick a step (the scenario's control
    period). `scenario`: a name, a path or a Scenario; `overrides`: {'payload.mass': 1.2, ...}
    (the keys of `multilift sweep --set`); `duration` [s]: the episode's length (the
    scenario's by default); `task`: 'hover' or 'mission' (multilift_learning.tasks);
    the rest (`action_mode`, `normalise`, `duration`, `target_radius`, `start`,
    `ground_height`, `bound`, `tilt_limit_deg`, `body_rate_limit`, `start_speed`):
    multilift_learning.options.TaskOptions.

    `expert_action()` is the seed's controller's answer at the current state: the baseline.
    `render_mode='rgb_array'`: `render()` draws the formation in 3-D as `multilift animate`
    does (UAVs, cables coloured by tension, payload, their paths so far), (H, W, 3) uint8."""

    metadata = {'render_modes': ['rgb_array'], 'render_fps': 10}

    def __init__(self, scenario: str | Scenario = 'twin_lift', task: str = 'hover',
                 overrides: dict[str, Any] | None = None, render_mode: str | None = None,
                 **options):
        one_of('render_mode', render_mode, (None, *self.metadata['render_modes']))
        self.render_mode = render_mode
        self._history: list[tuple[float, np.ndarray, np.ndarray, np.ndarray]] = []
        self.batch = formation_batch([scenario], task, overrides, options)
        self.observation_space, self.action_space = spaces(self.batch)
        self.observation_names = observation_names(self.batch.n)
        self.reward_weights = dict(REWARD_WEIGHTS)

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self.batch.rngs = [self.np_random]
        self.batch.reset()
        observation, seen = self.batch.observe()
        self._history = []
        self._remember()
        return observation[0], self._info(seen)

    def step(self, action):
        speeds = self.batch.step(np.asarray(action, dtype=float)[None])
        observation, seen = self.batch.observe()
        terminated, truncated, reasons = self.batch.ends(seen)
        reward, terms = self.batch.reward(seen, speeds, terminated)
        self._remember()
        info = self._info(seen)
        info['reward_terms'] = {name: float(value[0]) for name, value in terms.items()}
        info['termination'] = reasons[0]
        return observation[0], float(reward[0]), bool(terminated[0]), bool(truncated[0]), info

    def expert_action(self) -> np.ndarray:
        """The seed's controllers' answer to the current state, as an action (the baseline
        policy); the same until the next step."""
        return self.batch.expert_actions()[0]

    def _remember(self) -> None:
        if self.render_mode is not None:
            engine = self.batch.engine
            self._history.append((float(engine.t[0]), engine.positions[0].copy(),
                                  engine.payload_positions[0].copy(), self.batch.tension[0].copy()))

    def render(self) -> np.ndarray | None:
        """The formation now, with its paths since the reset: (H, W, 3) uint8 RGB."""
        if self.render_mode is None:
            return None
        from matplotlib import pyplot as plt

        from multilift_tools.animation import AnimationData, FormationAnimator
        t, uavs, payload, tension = zip(*self._history)
        data = AnimationData(np.array(t), np.stack(uavs, axis=1), np.array(payload),
                             np.array(tension), np.arange(len(t)))
        animator = FormationAnimator(data, self.batch.scenarios[0].name)
        try:
            return animator.render(len(t) - 1)[:, :, :3].copy()
        finally:
            plt.close(animator.fig)

    def _info(self, seen: dict) -> dict:
        """t [s], the cable tensions [N], Algorithm 1's stop reason (None) and the payload's
        distance from its target `payload_error` [m]."""
        engine = self.batch.engine
        return {'t': float(engine.t[0]), 'tension': self.batch.tension[0].copy(),
                'stop_reason': engine.stop_reason(0),
                'payload_error': float(np.linalg.norm(seen['position_error'][0]))}
