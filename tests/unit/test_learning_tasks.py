"""What a learner gets from the learning environments (issue 36): rewards in [0, 1] with nothing
gained by ending early, terminations with their reason, actions centred on hover in both action
modes (the attitude-rate loop compiled and uncompiled to the bit), float32 observations and
their normalisation, the start options, slack cables, single environments reset and
SAME_STEP autoreset, the numpy policy files, and bad options named."""
from __future__ import annotations

import json

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode

import multilift_learning  # noqa: F401 - registers the environments
from multilift_learning import policies
from multilift_learning.batch import TERMINATIONS
from multilift_learning.laws import body_rates
from multilift_learning.observations import OBSERVATION_CLIP, observation_scales
from multilift_learning.policies import MlpPolicy
from multilift_learning.recording import RecordEpisodes
from multilift_sim import kernels


def _fly(env, policy, steps: int):
    """(rewards, last info, terminated, truncated) of up to `steps` steps of `policy(env)`."""
    rewards, info, terminated, truncated = [], {}, False, False
    for _ in range(steps):
        observation, reward, terminated, truncated, info = env.step(policy(env))
        assert observation.dtype == np.float32 and np.isfinite(observation).all()
        assert info['payload_error'] == pytest.approx(np.linalg.norm(
            env.unwrapped.batch.observe()[1]['position_error'][0]))
        rewards.append(reward)
        if terminated or truncated:
            break
    return np.array(rewards), info, terminated, truncated


@pytest.mark.parametrize('mode', ['rotor_speeds', 'thrust_body_rates'])
def test_both_action_modes_pass_gymnasium_s_checker_and_action_0_hovers(mode):
    env = gymnasium.make('multilift/Hover-v0', duration=1.0, action_mode=mode, target_radius=0)
    check_env(env.unwrapped, skip_render_check=True)
    env.reset(seed=0)
    batch = env.unwrapped.batch
    speeds, _ = batch.speeds(np.zeros((1, batch.action_size)))
    if mode == 'rotor_speeds':
        assert np.array_equal(speeds, np.broadcast_to(batch.speed_hover, speeds.shape))
    rewards, info, terminated, truncated = _fly(env, lambda e: np.zeros(e.action_space.shape),
                                                100)
    # 1 s of zero actions: the payload hangs where it started (its rest place, the target)
    assert truncated and not terminated and info['payload_error'] < 0.1
    assert (rewards > 0.9).all() and (rewards <= 1.0).all()


def test_a_fall_ends_on_the_ground_and_never_pays_more_than_flying_on():
    env = gymnasium.make('multilift/Hover-v0', duration=5.0, target_radius=0.0)
    env.reset(seed=0)
    fall, info, terminated, _ = _fly(env, lambda e: -np.ones(e.action_space.shape), 500)
    assert terminated and info['termination'].startswith('ground contact')
    assert fall[-1] == 0.0 and (fall >= 0).all() and (fall <= 1).all()
    env.reset(seed=0)
    hover, *_ = _fly(env, lambda e: np.zeros(e.action_space.shape), 500)
    assert len(hover) == 500 and hover.sum() > fall.sum() + 0.9 * (500 - len(fall))


def test_a_tilt_beyond_the_limit_and_leaving_the_bound_terminate_with_their_reason():
    env = gymnasium.make('multilift/Hover-v0', duration=5.0, action_mode='thrust_body_rates',
                         tilt_limit_deg=30.0)
    env.reset(seed=0)
    roll = np.zeros(env.action_space.shape)
    roll[1] = 1.0  # uav1 asks to roll at body_rate_limit (1 rad/s)
    rewards, info, terminated, _ = _fly(env, lambda e: roll, 200)
    euler = env.unwrapped.batch.engine.measured()[0, 0, 6:8]
    assert terminated and info['termination'].startswith('tilt limit')
    assert np.cos(euler[0]) * np.cos(euler[1]) < np.cos(np.radians(30.0))
    # 30 deg (0.52 rad) at 1 rad/s at most, slower: the torque left at hover thrust
    assert 0.53 < len(rewards) * 0.01 < 3.0
    env = gymnasium.make('multilift/Hover-v0', duration=5.0, target_radius=0.5, bound=0.01)
    env.reset(seed=3)
    _, info, terminated, _ = _fly(env, lambda e: np.zeros(e.action_space.shape), 5)
    assert terminated and info['termination'].startswith('bound')
    assert {r.split(':')[0].split(' ')[0] for r in TERMINATIONS} == {
        'physical', 'tilt', 'ground', 'bound'}


