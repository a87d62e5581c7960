"""The learning environments (multilift_learning): Gymnasium's own checks, determinism, the
baseline (the seed's controllers) equal to the engine's headless run, the vectorised
environment equal to single ones and its autoreset as Gymnasium's NEXT_STEP defines it; the
PettingZoo environment, recorded episodes, the example's batched search."""
from __future__ import annotations

import importlib.util

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from pettingzoo.test import parallel_api_test

import multilift_learning
from conftest import ROOT, raw_messages
from multilift_control.engine import Engine
from multilift_learning.attitude import AttitudeActions
from multilift_learning.batch import observation_names
from multilift_learning.parallel_env import parallel_env
from multilift_learning.policies import MlpPolicy, shared_by_agents
from multilift_learning.recording import RecordEpisodes
from multilift_learning.tasks import task_scenario
from multilift_learning.vector_env import FormationVectorEnv
from multilift_sim import scenario as scenario_io
from multilift_tools.bagdata import load_run
from multilift_tools.figures import plot_main
from multilift_tools.headless_bag import record_headless


@pytest.mark.parametrize('env_id', sorted(multilift_learning.ENVIRONMENTS))
def test_registered_on_import_and_gymnasium_s_checker_passes(env_id):
    env = gymnasium.make(env_id, duration=0.1)
    check_env(env.unwrapped, skip_render_check=True)
    observation, info = env.reset(seed=0)
    n = env.unwrapped.batch.n          # twin_lift's two UAVs; Navigate-v0's forest, three
    assert observation.shape == (len(observation_names(n)),) == (38 if n == 2 else 54,)
    assert observation.dtype == np.float32
    assert env.action_space.shape == (4 * n,) and info['t'] == 0.0


def _episode(env, seed: int, steps: int) -> list[np.ndarray]:
    observation, _ = env.reset(seed=seed)
    env.action_space.seed(seed)
    seen = [observation]
    for _ in range(steps):
        observation, reward, terminated, truncated, _ = env.step(env.action_space.sample() * 0.1)
        seen.append(np.append(observation, reward))
    return seen


def test_the_same_seed_gives_the_same_episode():
    env = gymnasium.make('multilift/Hover-v0', duration=0.2)
    first, again = _episode(env, 7, 15), _episode(env, 7, 15)
    other = _episode(env, 8, 15)
    assert all(np.array_equal(a, b) for a, b in zip(first, again))
    assert not np.array_equal(first[0], other[0])  # the target drawn differs


@pytest.mark.parametrize('env_id,name', [('multilift/Mission-v0', 'twin_lift'),
                                         ('multilift/Mission-v0', 'multi_lift'),
                                         ('multilift/Hover-v0', 'twin_lift')])
def test_the_baseline_episode_is_the_headless_run(env_id, name):
    """The seed's controllers as the policy fly what the engine flies on its own (1e-9 m),
    tick by tick to the episode's truncation at the scenario's duration."""
    env = gymnasium.make(env_id, scenario=name, duration=3.0, target_radius=0.0).unwrapped
    env.reset(seed=0)
    scenario = scenario_io.load(name).with_duration(3.0)
    headless = Engine(task_scenario(scenario, env.batch.targets.task.name))
    steps, baseline = 0, 0.0
    while True:
        _, reward, terminated, truncated, info = env.step(env.expert_action())
        headless.step(1)
        steps, baseline = steps + 1, baseline + reward
        assert np.abs(env.batch.engine.state - headless.state).max() < 1e-9
        if terminated or truncated:
            break
    assert truncated and not terminated and steps == 300 and headless.finished[0]
    assert np.isfinite(baseline)
    print(f'{env_id} {name}: return of the baseline over 3 s: {baseline:.1f}')


