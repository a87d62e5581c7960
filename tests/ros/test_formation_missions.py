"""Twin-lift and "V" multi-lift fly the seed's 120 s mission (seed Ch. 4): the twin-lift through
the ROS stack, its bag equal to the headless run's over the whole mission (1e-9 m), the V
headless (the same laws and tick: tests/ros/test_headless.py, and here the twin-lift).

Checked against physics computed here from the recorded positions (Eq. 2.73 force balance),
not against recorded outputs of our own code. The figures the README quotes are printed.
"""
from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

from conftest import ROOT, next_domain
from multilift_tools.bagdata import load_run

MULTILIFT = str(ROOT / 'scripts' / 'multilift')
K_T = 1.83e-6        # Table 4.2 [N s^2/rad^2]
M_UAV, M_P, G = 2.5, 0.8, 9.81


def _fly(name: str, tmp_path_factory, *options: str):
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    bag = tmp_path_factory.mktemp(name) / 'bag'
    out = subprocess.run([MULTILIFT, 'run', name, '--bag', str(bag), *options],
                         capture_output=True, text=True, timeout=1200, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    print(out.stdout)
    return load_run(bag)


@pytest.fixture(scope='module')
def twin(tmp_path_factory):
    return _fly('twin_lift', tmp_path_factory)


@pytest.fixture(scope='module')
def multi(tmp_path_factory):
    return _fly('multi_lift', tmp_path_factory, '--headless')


def test_the_ros_mission_is_the_headless_one(twin, tmp_path_factory):
    """The whole 120 s twin-lift through ROS nodes equals the headless run (lockstep)."""
    headless = _fly('twin_lift', tmp_path_factory, '--headless')
    assert np.array_equal(twin.t, headless.t) and twin.t[-1] == pytest.approx(120.0)
    assert np.abs(twin.uav_positions() - headless.uav_positions()).max() < 1e-9
    assert np.abs(twin.payload_position() - headless.payload_position()).max() < 1e-9
    assert np.abs(twin.rotor_speeds(2) - headless.rotor_speeds(2)).max() < 1e-6


def _thrust(run, i):
    """Delivered thrust k_T sum(omega^2) of UAV i (1 = leader) [N]."""
    return K_T * np.sum(run.rotor_speeds(i) ** 2, axis=1)


@pytest.mark.parametrize('which', ['twin', 'multi'])
def test_mission_completes_within_limits(which, request):
    run = request.getfixturevalue(which)
    assert run.formation_time[-1] == pytest.approx(120.0)
    for i in range(1, run.n_uavs + 1):
        w = run.rotor_speeds(i)
        assert w.min() >= 0.0 and w.max() <= 2100.0
        assert np.all(run.payload_position()[:, 2] < run.uav_positions()[i - 1][:, 2])
    g = run.g()
    print(f'{which}: max |g_i| = {np.abs(g).max():.2e} m^2 (seed: within 2e-2)')
    assert np.abs(g).max() < 2e-2


@pytest.mark.parametrize('which', ['twin', 'multi'])
def test_steady_hover_matches_static_equilibrium(which, request):
    """Eq. 2.73 at the end of the hover phase: payload balance gives the tensions; the leader's
    balance gives its thrust, hence its rotor speed."""
    run = request.getfixturevalue(which)
    k = -1
    r = np.array([p[k] for p in run.uav_positions()])
    p = run.payload_position()[k]
    directions = (r - p) / np.linalg.norm(r - p, axis=1)[:, None]  # payload -> UAV
    tension, *_ = np.linalg.lstsq(directions.T, np.array([0, 0, M_P * G]), rcond=None)
    recorded = run.tensions()[k]
    assert recorded == pytest.approx(tension, abs=0.05 * M_P * G)
    leader_force = M_UAV * G * np.array([0, 0, 1.0]) + tension[0] * directions[0]
    omega = np.sqrt(np.linalg.norm(leader_force) / (4 * K_T))
    assert np.mean(run.rotor_speeds(1)[k]) == pytest.approx(omega, rel=0.01)


def test_leader_needs_more_thrust_in_the_climb(twin):
    """Seed §4.3: while the follower's altitude loop lags the leader at the start of the
    climb, the leader carries more (6.14 % in the seed)."""
    t = twin.rotor_time(1)
    onset, climb = t < 2.0, t < 10.0
    excess = {name: 100 * (_thrust(twin, 1)[w].mean() / _thrust(twin, 2)[w].mean() - 1)
              for name, w in (('onset', onset), ('climb', climb))}
    print(f'twin-lift: leader thrust above the follower: {excess["onset"]:.2f} % over the first '
          f'2 s of the climb, {excess["climb"]:.2f} % over the whole 10 s climb (seed: 6.14 %)')
    z = twin.uav_positions()[:, twin.t < 2.0, 2]
    assert np.mean(z[1]) < np.mean(z[0])  # the follower lags in altitude
    assert excess['onset'] > 1.0
    assert excess['climb'] == pytest.approx(6.14, abs=1.5)


def test_v_leader_rotor_speed_drops_against_twin(twin, multi):
    cruise = (twin.rotor_time(1) > 60) & (twin.rotor_time(1) < 95)
    w_twin = twin.rotor_speeds(1)[cruise].mean()
    w_multi = multi.rotor_speeds(1)[cruise].mean()
    print(f'leader rotor speed, V vs twin-lift: {100 * (1 - w_multi / w_twin):.2f} % lower '
          f'(seed: 2.37 %)')
    assert w_multi < w_twin


def test_virtual_constraint_offset_bounded_and_smaller_for_the_v(twin, multi):
    late = twin.formation_error_time(2) > 60
    offsets = {}
    for name, run in (('twin', twin), ('multi', multi)):
        errors = [np.linalg.norm(run.formation_errors(i)[late], axis=1)
                  for i in range(2, run.n_uavs + 1)]
        for e in errors:
            assert np.all(np.isfinite(e)) and e.max() < 2.0  # bounded [m]
        offsets[name] = float(np.mean([e.mean() for e in errors]))
    print(f'persistent virtual-constraint offset: twin {offsets["twin"]:.3f} m, '
          f'V {offsets["multi"]:.3f} m')
    assert offsets['multi'] < offsets['twin']


@pytest.mark.parametrize('name', ['v5', 'circle3'])
def test_other_geometries_fly_30_s_with_bounded_errors(name, tmp_path_factory):
    """Headless (the ROS stack runs the same tick: test_the_ros_mission_is_the_headless_one)."""
    run = _fly(name, tmp_path_factory, '--duration', '30', '--headless')
    assert run.formation_time[-1] == pytest.approx(30.0)
    worst = max(np.abs(run.formation_errors(i)).max() for i in range(2, run.n_uavs + 1))
    print(f'{name}: largest virtual-constraint row error in 30 s: {worst:.3f} '
          '(m, or m^2 for distance rows)')
    assert worst < 5.0
    assert np.abs(run.g()).max() < 2e-2
