"""Winch rates as optional actions of the learning environments (issue 32 item 6:
`winch_actions=True`): each UAV's action gains its reel rate, which pays out within the
winch's limits, the baseline reels as the scenario does, and the cable models a task flies."""
import gymnasium
import numpy as np
import pytest

import multilift_learning  # noqa: F401 - registers the environments
from multilift_learning.parallel_env import parallel_env
from multilift_learning.tasks import learning_cable_model
from multilift_sim import scenario as scenario_io
from multilift_sim.physics.layout import REEL_LENGTH


def _env(**options):
    return gymnasium.make('multilift/Hover-v0', scenario='winch_lower', duration=5.0,
                          **options).unwrapped


def test_a_reel_action_of_one_pays_out_at_the_winch_s_rate_after_its_ramp():
    env = _env(winch_actions=True)
    env.reset(seed=0)
    batch = env.batch
    size = batch.uav_action_size
    assert size == batch.rotors + 1 and env.action_space.shape == (2 * size,)
    start = batch.engine.memory.reel[0, :, REEL_LENGTH].copy()
    ticks = 300
    for _ in range(ticks):
        action = env.expert_action().copy()
        action[size - 1] = 1.0      # uav1 pays out at its rate_limit, 0.5 m/s
        action[2 * size - 1] = -0.5  # uav2 reels in at 0.25 m/s
        env.step(action)
    t = ticks * 0.01
    # a trapezoid of the acceleration limit 0.5 m/s^2: rate / acceleration seconds to speed
    paid = [rate * t - rate * abs(rate) / (2 * 0.5) for rate in (0.5, -0.25)]
    lengths = batch.engine.memory.reel[0, :, REEL_LENGTH]
    assert lengths - start == pytest.approx(paid, abs=0.01)


def test_the_baseline_reels_as_the_scenario_commands_and_flies_as_without_the_option():
    flown = []
    for options in ({}, {'winch_actions': True}):
        env = _env(**options)
        env.reset(seed=3)
        for _ in range(150):
            action = env.expert_action()
            if options:
                assert np.all(action.reshape(2, -1)[:, -1] == 0.0)  # nothing scheduled yet
            env.step(action)
        flown.append(env.batch.engine.memory.state[0].copy())
    assert np.array_equal(flown[0], flown[1])


def test_each_agent_of_the_parallel_env_reels_its_own_winch():
    env = parallel_env(scenario='winch_lower', duration=2.0, winch_actions=True)
    env.reset(seed=1)
    assert env.action_space('uav1').shape == (env.batch.rotors + 1,)
    actions = env.expert_actions()
    actions['uav2'] = actions['uav2'].copy()
    actions['uav2'][-1] = 1.0
    for _ in range(50):
        env.step(actions)
    lengths = env.batch.engine.memory.reel[0, :, REEL_LENGTH]
    assert lengths[1] > lengths[0] == pytest.approx(10.26)


def test_winch_actions_need_a_winch_on_every_uav_and_a_boolean():
    with pytest.raises(ValueError, match="winch_actions needs a winch on every UAV.*'twin_lift'"):
        gymnasium.make('multilift/Hover-v0', winch_actions=True)
    with pytest.raises(ValueError, match='winch_actions must be True or False'):
        gymnasium.make('multilift/Hover-v0', winch_actions='yes')


def test_a_task_flies_rigid_cables_slack_unless_they_are_reeled():
    assert learning_cable_model(scenario_io.load('twin_lift')) == 'slack'
    assert learning_cable_model(scenario_io.load('winch_lower')) == 'rigid'
    assert learning_cable_model(scenario_io.load('twin_lift_elastic')) == 'elastic'