def test_the_vector_env_is_single_envs_in_one_engine_with_next_step_autoreset():
    vector = gymnasium.make_vec('multilift/Hover-v0', num_envs=3, duration=0.05)
    assert isinstance(vector, FormationVectorEnv)  # the batched engine, no loop over envs
    singles = [gymnasium.make('multilift/Hover-v0', duration=0.05) for _ in range(3)]
    observations, _ = vector.reset(seed=10)
    first = observations.copy()
    for k, env in enumerate(singles):
        assert np.array_equal(observations[k], env.reset(seed=10 + k)[0])
    rng = np.random.default_rng(0)
    for step in range(5):
        actions = rng.uniform(-0.1, 0.1, vector.action_space.shape)
        observations, rewards, terminated, truncated, infos = vector.step(actions)
        for k, env in enumerate(singles):
            single = env.step(actions[k])
            assert np.array_equal(observations[k], single[0])
            assert rewards[k] == single[1] and truncated[k] == single[3]
        assert truncated.all() == (step == 4)
    # the step after the end: each environment reset, its action ignored
    observations, rewards, terminated, truncated, infos = vector.step(actions)
    assert (rewards == 0).all() and not terminated.any() and not truncated.any()
    assert (infos['t'] == 0).all()
    assert not np.array_equal(observations, first)  # new targets drawn from each stream


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match='unknown task'):
        FormationVectorEnv(2, task='juggle')
    with pytest.raises(ValueError, match='num_envs must be >= 1'):
        FormationVectorEnv(0)
    with pytest.raises(ValueError, match='control.mode: cascade'):
        gymnasium.make('multilift/Mission-v0', overrides={'control.mode': 'constant_rotor_speed'})
    with pytest.raises(scenario_io.ScenarioError, match='payload.mass'):
        gymnasium.make('multilift/Hover-v0', overrides={'payload.mass': -1.0})


def test_overrides_reach_the_scenario():
    env = gymnasium.make('multilift/Hover-v0', overrides={'payload.mass': 1.2},
                         duration=1.0).unwrapped
    assert env.batch.scenarios[0].payload.mass == 1.2
    assert env.batch.engine.t_max[0] == pytest.approx(1.0)


def test_the_parallel_env_passes_pettingzoo_s_test_and_flies_the_baseline():
    parallel_api_test(parallel_env(scenario='multi_lift', duration=0.2), num_cycles=30)
    env = parallel_env(scenario='multi_lift', task='mission', duration=0.5)
    single = gymnasium.make('multilift/Mission-v0', scenario='multi_lift', duration=0.5)
    observations, _ = env.reset(seed=4)
    flat, _ = single.reset(seed=4)
    assert env.agents == ['uav1', 'uav2', 'uav3']
    assert np.array_equal(observations['uav2'][:16], flat[16:32])
    while env.agents:
        observations, rewards, terminated, truncated, _ = env.step(env.expert_actions())
        flat, reward, *_ = single.step(single.unwrapped.expert_action())
        assert np.array_equal(observations['uav3'][-6:], flat[-6:]) and rewards['uav1'] == reward
    assert truncated['uav1'] and not terminated['uav1']


def _agent_policy(observation_size: int, action_size: int) -> MlpPolicy:
    """A random one-agent MLP (small weights: it flies near hover for a while)."""
    rng = np.random.default_rng(3)
    weights = (rng.normal(0, 0.1, (observation_size, 8)), rng.normal(0, 0.1, (8, action_size)))
    return MlpPolicy(weights, (np.zeros(8), np.zeros(action_size)), 'tanh',
                     np.zeros(observation_size), np.ones(observation_size), 10.0)


def test_an_agent_s_policy_shared_by_every_uav_flies_the_parallel_env_as_the_batch():
    """One agent's policy (the PettingZoo env's agent: its UAV's slots and the payload's)
    flown by every UAV: `policies.shared_by_agents` on the vector env's observations gives each
    agent what the parallel env shows it, and both fly the same episode (environment k of the
    vector env seeded s is the parallel env seeded s + k)."""
    kwargs = {'scenario': 'multi_lift', 'duration': 0.5, 'action_mode': 'thrust_body_rates'}
    env = parallel_env(**kwargs)
    agent = _agent_policy(env.observation_space('uav1').shape[0],
                          env.action_space('uav1').shape[0])
    vector = FormationVectorEnv(2, **kwargs)
    act = shared_by_agents(agent, 3)
    flat, _ = vector.reset(seed=7)
    observations, _ = env.reset(seed=8)
    steps = 0
    while env.agents:
        actions = act(flat)
        assert actions.shape == (2, 12)
        for k, name in enumerate(env.possible_agents):
            assert np.array_equal(observations[name], flat[1, env.agent_slots[k]])
            assert np.allclose(actions[1, 4 * k:4 * k + 4], agent(observations[name]),
                               rtol=0, atol=1e-12)  # one matrix product or one row's
        observations, rewards, *_ = env.step({name: actions[1, 4 * k:4 * k + 4]
                                              for k, name in enumerate(env.agents)})
        flat, reward, *_ = vector.step(actions)
        assert rewards['uav1'] == reward[1]
        steps += 1
    assert steps == 50


