"""`RecordEpisodes`: every episode of a `FormationEnv` written to a bag of its own, the bag a run
writes (`multilift_tools.headless_bag.EngineBag`: the same topics, messages and simulated-time
stamps, so Foxglove opens it and `multilift plot` draws it), with the policy's rotor speeds as
the UAVs' /uav{i}/rotor_cmd. A policy has no reference, set-points or formation errors: those
topics are left out. Beside each bag's metadata.yaml, summary.json: the run's figures as a
run writes them (`Engine.summary`: `sim.scenario` the scenario's name, which `multilift plot`
reads) and `task`: its name, options, the payload's target [m] (world) at the episode's first
and last tick, the episode's steps, return, termination reason ('' if none) and the payload's
mean distance from its target [m].

    env = RecordEpisodes(gymnasium.make('multilift/Mission-v0'), 'episodes')
    # episodes/episode_0001, episode_0002, ... (rosbag2 directories, MCAP)
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import gymnasium
import numpy as np

from multilift_sim.bag import BagWriter
from multilift_tools.headless_bag import EngineBag


class RecordEpisodes(gymnasium.Wrapper):
    """Writes each episode of `env` (a FormationEnv, maybe wrapped) to FOLDER/episode_NNNN when
    it ends (terminated, truncated, or a reset or close before that). `bags` lists them."""

    def __init__(self, env: gymnasium.Env, folder: str | Path):
        super().__init__(env)
        self.folder = Path(folder)
        self.bags: list[Path] = []
        self._record = None
        self._count = 0
        self._episode: dict = {}

    def reset(self, **kwargs):
        self._finish()
        observation, info = self.env.reset(**kwargs)
        engine = self.env.unwrapped.batch.engine
        self._record = engine.new_record(int(engine.arrays.tick_count[0]))
        self._count = 0
        self._episode = {'target_start': self._target(), 'return': 0.0, 'termination': '',
                         'payload_error_sum': 0.0}
        return observation, info

    def step(self, action):
        batch = self.env.unwrapped.batch
        memory, record, k = batch.engine.memory, self._record, self._count
        if record is None:
            raise gymnasium.error.ResetNeeded('RecordEpisodes: reset before step')
        # the tick's start, as the engine's own record keeps it (engine.tick.run_ticks)
        record.states[k, 0] = memory.state[0]
        record.g[k, 0], record.g_dot[k, 0] = memory.g[0], memory.g_dot[0]
        record.taut[k, 0], record.gust[k, 0] = memory.taut[0], memory.gust[0]
        speeds, saturated = batch.speeds(np.asarray(action, dtype=float)[None])
        result = self.env.step(action)
        record.speeds[k, 0] = speeds[0]
        record.saturated[k, 0] = saturated[0]
        record.tension[k, 0] = batch.tension[0]
        self._count += 1
        info = result[4]
        self._episode['return'] += float(result[1])
        self._episode['payload_error_sum'] += info['payload_error']
        self._episode['termination'] = info.get('termination', '')
        if result[2] or result[3]:
            self._finish()
        return result

    def close(self):
        self._finish()
        return super().close()

    def _target(self) -> list[float]:
        """The payload's target now [m], world."""
        batch = self.env.unwrapped.batch
        return batch.targets.at(batch.engine.t)[0][0].tolist()

    def _finish(self) -> None:
        """Write the episode flown so far (if any) to its bag."""
        if self._record is None or self._count == 0:
            return
        batch = self.env.unwrapped.batch
        path = self.folder / f'episode_{len(self.bags) + 1:04d}'
        writer = BagWriter(path)
        try:
            bag = EngineBag(batch.scenarios[0], batch.engine, writer, controllers=False)
            bag.ticks(0, self._record, self._count)
            if batch.engine.finished[0]:
                bag.last()
        finally:
            writer.close()
        episode = self._episode
        summary = batch.engine.summary(0)
        summary['task'] = {
            'name': batch.targets.task.name,
            'options': dataclasses.asdict(batch.options),
            'target_start': episode['target_start'], 'target_end': self._target(),
            'steps': self._count, 'return': episode['return'],
            'termination': episode['termination'],
            'payload_error_mean': episode['payload_error_sum'] / self._count}
        (path / 'summary.json').write_text(json.dumps(summary, indent=1, sort_keys=True,
                                                      default=float))
        self.bags.append(path)
        self._record, self._count = None, 0
