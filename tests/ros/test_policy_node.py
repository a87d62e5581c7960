"""From training to ROS: a policy on the learning environments' observations flies a run
through `multilift run SCENARIO --external uav1,..` as multilift_learning's policy_node; the
baseline policy's bag is our controllers' run (lockstep: 1e-9 m); the tension a policy sees is
its tick's (the environment's); a policy file (npz) flies in its action mode."""
from __future__ import annotations

import os
import signal
import subprocess

import numpy as np

from conftest import ROOT, next_domain, raw_messages
from multilift_learning.policies import MlpPolicy, save
from multilift_tools.bagdata import load_run

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
DURATION = '2'
# a policy of a user's: every rotor at the speed that carries the UAV and its payload share
HOVER_POLICY = '''
import numpy as np
from multilift_learning.env import FormationEnv
_env = FormationEnv('twin_lift', task='mission')
_hover = _env.batch.actions(_env.batch.speed_hover.repeat(_env.batch.rotors, axis=2))[0]
def act(observation):
    assert observation.shape == _env.observation_space.shape
    return _hover
'''


def _env(**extra) -> dict:
    return dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', **extra)


def _fly_with_policy(tmp_path, policy: str, env: dict) -> subprocess.CompletedProcess:
    node = subprocess.Popen([MULTILIFT, 'node', 'multilift_learning', 'policy_node',
                             '--ros-args', '-p', 'scenario:=twin_lift', '-p', f'policy:={policy}',
                             '-p', 'record:=true'], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        run = subprocess.run([MULTILIFT, 'run', 'twin_lift', '--external', 'uav1,uav2',
                              '--duration', DURATION, '--bag', str(tmp_path / 'policy')],
                             capture_output=True, text=True, timeout=300, env=env)
    finally:
        if node.poll() is None:
            os.killpg(node.pid, signal.SIGINT)
        out, _ = node.communicate(timeout=60)
    assert run.returncode == 0, run.stdout + run.stderr + out
    return run


def test_the_baseline_policy_flies_the_run_of_our_controllers(tmp_path):
    env = _env()
    ours = subprocess.run([MULTILIFT, 'run', 'twin_lift', '--duration', DURATION, '--bag',
                           str(tmp_path / 'ours')], capture_output=True, text=True, timeout=300,
                          env=env)
    assert ours.returncode == 0, ours.stderr
    run = _fly_with_policy(tmp_path, 'baseline', env)
    assert 'leader tracking' not in run.stdout  # none of our controllers ran
    policy, reference = load_run(tmp_path / 'policy'), load_run(tmp_path / 'ours')
    assert np.array_equal(policy.t, reference.t)
    assert np.abs(policy.uav_positions() - reference.uav_positions()).max() < 1e-9
    assert np.abs(policy.payload_position() - reference.payload_position()).max() < 1e-9
    assert len(raw_messages(tmp_path / 'policy')['/uav2/rotor_cmd']) == 200


def test_a_users_callable_flies_through_the_node(tmp_path):
    (tmp_path / 'user_policy.py').write_text(HOVER_POLICY)
    env = _env(PYTHONPATH=f'{tmp_path}:{os.environ.get("PYTHONPATH", "")}')
    _fly_with_policy(tmp_path, 'user_policy:act', env)
    commands = raw_messages(tmp_path / 'policy')['/uav1/rotor_cmd']
    assert len(commands) == 200 and len(set(c[-40:] for c in commands)) == 1  # held hover


# a user's policy that notes the tension slots it is given (uav1's and uav2's tension ratio)
TENSION_POLICY = '''
import os
import numpy as np
def act(observation):
    with open(os.environ['TENSION_LOG'], 'a') as log:
        log.write(f'{float(observation[15])!r} {float(observation[31])!r}\\n')
    return np.zeros(8)
'''


def test_the_policy_sees_the_tension_of_its_tick(tmp_path):
    """The tension slots at tick k are /formation/state's of tick k - 1 (the environment's:
    the integration that ended at k), 0 at k = 0; not one tick late."""
    (tmp_path / 'tension_policy.py').write_text(TENSION_POLICY)
    log = tmp_path / 'tension.txt'
    env = _env(PYTHONPATH=f'{tmp_path}:{os.environ.get("PYTHONPATH", "")}', TENSION_LOG=str(log))
    _fly_with_policy(tmp_path, 'tension_policy:act', env)
    seen = np.loadtxt(log)
    run = load_run(tmp_path / 'policy')
    share = 0.8 * 9.81 / 2  # twin_lift: m_p g / n [N]
    assert len(seen) == 200 and (seen[0] == 0).all()
    assert np.abs(seen[1:] - run.tensions()[:199] / share).max() < 1e-6  # float32 slots


def test_a_policy_file_flies_in_its_action_mode(tmp_path):
    """A policy file whose network answers 0 (hover in thrust_body_rates) flies the run; a
    file of the wrong shape is one line and exit 1."""
    zero = MlpPolicy((np.zeros((38, 4)), np.zeros((4, 8))), (np.zeros(4), np.zeros(8)), 'tanh',
                     np.zeros(38), np.ones(38), 10.0,
                     {'options': {'action_mode': 'thrust_body_rates'}})
    save(tmp_path / 'zero.npz', zero)
    _fly_with_policy(tmp_path, f'npz:{tmp_path / "zero.npz"}', _env())
    run = load_run(tmp_path / 'policy')
    heights = run.uav_positions()[:, :, 2]  # (n, T)
    assert len(raw_messages(tmp_path / 'policy')['/uav1/rotor_cmd']) == 200
    assert np.abs(heights - heights[:, :1]).max() < 0.5  # held up by its hover thrust
    wrong = MlpPolicy((np.zeros((30, 4)), np.zeros((4, 8))), (np.zeros(4), np.zeros(8)),
                      'tanh', np.zeros(30), np.ones(30), 10.0, {})
    save(tmp_path / 'wrong.npz', wrong)
    out = subprocess.run([MULTILIFT, 'node', 'multilift_learning', 'policy_node', '--ros-args',
                          '-p', 'scenario:=twin_lift', '-p', f'policy:=npz:{tmp_path}/wrong.npz'],
                         capture_output=True, text=True, timeout=60, env=_env())
    assert out.returncode == 1 and len(out.stderr.strip().splitlines()) == 1
    assert 'maps 30 observations to 8 actions' in out.stderr


def test_a_bad_policy_is_one_line_and_exit_1(tmp_path):
    out = subprocess.run([MULTILIFT, 'node', 'multilift_learning', 'policy_node', '--ros-args',
                          '-p', 'scenario:=twin_lift', '-p', 'policy:=nowhere'],
                         capture_output=True, text=True, timeout=60, env=_env())
    assert out.returncode == 1
    assert 'expected baseline, MODULE:CALLABLE or npz:PATH' in out.stderr
