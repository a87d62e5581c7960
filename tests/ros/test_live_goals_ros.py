"""Live goals through ROS (issue 34 item 2): `multilift run SCENARIO --live` holds the leader's
start until `multilift goal` sends one; the leader's reference then flies there and holds it,
the formation follows, and /formation/goal is in the bag with its stamp. `--live` with
`--headless` is exit 2, and `multilift goal` without a live run is exit 1."""
from __future__ import annotations

import subprocess

import numpy as np

from conftest import ROOT, raw_messages, started_run, wait_for
from multilift_tools.bagdata import load_run
from multilift_sim import scenario as scenario_io

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
STAMP = 4.0  # [s] simulated: the goal takes effect at this tick (or later, if it comes later)
DURATION = 20.0  # [s] simulated, paced to the wall clock: time enough for a late goal


def test_a_live_goal_is_flown_from_its_stamp_and_recorded(ros_env, tmp_path):
    bag = tmp_path / 'bag'
    start = np.array(scenario_io.load('single_lift').uavs[0].position)
    goal = start + np.array([0.4, -0.3, 0.3])
    with started_run(['single_lift', '--live', '--realtime', '--duration', str(DURATION),
                      '--bag', str(bag)], ros_env) as (run, work):
        sent = subprocess.run([MULTILIFT, 'goal', *map(str, goal), '--at', str(STAMP),
                               '--yaw', '20', '--timeout', '60'], env=ros_env,
                              capture_output=True, text=True, timeout=120)
        assert sent.returncode == 0, sent.stderr
        log = work / 'leader_node.log'
        wait_for(lambda: log.exists(), 60, f'the leader log in {sorted(work.iterdir())}')
        wait_for(lambda: 'goal flown from t = ' in log.read_text(), 120,
                 'the leader flying the goal')
        # at its stamp, unless the goal came later (a loaded machine)
        assert ('goal flown from t = 4.000 s\n' in log.read_text()
                or 'it came later' in log.read_text()), log.read_text()
        _, err = run.communicate(timeout=300)
    assert run.returncode == 0, err[-2000:]
    flown = load_run(bag)
    times, reference = flown.reference_time, flown.reference_position()
    before = times < STAMP - 1e-9
    # held at the start until the stamp (or until the goal came, were it late), then flown
    assert np.abs(reference[before] - start).max() < 1e-12
    moved = np.flatnonzero(np.abs(reference - start).max(axis=1) > 1e-9)
    assert len(moved) and times[moved[0]] >= STAMP - 1e-9
    np.testing.assert_allclose(reference[-1], goal, atol=1e-9)
    assert np.linalg.norm(flown.uav_positions()[0][-1] - goal) < 0.15
    assert flown.uav_euler()[0][-1, 2] > np.radians(10.0)  # turning to the goal's yaw
    [goal_message] = raw_messages(bag)['/formation/goal']
    assert len(goal_message) > 0


def test_live_with_headless_is_exit_2_and_a_goal_without_a_run_is_exit_1(ros_env):
    out = subprocess.run([MULTILIFT, 'run', 'twin_lift', '--live', '--headless'],
                         capture_output=True, text=True, timeout=60, env=ros_env)
    assert out.returncode == 2 and 'error: --live' in out.stderr
    out = subprocess.run([MULTILIFT, 'goal', '1', '2', '3', '--timeout', '1'],
                         capture_output=True, text=True, timeout=60, env=ros_env)
    assert out.returncode == 1 and 'nothing reads /formation/goal' in out.stderr
    out = subprocess.run([MULTILIFT, 'goal', '1', 'nan', '3'], capture_output=True, text=True,
                         timeout=60, env=ros_env)
    assert out.returncode == 2
