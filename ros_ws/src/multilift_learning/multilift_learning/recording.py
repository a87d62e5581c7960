"""`RecordEpisodes`: every episode of a `FormationEnv` written to a bag of its own, the bag a run
writes (`multilift_tools.headless_bag.EngineBag`: the same topics, messages and simulated-time
stamps, so Foxglove opens it and `multilift plot` draws it), with the policy's rotor speeds as
the UAVs' /uav{i}/rotor_cmd. A policy has no reference, set-points or formation errors: those
topics are left out.

    env = RecordEpisodes(gymnasium.make('multilift/Mission-v0'), 'episodes')
    # episodes/episode_0001, episode_0002, ... (rosbag2 directories, MCAP)
"""
from __future__ import annotations

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

    def reset(self, **kwargs):
        self._finish()
        observation, info = self.env.reset(**kwargs)
        engine = self.env.unwrapped.batch.engine
        self._record = engine.new_record(int(engine.arrays.tick_count[0]))
        self._count = 0
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
        result = self.env.step(action)
        speeds = batch.speeds(np.asarray(action, dtype=float)[None])
        record.speeds[k, 0] = speeds[0]
        record.saturated[k, 0] = batch.at_limits(speeds)[0]
        record.tension[k, 0] = batch.tension[0]
        self._count += 1
        if result[2] or result[3]:
            self._finish()
        return result

    def close(self):
        self._finish()
        return super().close()

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
        self.bags.append(path)
        self._record, self._count = None, 0
