"""Winches through ROS (issue 32 item 3, docs/cables.md): a twin-lift whose winches pay out
flies through ROS as headless, both bags carrying /uav{i}/cable_length; a live run
(`run --live`) reels at the rate `multilift winch` sends, from the tick it arrives in or, stamped
(`--at T`), from the tick of its stamp, which the bag records; bad
arguments are exit 2, a winch command without a run exit 1."""
from __future__ import annotations

import struct
import subprocess

import numpy as np
import yaml

from conftest import ROOT, SCENARIOS, flown_alike, raw_messages, started_run, wait_for

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
WINCH = {'rate_limit': 0.5, 'acceleration_limit': 0.5, 'min_length': 2.0, 'max_length': 15.0}


def _lengths(bag, uav: int) -> np.ndarray:
    """The /uav{uav}/cable_length values [m] of a bag (std_msgs/Float64: CDR header, double)."""
    return np.array([struct.unpack_from('<d', data, 4)[0]
                     for data in raw_messages(bag)[f'/uav{uav}/cable_length']])


def test_a_winched_twin_lift_flies_alike_through_ros_and_headless(tmp_path, multilift_run):
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    for uav in data['uavs']:
        uav['winch'] = WINCH
    data['simulation']['duration'] = 5.0
    data['events'] = [{'time': 1.0, 'type': 'winch_rate', 'uav': i, 'rate': 0.3}
                      for i in (1, 2)] + [{'time': 3.5, 'type': 'winch_rate', 'uav': 2,
                                           'rate': 0.0}]
    path = tmp_path / 'twin_lift_winch.yaml'
    path.write_text(yaml.safe_dump(data))
    ros, headless = flown_alike(multilift_run, path, tmp_path)
    for uav in (1, 2):
        lengths = _lengths(tmp_path / 'ros', uav)
        assert len(lengths) == len(ros.t)     # one a tick, t = 0 to t_max
        np.testing.assert_array_equal(lengths, _lengths(tmp_path / 'headless', uav))
        assert lengths[0] == 10.26 and np.all(np.diff(lengths) >= 0.0)
    # uav2 stopped at 3.5 s: 0.3 m/s for 2.5 s less its ramp's 0.09 m, plus the stop's 0.09 m
    assert abs(_lengths(tmp_path / 'ros', 2)[-1] - (10.26 + 0.75)) < 1e-9
    assert ros.summary['sim']['longest_cable'] == headless.summary['sim']['longest_cable']


def test_a_live_reel_rate_is_reeled_and_recorded(ros_env, tmp_path):
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['uavs'][0]['winch'] = dict(WINCH, min_length=1.0)
    path = tmp_path / 'single_lift_winch.yaml'
    path.write_text(yaml.safe_dump(data))
    bag = tmp_path / 'bag'
    with started_run([str(path), '--live', '--realtime', '--duration', '12', '--bag', str(bag)],
                     ros_env) as (run, work):
        # at once, and stamped for t = 9 s (sent together: the stamp, not the arrival, counts)
        sent = [subprocess.Popen([MULTILIFT, 'winch', '1', *args, '--timeout', '60'],
                                 env=ros_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True) for args in (['0.4'], ['-0.4', '--at', '9'])]
        for tool in sent:
            _, tool_err = tool.communicate(timeout=120)
            assert tool.returncode == 0, tool_err
        log = work / 'sim_node.log'
        wait_for(lambda: 'uav1 winch commanded to 0.4 m/s' in log.read_text(), 60,
                 'the simulator reeling')
        wait_for(lambda: 'uav1 winch commanded to -0.4 m/s at t = 9.000 s' in log.read_text(),
                 60, 'the simulator queueing the stamped rate for its tick')
        _, err = run.communicate(timeout=300)
    assert run.returncode == 0, err[-2000:]
    lengths = _lengths(bag, 1)
    assert lengths[0] == 2.5 and lengths[-1] > 2.5 + 0.2   # it paid out
    assert np.abs(np.diff(lengths)).max() <= 0.4 * 0.01 + 1e-12   # within the commanded rate
    # the period from tick 900 (t = 9 s) is the first to brake at 0.5 m/s^2: its mean rate
    # 0.4 - 0.5 x 0.01 / 2, the period before it still at 0.4 m/s
    rates = np.diff(lengths) / 0.01
    assert abs(rates[899] - 0.4) < 1e-9 and abs(rates[900] - 0.3975) < 1e-9
    [command] = raw_messages(bag)['/uav1/winch_cmd']
    assert struct.unpack_from('<d', command, 4)[0] == 0.4
    [stamped] = raw_messages(bag)['/uav1/winch_cmd_stamped']
    assert struct.unpack_from('<iI', stamped, 4) == (9, 0)


def test_bad_winch_arguments_are_exit_2_and_no_run_exit_1(ros_env):
    for args in (['1', 'nan'], ['0', '0.3'], ['1', '0.3', '--timeout', '0'],
                 ['1', '0.3', '--at', '-1']):
        out = subprocess.run([MULTILIFT, 'winch', *args], capture_output=True, text=True,
                             timeout=60, env=ros_env)
        assert out.returncode == 2 and out.stderr.startswith('error: winch:'), out.stderr
    out = subprocess.run([MULTILIFT, 'winch', '1', '0.3', '--timeout', '1'],
                         capture_output=True, text=True, timeout=60, env=ros_env)
    assert out.returncode == 1 and 'nothing reads /uav1/winch_cmd' in out.stderr