def test_the_rate_loop_is_compiled_and_uncompiled_to_the_bit_and_holds_its_rate():
    env = gymnasium.make('multilift/Hover-v0', duration=1.0, action_mode='thrust_body_rates')
    env.reset(seed=1)
    batch = env.unwrapped.batch
    rng = np.random.default_rng(5)
    states = batch.engine.measured().copy()
    states[:, :, 9:12] = rng.normal(0, 0.5, (1, 2, 3))
    rates, thrust = rng.normal(0, 1.0, (1, 2, 3)), rng.uniform(10, 40, (1, 2))
    out = []
    for law in (body_rates.body_rate_commands, kernels.uncompiled(body_rates.body_rate_commands)):
        speeds, saturated = np.empty((1, 2, 4)), np.empty((1, 2, 4), dtype=bool)
        law(batch.engine.arrays.cascade, batch.engine.memory.mixers, states, rates, thrust,
            speeds, saturated)
        out.append((speeds, saturated))
    assert np.array_equal(out[0][0], out[1][0]) and np.array_equal(out[0][1], out[1][1])
    pitch = np.zeros(env.action_space.shape)
    pitch[[2, 6]] = 0.1  # both UAVs pitch at 0.1 rad/s
    for _ in range(40):
        env.step(pitch)
    body_rate = batch.engine.measured()[0, :, 10]
    assert body_rate == pytest.approx([0.1, 0.1], abs=0.01)


def test_observations_are_float32_with_their_scales_when_normalised():
    raw = gymnasium.make('multilift/Hover-v0', duration=1.0, start='scenario')
    scaled = gymnasium.make('multilift/Hover-v0', duration=1.0, start='scenario', normalise=True)
    o_raw, _ = raw.reset(seed=2)
    o_scaled, _ = scaled.reset(seed=2)
    assert o_raw.dtype == o_scaled.dtype == np.float32
    expected = np.clip(o_raw / observation_scales(2), -OBSERVATION_CLIP, OBSERVATION_CLIP)
    assert np.allclose(o_scaled, expected, rtol=1e-6)
    assert scaled.observation_space.high.max() == OBSERVATION_CLIP
    assert np.isinf(raw.observation_space.high).all()


def test_the_start_options_and_slack_cables():
    rest = gymnasium.make('multilift/Hover-v0', duration=2.0, target_radius=0.0).unwrapped
    released = gymnasium.make('multilift/Hover-v0', duration=2.0, target_radius=0.0,
                              start='scenario').unwrapped
    moving = gymnasium.make('multilift/Hover-v0', duration=2.0, start_speed=0.5).unwrapped
    assert rest.reset(seed=0)[1]['payload_error'] < 0.002  # the rest place: reach l + eps_g
    assert released.reset(seed=0)[1]['payload_error'] == pytest.approx(2.66, abs=0.05)
    moving.reset(seed=4)
    layout, state = moving.batch.layout, moving.batch.engine.state[0]
    velocities = np.vstack([layout.uav_velocities(state), layout.payload_velocity(state)])
    assert np.ptp(velocities, axis=0).max() == 0 and 0 < np.linalg.norm(velocities[0]) <= 0.5
    assert all(s.cable_model == 'slack' for s in rest.batch.scenarios)
    # a falling formation: the cables go slack and pull nothing; none ever pushes
    released.reset(seed=0)
    tensions = []
    for _ in range(150):
        released.step(-0.3 * np.ones(8))
        tensions.append(released.batch.tension[0].copy())
    assert min(map(min, tensions)) >= 0.0 and (np.array(tensions) == 0).any()


def test_single_environments_reset_and_same_step_autoreset():
    envs = gymnasium.make_vec('multilift/Hover-v0', num_envs=3, duration=0.05,
                              autoreset_mode=AutoresetMode.SAME_STEP)
    envs.reset(seed=1)
    for _ in range(2):
        envs.step(np.zeros((3, 8)))
    observations, infos = envs.reset(options={'reset_mask': np.array([False, True, False])})
    assert infos['t'].tolist() == [0.02, 0.0, 0.02]
    for _ in range(3):
        observations, _, _, truncated, infos = envs.step(np.zeros((3, 8)))
    assert truncated.tolist() == [True, False, True] and infos['_final_obs'].tolist() == [
        True, False, True]
    assert infos['t'][0] == 0.05 and envs.unwrapped.batch.engine.t[0] == 0.0  # reset at once
    assert not np.array_equal(infos['final_obs'][0], observations[0])
    with pytest.raises(ValueError, match='reset_mask'):
        envs.reset(options={'reset_mask': np.array([1, 0, 1])})


def test_bad_options_are_named():
    cases = [({'action_mode': 'joystick'}, 'action_mode'), ({'duration': -1.0}, 'duration'),
             ({'tilt_limit_deg': 95.0}, 'tilt_limit_deg'), ({'start': 'moon'}, 'start'),
             ({'bound': 0.0}, 'bound'), ({'episode_len': 3}, 'TaskOptions'),
             ({'normalise': 'yes'}, 'normalise')]
    for options, name in cases:
        with pytest.raises(ValueError, match=name):
            gymnasium.make('multilift/Hover-v0', **options)
    env = gymnasium.make('multilift/Hover-v0', action_mode='thrust_body_rates').unwrapped
    with pytest.raises(ValueError, match='action_mode'):
        env.expert_action()


