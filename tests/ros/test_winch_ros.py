"""Winches through ROS (issue 32 item 3, docs/cables.md): a twin-lift whose winches pay out
flies through ROS as headless, both bags carrying /uav{i}/cable_length; a live run
(`run --live`) reels at the rate `multilift winch` sends, from the tick it arrives in or, stamped
(`--at T`), from the tick of its stamp, which the bag records; bad
arguments are exit 2, a winch command without a run exit 1."""
from __future__ import annotations

import re
import struct
import subprocess

import numpy as np
import pytest
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
    """`multilift winch 1 0.4` reels from the tick it arrives in; then `multilift winch 1 0
    --at T`, stamped 5 s of simulated time after it, stops the reel from the tick of T (or,
    arriving after T on a loaded machine, from the tick it arrives in, logged late): the bag
    shows the braking from exactly the tick the simulator logged."""
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['uavs'][0]['winch'] = dict(WINCH, min_length=1.0)
    path = tmp_path / 'single_lift_winch.yaml'
    path.write_text(yaml.safe_dump(data))
    bag = tmp_path / 'bag'
    reeling = re.compile(r'uav1 winch commanded to 0\.4 m/s at t = ([0-9.]+) s')
    stopping = re.compile(r'uav1 winch commanded to 0 m/s at t = ([0-9.]+) s( \()?')
    with started_run([str(path), '--live', '--realtime', '--duration', '20', '--bag', str(bag)],
                     ros_env) as (run, work):
        sent = subprocess.run([MULTILIFT, 'winch', '1', '0.4', '--timeout', '60'],
                              env=ros_env, capture_output=True, text=True, timeout=120)
        assert sent.returncode == 0, sent.stderr
        log = work / 'sim_node.log'
        wait_for(lambda: reeling.search(log.read_text()), 60, 'the simulator reeling')
        start = float(reeling.search(log.read_text()).group(1))
        assert start < 14.0, 'the first command came too late to test the stamped one'
        stamp = round(start + 5.0, 2)
        sent = subprocess.run([MULTILIFT, 'winch', '1', '0', '--at', f'{stamp:.2f}',
                               '--timeout', '60'],
                              env=ros_env, capture_output=True, text=True, timeout=120)
        assert sent.returncode == 0, sent.stderr
        wait_for(lambda: stopping.search(log.read_text()), 60, 'the simulator stopping')
        stop, late = stopping.search(log.read_text()).groups()
        _, err = run.communicate(timeout=300)
    assert run.returncode == 0, err[-2000:]
    if not late:
        assert float(stop) == pytest.approx(stamp, abs=1e-9)   # the stamp's tick
    lengths = _lengths(bag, 1)
    assert lengths[0] == 2.5 and lengths[-1] > 2.5 + 0.2   # it paid out
    assert np.abs(np.diff(lengths)).max() <= 0.4 * 0.01 + 1e-12   # within the commanded rate
    # from the logged tick the reel brakes at 0.5 m/s^2 (at 0.4 m/s since the first command,
    # more than a ramp of 0.8 s earlier): that period's mean rate 0.4 - 0.5 x 0.01 / 2, the
    # period before at 0.4, and at rest from 0.8 s after
    rates = np.diff(lengths) / 0.01
    tick = round(float(stop) / 0.01)
    assert abs(rates[tick - 1] - 0.4) < 1e-9 and abs(rates[tick] - 0.3975) < 1e-9
    assert np.all(rates[tick + 81:] == 0.0)
    [command] = raw_messages(bag)['/uav1/winch_cmd']
    assert struct.unpack_from('<d', command, 4)[0] == 0.4
    [stamped] = raw_messages(bag)['/uav1/winch_cmd_stamped']
    assert struct.unpack_from('<iI', stamped, 4) == (int(stamp), round(stamp % 1 * 1e9))


def test_bad_winch_arguments_are_exit_2_and_no_run_exit_1(ros_env):
    for args in (['1', 'nan'], ['0', '0.3'], ['1', '0.3', '--timeout', '0'],
                 ['1', '0.3', '--at', '-1']):
        out = subprocess.run([MULTILIFT, 'winch', *args], capture_output=True, text=True,
                             timeout=60, env=ros_env)
        assert out.returncode == 2 and out.stderr.startswith('error: winch:'), out.stderr
    out = subprocess.run([MULTILIFT, 'winch', '1', '0.3', '--timeout', '1'],
                         capture_output=True, text=True, timeout=60, env=ros_env)
    assert out.returncode == 1 and 'nothing reads /uav1/winch_cmd' in out.stderr