def test_a_population_in_one_batch_scores_as_its_candidates_alone():
    """The example's search (examples/learning): candidates' returns from one batched
    environment equal each candidate flown alone."""
    path = ROOT / 'examples' / 'learning' / 'tune_follower_gains.py'
    spec = importlib.util.spec_from_file_location('tune_follower_gains', path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    gains = np.array([[2.1, 1.3], [1.0, 3.0], [3.0, 0.5]])
    together = example.returns('twin_lift', 1.0, gains)
    alone = [example.returns('twin_lift', 1.0, g[None])[0] for g in gains]
    assert together.tolist() == alone and len(set(alone)) == 3


def test_an_episode_recorded_is_the_run_s_bag_and_plots(tmp_path, capsys):
    """The baseline's episode, recorded: the simulator's topics of a headless run's bag (1e-9
    m), the policy's rotor commands, no controller topic; `multilift plot` draws it."""
    env = RecordEpisodes(gymnasium.make('multilift/Mission-v0', duration=1.0), tmp_path / 'ep')
    env.reset(seed=0)
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(env.unwrapped.expert_action())
        done = terminated or truncated
    [bag] = env.bags
    record_headless(task_scenario(scenario_io.load('twin_lift').with_duration(1.0), 'mission'),
                    tmp_path / 'headless')
    episode, headless = load_run(bag), load_run(tmp_path / 'headless')
    assert np.array_equal(episode.t, headless.t) and len(episode.t) == 101
    assert np.abs(episode.uav_positions() - headless.uav_positions()).max() < 1e-9
    assert np.abs(episode.payload_position() - headless.payload_position()).max() < 1e-9
    assert np.abs(episode.rotor_speeds(2) - headless.rotor_speeds(2)).max() < 1e-6
    recorded = raw_messages(bag)
    assert len(recorded['/uav1/rotor_cmd']) == 100
    assert '/uav1/attitude_setpoint' not in recorded and '/uav1/reference' not in recorded
    assert plot_main([str(bag), '--out', str(tmp_path / 'plots')]) == 0
    assert list((tmp_path / 'plots').glob('*.png'))


def test_rgb_array_frames_show_the_formation():
    env = gymnasium.make('multilift/Hover-v0', duration=0.5, render_mode='rgb_array')
    env.reset(seed=0)
    first = env.render()
    for _ in range(20):
        env.step(env.unwrapped.expert_action())
    later = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    assert first.shape == later.shape and not np.array_equal(first, later)
    with pytest.raises(ValueError, match='render_mode'):
        gymnasium.make('multilift/Hover-v0', render_mode='ansi')


def test_attitude_actions_are_the_controllers_inner_half():
    """The seed's controllers' own attitude set-points and thrust, given as AttitudeActions,
    fly what the engine flies with its whole cascade (1e-9 m)."""
    env = AttitudeActions(gymnasium.make('multilift/Mission-v0', duration=2.0))
    env.reset(seed=0)
    assert env.action_space.shape == (8,)
    own = Engine(task_scenario(scenario_io.load('twin_lift').with_duration(2.0), 'mission'))
    record = own.new_record(1)
    done = False
    while not done:
        own.step(1, record)
        action = env.attitude_action(record.setpoints[0, 0], record.thrust[0, 0])
        _, _, terminated, truncated, _ = env.step(action)
        done = terminated or truncated
        assert np.abs(env.unwrapped.batch.engine.state - own.state).max() < 1e-9
    assert truncated and own.finished[0]