def test_a_policy_file_round_trips_and_a_wrong_shape_is_named(tmp_path):
    rng = np.random.default_rng(0)
    weights = (rng.normal(size=(38, 16)), rng.normal(size=(16, 8)))
    biases = (rng.normal(size=16), rng.normal(size=8))
    policy = MlpPolicy(weights, biases, 'tanh', rng.normal(size=38), rng.uniform(1, 2, 38),
                       5.0, {'id': 'multilift/Hover-v0'})
    loaded = policies.load(policies.save(tmp_path / 'p.npz', policy))
    observation = rng.normal(size=(4, 38)) * 10
    x = np.clip((observation - policy.observation_mean) / policy.observation_std, -5, 5)
    expected = np.clip(np.tanh(x @ weights[0] + biases[0]) @ weights[1] + biases[1], -1, 1)
    assert np.array_equal(loaded(observation), expected) and loaded.environment['id']
    assert loaded(observation[0]).shape == (8,)
    bad = dict(np.load(tmp_path / 'p.npz'))
    bad['biases_1'] = np.zeros(7)
    np.savez(tmp_path / 'bad.npz', **bad)
    with pytest.raises(ValueError, match=r'bad.npz: biases_1 has shape \(7,\)'):
        policies.load(tmp_path / 'bad.npz')
    with pytest.raises(ValueError, match='takes'):
        loaded(np.zeros(37))


def test_recorded_episodes_carry_the_scenario_and_the_target(tmp_path):
    env = RecordEpisodes(gymnasium.make('multilift/Hover-v0', duration=0.3), tmp_path)
    env.reset(seed=6)
    done = False
    while not done:
        *_, terminated, truncated, _ = env.step(env.unwrapped.expert_action())
        done = terminated or truncated
    summary = json.loads((env.bags[0] / 'summary.json').read_text())
    target = env.unwrapped.batch.targets.hold[0]
    assert summary['sim']['scenario'] == 'twin_lift'
    assert summary['task']['name'] == 'hover' and summary['task']['steps'] == 30
    assert summary['task']['target_start'] == pytest.approx(target.tolist())
    assert summary['task']['termination'] == '' and summary['task']['payload_error_mean'] < 0.5


def test_the_sb3_adapter_steps_as_sb3_s_own_dummy_vec_env():
    """SB3VecEnv (the batched env through its public calls) against SB3's DummyVecEnv of
    FormationEnvs: the same observations, rewards, dones and end-of-episode infos, step for
    step, across terminations (env 0 rolls past the tilt limit) and truncations."""
    pytest.importorskip('stable_baselines3')
    from stable_baselines3.common.vec_env import DummyVecEnv

    from multilift_learning.sb3 import SB3VecEnv
    kwargs = {'duration': 1.0, 'action_mode': 'thrust_body_rates', 'tilt_limit_deg': 5.0}
    ours = SB3VecEnv.make('multilift/Hover-v0', 3, **kwargs)
    theirs = DummyVecEnv([lambda: gymnasium.make('multilift/Hover-v0', **kwargs)] * 3)
    ours.seed(5)
    theirs.seed(5)
    assert np.array_equal(ours.reset(), theirs.reset())
    rng = np.random.default_rng(0)
    ends = {'terminated': 0, 'truncated': 0}
    for _ in range(200):
        actions = rng.uniform(-0.3, 0.3, (3, 8))
        actions[0, 1] = 1.0
        a, reward_a, done_a, info_a = ours.step(actions)
        b, reward_b, done_b, info_b = theirs.step(actions)
        assert np.array_equal(a, b) and np.array_equal(reward_a, reward_b)
        assert np.array_equal(done_a, done_b)
        for x, y in zip(info_a, info_b):
            assert x['TimeLimit.truncated'] == y['TimeLimit.truncated']
            assert x['termination'] == y['termination']
            assert ('terminal_observation' in x) == ('terminal_observation' in y)
            if 'terminal_observation' in y:
                assert np.array_equal(x['terminal_observation'], y['terminal_observation'])
                ends['truncated' if y['TimeLimit.truncated'] else 'terminated'] += 1
    assert ends['terminated'] >= 2 and ends['truncated'] >= 4


