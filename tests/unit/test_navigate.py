"""`multilift/Navigate-v0` (issue 34 item 7): the payload's target is the goal where the
forest's mission leaves it, held from the start; the scenario's own controllers (the expert)
bring it there past the trees without contact, and a tree moved onto the path ends the episode
with the contact named."""
from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import multilift_learning  # noqa: F401 - registers the environments


def _fly_expert(env) -> tuple[dict, bool, bool, int]:
    env.reset(seed=0)
    steps = 0
    while True:
        _, _, terminated, truncated, info = env.step(env.unwrapped.expert_action())
        steps += 1
        if terminated or truncated:
            return info, terminated, truncated, steps


def test_the_goal_is_the_mission_s_end_and_the_expert_reaches_it_past_the_trees():
    env = gymnasium.make('multilift/Navigate-v0')
    _, info = env.reset(seed=0)
    assert info['payload_error'] == pytest.approx(6.4, abs=0.1)   # the goal 6.4 m ahead
    batch = env.unwrapped.batch
    target, velocity = batch.targets.at(np.zeros(1))
    assert np.all(velocity == 0.0)
    np.testing.assert_allclose(target, batch.targets.at(np.full(1, 10.0))[0])   # held
    info, terminated, truncated, _ = _fly_expert(env)
    assert truncated and not terminated and info['termination'] == ''
    assert info['payload_error'] < 0.05


def test_a_tree_on_the_path_ends_the_episode_naming_the_contact():
    env = gymnasium.make('multilift/Navigate-v0',
                         overrides={'world.obstacles[0].center': [1.3, 0.3, 1.5]})
    info, terminated, truncated, steps = _fly_expert(env)
    assert terminated and not truncated
    assert "contact: uav1 touched obstacle 'tree1'" in info['termination']
    assert steps < 13500