def test_the_sb3_agents_adapter_steps_as_the_parallel_env():
    """SB3AgentVecEnv (one environment per UAV of a batch of formations, for a policy whose
    parameters the UAVs share) against the PettingZoo env: formation b's agents see and earn
    what the parallel env's agents do, step for step, and end with their formation (a tilt)."""
    pytest.importorskip('stable_baselines3')
    from multilift_learning.parallel_env import parallel_env
    from multilift_learning.sb3 import SB3AgentVecEnv
    kwargs = {'scenario': 'multi_lift', 'duration': 1.0, 'action_mode': 'thrust_body_rates',
              'tilt_limit_deg': 5.0}
    ours = SB3AgentVecEnv.make('multilift/Hover-v0', 2, **kwargs)
    assert ours.num_envs == 6 and ours.observation_space.shape == (22,)
    theirs = [parallel_env(**kwargs) for _ in range(2)]
    ours.seed(9)  # formation b: agent 0's seed, 9 + 3 b
    first = ours.reset()
    for b, env in enumerate(theirs):
        seen, _ = env.reset(seed=9 + 3 * b)
        assert np.array_equal(first[3 * b:3 * b + 3], np.stack(list(seen.values())))
    rng = np.random.default_rng(1)
    ended = 0
    for _ in range(60):
        actions = rng.uniform(-0.2, 0.2, (6, 4))
        actions[0, 1] = 1.0  # formation 0's leader rolls past the tilt limit
        observations, rewards, dones, infos = ours.step(actions)
        for b, env in enumerate(theirs):
            seen, earned, terminated, *_ = env.step(
                {name: actions[3 * b + k] for k, name in enumerate(env.possible_agents)})
            done = terminated['uav1']
            assert np.array_equal(rewards[3 * b:3 * b + 3], [np.float32(earned['uav1'])] * 3)
            assert list(dones[3 * b:3 * b + 3]) == [done] * 3
            if done:
                ended += 1
                final = np.stack([infos[3 * b + k]['terminal_observation'] for k in range(3)])
                assert np.array_equal(final, np.stack(list(seen.values())))
            else:
                assert np.array_equal(observations[3 * b:3 * b + 3], np.stack(list(seen.values())))
        if ended:
            break
    assert ended == 1 and dones[:3].all() and not dones[3:].any()


def test_a_task_s_scenario_file_flies_the_task_s_physics():
    """The YAML `multilift run` flies for a policy (tasks.task_scenario_yaml) is the task's
    scenario: the same states to the bit after 3 s."""
    from multilift_control.engine import Engine
    from multilift_learning.tasks import scenario_of, task_scenario, task_scenario_yaml
    from multilift_sim import scenario as scenario_io
    written = scenario_io.loads(task_scenario_yaml('twin_lift', 'hover', duration=3.0), 'task')
    flown = task_scenario(scenario_of('twin_lift', duration=3.0), 'hover')
    assert written.cable_model == 'slack' and written.payload.swing == 0.0
    a, b = Engine(written), Engine(flown)
    a.step(300)
    b.step(300)
    assert np.array_equal(a.state, b.state) and a.finished[0]


@pytest.mark.parametrize('agents', [False, True])
def test_the_training_example_writes_a_policy_its_curve_and_its_evaluation(tmp_path, monkeypatch,
                                                                         agents):
    """examples/learning/train_ppo.py, two updates: policy.npz loads with the environment's
    (or one agent's) sizes, progress.csv has a row per update, evaluation.json the policy's and
    the baseline's figures (and, with --agents, the PettingZoo env's, equal to the batch's: the
    same seeds)."""
    pytest.importorskip('stable_baselines3')
    import runpy
    import sys

    from conftest import ROOT
    out = tmp_path / 'ppo'
    monkeypatch.setattr(sys, 'argv', [
        'train_ppo.py', '--steps', '1024', '--envs', '2', '--rollout', '256', '--batch', '256',
        '--epochs', '1', '--duration', '0.5', '--eval-episodes', '2', '--scenario', 'multi_lift',
        '--out', str(out)] + (['--agents'] if agents else []))
    runpy.run_path(str(ROOT / 'examples' / 'learning' / 'train_ppo.py'), run_name='__main__')
    policy = policies.load(out / 'policy.npz')
    assert policy.environment['trained']['steps'] == 1024
    assert (policy.observation_size, policy.action_size) == ((22, 4) if agents else (54, 12))
    rows = (out / 'progress.csv').read_text().splitlines()
    assert rows[0].startswith('steps,') and [r.split(',')[0] for r in rows[1:]] == ['512', '1024']
    result = json.loads((out / 'evaluation.json').read_text())
    assert result['baseline']['flown_to_end'] == 1.0
    assert ('parallel_env' in result) == agents
    if agents:
        assert result['parallel_env']['flown_to_end'] == result['policy']['flown_to_end']
        if result['policy']['flown_to_end']:
            assert result['parallel_env']['payload_error_mean'] == pytest.approx(
                result['policy']['payload_error_mean'], rel=1e-9)
