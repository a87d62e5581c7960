"""bagdata.load_run and the plot / animate / compare commands, on bags built in the test.

The bags are written with multilift_sim.bag.BagWriter from rclpy-serialized messages whose
values are known functions of time, so what load_run returns is checked value by value; the
figures are checked for what can be checked without a person: exit code, PNG/GIF files of
sane size and frame count, one error line for bad input.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from geometry_msgs.msg import Vector3Stamped
from multilift_msgs.msg import (AttitudeSetpoint, FormationState, RotorCommand,
                                TrackingReference, VirtualConstraintError)
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from std_msgs.msg import String

from multilift_tools import bagdata
from multilift_sim.bag import BagWriter
from multilift_sim.topics import (ATTITUDE_SETPOINT, FORMATION_ERROR, FORMATION_STATE, ODOM,
                                  PAYLOAD_GUST, PAYLOAD_ODOM, REFERENCE_TOPIC, ROTOR_CMD,
                                  topic_type, uav_topic)
from multilift_tools.bagdata import RunDataError, load_run
from multilift_tools.animation import animate_main
from multilift_tools.compare import compare_main
from multilift_tools.figures import plot_main

DT = 0.05  # [s] sample step of the synthetic runs
OMEGA_MAX = 2100.0  # [rad/s] rotor limit of the twin_lift / multi_lift scenarios
PNG_MAGIC = b'\x89PNG\r\n\x1a\n'


def _quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of R = Rz(yaw) Ry(pitch) Rx(roll), written independently of bagdata."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def _stamp(msg, t: float) -> None:
    ns = int(round(t * 1e9))
    msg.header.stamp.sec, msg.header.stamp.nanosec = ns // 1_000_000_000, ns % 1_000_000_000
    msg.header.frame_id = 'world'


@dataclass
class Truth:
    """What a synthetic bag holds: t (T,) [s]; uavs (n, T, 3) [m]; euler (n, T, 3) [rad];
    payload (T, 3) [m]; payload velocity (T, 3) [m/s]; tension, g, g_dot (T, n);
    omega (n, T, 4) [rad/s]; saturated (n, T, 4); thrust (n, T) [N]; errors (n-1, T, 3) [m];
    gust (T, 3) [m/s]; reference (T, 3) [m]."""
    t: np.ndarray
    uavs: np.ndarray
    euler: np.ndarray
    payload: np.ndarray
    payload_velocity: np.ndarray
    tension: np.ndarray
    g: np.ndarray
    g_dot: np.ndarray
    omega: np.ndarray
    saturated: np.ndarray
    thrust: np.ndarray
    errors: np.ndarray
    gust: np.ndarray
    reference: np.ndarray


def _truth(n: int, duration: float, swing: float) -> Truth:
    """A formation flying +x at 0.5 m/s with a payload swinging `swing` [m] below it."""
    t = np.arange(0.0, duration + 1e-9, DT)
    T = len(t)
    offsets = np.array([[0.0, 0.0, 0.0], [-3.46, 2.0, 0.0], [-3.46, -2.0, 0.0]])[:n]
    base = np.stack([0.5 * t, np.zeros(T), 2.0 + 0.1 * t], axis=1)
    uavs = base[None] + offsets[:, None, :]
    euler = np.stack([np.stack([0.1 * np.sin(t + i), 0.05 * np.cos(t), 0.3 * i + 0 * t], 1)
                      for i in range(n)])
    centroid = uavs.mean(axis=0)
    payload = centroid + np.stack([swing * np.sin(2 * np.pi * t / 6.4), np.zeros(T),
                                   np.full(T, -10.0)], axis=1)
    payload_velocity = np.gradient(payload, t, axis=0)
    k = np.arange(n)
    tension = 4.0 + np.sin(t)[:, None] + k[None]
    tension[T // 2, 0] = -0.5  # one compression sample
    g = 1e-6 * np.sin(3 * t)[:, None] * (k[None] + 1)
    g_dot = 3e-6 * np.cos(3 * t)[:, None] * (k[None] + 1)
    omega = 1900.0 + 50.0 * np.sin(t)[None, :, None] + 10.0 * np.arange(4)[None, None, :] \
        + 5.0 * np.arange(n)[:, None, None]
    saturated = np.zeros(omega.shape, dtype=bool)
    saturated[:, T // 3:T // 3 + 5, 0] = True
    omega[saturated] = OMEGA_MAX
    thrust = 27.0 + np.cos(t)[None] + 0.5 * k[:, None]
    errors = np.stack([np.stack([0.1 * np.sin(t) * i, -0.05 * i + 0 * t, 0.02 * np.cos(t)], 1)
                       for i in range(2, n + 1)]) if n > 1 else np.zeros((0, T, 3))
    gust = np.zeros((T, 3))
    gust[T // 2:T // 2 + 20, 1] = -np.sin(np.linspace(0, np.pi, 20)) * 3.0
    return Truth(t, uavs, euler, payload, payload_velocity, tension, g, g_dot, omega,
                 saturated, thrust, errors, gust, base)


def _odometry(t: float, position, quaternion, linear, child: str) -> Odometry:
    msg = Odometry(child_frame_id=child)
    _stamp(msg, t)
    p = msg.pose.pose.position
    p.x, p.y, p.z = (float(v) for v in position)
    q = msg.pose.pose.orientation
    q.x, q.y, q.z, q.w = quaternion
    v = msg.twist.twist.linear
    v.x, v.y, v.z = (float(c) for c in linear)
    return msg


def _messages(truth: Truth, k: int) -> list[tuple[str, object]]:
    """Every message of sample k, as (topic, message)."""
    t = float(truth.t[k])
    n = truth.uavs.shape[0]
    out: list[tuple[str, object]] = []
    for i in range(n):
        q = _quaternion(*truth.euler[i, k])
        out.append((uav_topic(i + 1, ODOM), _odometry(t, truth.uavs[i, k], q, (0.5, 0, 0),
                                                   f'uav{i + 1}/base_link')))
        rotor = RotorCommand(angular_velocity=[float(w) for w in truth.omega[i, k]],
                             saturated=[bool(s) for s in truth.saturated[i, k]])
        _stamp(rotor, t)
        out.append((uav_topic(i + 1, ROTOR_CMD), rotor))
        roll, pitch, yaw = truth.euler[i, k]
        setpoint = AttitudeSetpoint(roll=float(roll), pitch=float(pitch), yaw=float(yaw),
                                    thrust=float(truth.thrust[i, k]))
        _stamp(setpoint, t)
        out.append((uav_topic(i + 1, ATTITUDE_SETPOINT), setpoint))
        if i > 0:
            error = VirtualConstraintError(error=[float(e) for e in truth.errors[i - 1, k]],
                                           error_rate=[0.0, 0.0, 0.0])
            _stamp(error, t)
            out.append((uav_topic(i + 1, FORMATION_ERROR), error))
    out.append((PAYLOAD_ODOM, _odometry(t, truth.payload[k], (0.0, 0.0, 0.0, 1.0),
                                           truth.payload_velocity[k], 'payload')))
    state = FormationState(cable_tension=[float(v) for v in truth.tension[k]],
                           constraint_position=[float(v) for v in truth.g[k]],
                           constraint_velocity=[float(v) for v in truth.g_dot[k]])
    _stamp(state, t)
    out.append((FORMATION_STATE, state))
    gust = Vector3Stamped()
    _stamp(gust, t)
    gust.vector.x, gust.vector.y, gust.vector.z = (float(v) for v in truth.gust[k])
    out.append((PAYLOAD_GUST, gust))
    reference = TrackingReference()
    _stamp(reference, t)
    reference.position.x, reference.position.y, reference.position.z = (
        float(v) for v in truth.reference[k])
    out.append((REFERENCE_TOPIC, reference))
    return out


def make_bag(directory: Path, n: int, duration: float = 13.0, swing: float = 0.5,
             scenario: str | None = None) -> Truth:
    """Write a synthetic run of n UAVs to the bag `directory` (and summary.json naming
    `scenario`); the odometry of UAV 1 is written in reverse order (load_run sorts)."""
    truth = _truth(n, duration, swing)
    samples = [_messages(truth, k) for k in range(len(truth.t))]
    with BagWriter(directory) as bag:
        for topic, _ in samples[0]:
            bag.add_topic(topic, topic_type(topic))
        bag.add_topic('/chatter', 'std_msgs/msg/String')  # a foreign topic: ignored
        bag.write('/chatter', serialize_message(String(data='hello')), 0)
        for k, messages in enumerate(samples):
            for topic, msg in messages:
                j = len(samples) - 1 - k if topic == uav_topic(1, ODOM) else k
                if topic == uav_topic(1, ODOM):
                    msg = samples[j][0][1]
                bag.write(topic, serialize_message(msg), int(round(truth.t[j] * 1e9)) + 1)
    if scenario is not None:
        (directory / 'summary.json').write_text(json.dumps(
            {'sim': {'scenario': scenario, 'n_uavs': n}}))
    return truth


@pytest.fixture(scope='module')
def bags(tmp_path_factory) -> dict[str, tuple[Path, Truth]]:
    """A twin-lift-like bag (n = 2, summary naming twin_lift), a V of three (multi_lift) and a
    single lift without summary."""
    root = tmp_path_factory.mktemp('plotbags')
    out = {}
    for name, n, swing, scenario in (('twin', 2, 0.8, 'twin_lift'),
                                     ('multi', 3, 0.3, 'multi_lift'),
                                     ('single', 1, 0.5, None)):
        out[name] = (root / name, make_bag(root / name, n, swing=swing, scenario=scenario))
    return out


# -- load_run ------------------------------------------------------------------------------
def test_load_run_returns_what_was_written(bags):
    path, truth = bags['twin']
    run = load_run(path)
    T = len(truth.t)
    assert run.n_uavs == 2 and run.followers == [2]
    assert run.scenario_name == 'twin_lift' and run.label == 'twin_lift'
    np.testing.assert_allclose(run.t, truth.t, atol=1e-9)
    assert np.all(np.diff(run.t) > 0)  # written backwards, read sorted
    np.testing.assert_allclose(run.uav_positions(), truth.uavs, atol=1e-12)
    np.testing.assert_allclose(run.uav_euler(), truth.euler, atol=1e-12)
    np.testing.assert_allclose(run.payload_position(), truth.payload, atol=1e-12)
    np.testing.assert_allclose(run.payload_velocity(), truth.payload_velocity, atol=1e-12)
    np.testing.assert_allclose(run.payload_time, truth.t, atol=1e-9)
    np.testing.assert_allclose(run.tensions(), truth.tension, atol=1e-12)
    np.testing.assert_allclose(run.g(), truth.g, atol=1e-18)
    np.testing.assert_allclose(run.g_dot(), truth.g_dot, atol=1e-18)
    for i in (1, 2):
        np.testing.assert_allclose(run.rotor_speeds(i), truth.omega[i - 1], atol=1e-9)
        assert np.array_equal(run.saturated(i), truth.saturated[i - 1])
        np.testing.assert_allclose(run.thrust(i), truth.thrust[i - 1], atol=1e-12)
        np.testing.assert_allclose(run.attitude_setpoint(i), truth.euler[i - 1], atol=1e-12)
    np.testing.assert_allclose(run.thrusts(), truth.thrust, atol=1e-12)
    assert run.formation_errors(2).shape == (T, 3)
    np.testing.assert_allclose(run.formation_errors(2), truth.errors[0], atol=1e-12)
    np.testing.assert_allclose(run.gust_speed(), np.linalg.norm(truth.gust, axis=1),
                               atol=1e-12)
    np.testing.assert_allclose(run.reference_position(), truth.reference, atol=1e-12)
    assert run.duration == pytest.approx(truth.t[-1])
    assert not run.has('/chatter')


def test_missing_topic_is_a_clear_error(bags):
    run = load_run(bags['single'][0])
    assert run.n_uavs == 1 and run.followers == [] and run.scenario_name is None
    with pytest.raises(RunDataError, match='/uav2/formation_error'):
        run.formation_errors(2)


def test_rotor_limits_from_scenario_or_flags(bags):
    run = load_run(bags['twin'][0])
    scenario, note = bagdata.run_scenario(run)
    assert scenario is not None and scenario.name == 'twin_lift', note
    assert bagdata.rotor_limits(run, scenario, 1) == (0.0, OMEGA_MAX)
    assert bagdata.rotor_limits(run, None, 1) == (0.0, OMEGA_MAX)  # flagged rotors at max
    wrong, note = bagdata.run_scenario(run, 'multi_lift')
    assert wrong is None and '3 UAV' in note


def test_load_run_errors_name_the_path(tmp_path):
    with pytest.raises(FileNotFoundError, match='nowhere'):
        load_run(tmp_path / 'nowhere')
    (tmp_path / 'empty').mkdir()
    with pytest.raises(RunDataError, match='no metadata.yaml'):
        load_run(tmp_path / 'empty')
    broken = tmp_path / 'broken'
    broken.mkdir()
    (broken / 'metadata.yaml').write_text('rosbag2_bagfile_information: 7\n')
    with pytest.raises(RunDataError, match='broken'):
        load_run(broken)
    other = tmp_path / 'other'
    with BagWriter(other) as bag:
        bag.add_topic('/chatter', 'std_msgs/msg/String')
        bag.write('/chatter', serialize_message(String(data='x')), 1)
    with pytest.raises(RunDataError, match='no /uav1/odom'):
        load_run(other)


# -- plot ----------------------------------------------------------------------------------
def _pngs_ok(paths: list[Path]) -> None:
    for path in paths:
        data = path.read_bytes()
        assert data[:8] == PNG_MAGIC, path
        assert 15_000 < len(data) < 1_500_000, (path, len(data))


def _printed_paths(out: str) -> list[Path]:
    return [Path(line) for line in out.splitlines() if line.endswith(('.png', '.gif'))]


ALL_FIGURES = {'trajectories_3d', 'top_view', 'cable_constraints', 'cable_tensions',
               'formation_errors', 'attitude', 'thrust', 'rotor_speeds', 'thrust_margins',
               'payload_position', 'leader_tracking'}


def test_plot_writes_every_figure(bags, capsys):
    path, _ = bags['multi']
    assert plot_main([str(path)]) == 0
    written = _printed_paths(capsys.readouterr().out)
    assert {p.stem for p in written} == ALL_FIGURES
    assert all(p.parent == path / 'plots' for p in written)
    _pngs_ok(written)


def test_plot_single_lift_skips_formation_errors(bags, tmp_path, capsys):
    path, _ = bags['single']
    assert plot_main([str(path), '--out', str(tmp_path / 'figs')]) == 0
    captured = capsys.readouterr()
    written = _printed_paths(captured.out)
    assert {p.stem for p in written} == ALL_FIGURES - {'formation_errors'}
    assert 'skipped formation_errors' in captured.err
    assert 'no summary.json' in captured.err  # no scenario: said once, not a failure
    _pngs_ok(written)


def test_plot_missing_bag_is_exit_code_2_with_one_line(tmp_path, capsys):
    assert plot_main([str(tmp_path / 'nope')]) == 2
    captured = capsys.readouterr()
    assert captured.out == ''
    assert captured.err.splitlines() == [f'error: bag not found: {tmp_path / "nope"}']
    assert animate_main([str(tmp_path / 'nope')]) == 2
    assert compare_main([str(tmp_path / 'nope'), str(tmp_path / 'nope2')]) == 2


def test_bad_option_is_exit_code_2(bags, capsys):
    assert animate_main([str(bags['twin'][0]), '--fps', '-3']) == 2
    assert 'error:' in capsys.readouterr().err


# -- animate -------------------------------------------------------------------------------
def test_animate_writes_a_gif_of_the_expected_frames(bags, tmp_path, capsys):
    from PIL import Image
    path, truth = bags['multi']
    out = tmp_path / 'anim.gif'
    assert animate_main([str(path), '--out', str(out), '--fps', '5', '--speed', '2']) == 0
    assert _printed_paths(capsys.readouterr().out) == [out]
    data = out.read_bytes()
    assert data[:6] == b'GIF89a' and 20_000 < len(data) < 5_000_000
    with Image.open(out) as gif:
        expected = len(np.arange(0.0, truth.t[-1] + 1e-9, 2 / 5))
        assert gif.n_frames == expected
        assert gif.size == (560, 448)
        assert gif.info['duration'] == 200
        first = np.asarray(gif.convert('RGB'))
        gif.seek(gif.n_frames - 1)
        last = np.asarray(gif.convert('RGB'))
    assert np.any(first != last)  # the formation moved


def test_animate_mp4_without_ffmpeg_is_a_clear_error(bags, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr('shutil.which', lambda name: None)
    assert animate_main([str(bags['twin'][0]), '--out', str(tmp_path / 'a.mp4')]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and 'ffmpeg' in err[0] and 'a.mp4' in err[0]
    assert not (tmp_path / 'a.mp4').exists()
    assert animate_main([str(bags['twin'][0]), '--out', str(tmp_path / 'a.avi')]) == 2


# -- compare -------------------------------------------------------------------------------
def test_compare_twin_and_multi(bags, tmp_path, capsys):
    (a, truth_a), (b, truth_b) = bags['twin'], bags['multi']
    out = tmp_path / 'cmp'
    assert compare_main([str(a), str(b), '--out', str(out), '--labels', 'TL', 'ML']) == 0
    printed = capsys.readouterr().out
    written = _printed_paths(printed)
    assert {p.name for p in written} == {'compare_payload.png', 'compare_formation_error.png',
                                         'compare_leader_rotor_speed.png'}
    _pngs_ok(written)
    rows = {line[:34].strip(): line[34:].split() for line in printed.splitlines()}
    # the leader's mean rotor speed and its relative difference, from the synthetic truth
    mean_a, mean_b = truth_a.omega[0].mean(), truth_b.omega[0].mean()
    assert rows['leader mean rotor speed [rad/s]'] == [
        f'{mean_a:.1f}', f'{mean_b:.1f}', f'{(mean_b - mean_a) / mean_a * 100:+.2f}', '%']
    # mean |g_vc| per follower; UAV 3 only in B
    norm = [np.linalg.norm(e, axis=1).mean() for e in (truth_a.errors[0], *truth_b.errors)]
    assert rows['mean |g_vc| UAV 2 [m]'][:2] == [f'{norm[0]:.3f}', f'{norm[1]:.3f}']
    assert rows['mean |g_vc| UAV 3 [m]'] == ['-', f'{norm[2]:.3f}', '-']
    # the twin bag swings 0.8 m, the multi bag 0.3 m about the UAVs' centroid
    swing = [float(v) for v in rows['payload swing, max [m]'][:2]]
    assert swing[0] == pytest.approx(0.8, abs=0.1)
    assert swing[1] == pytest.approx(0.3, abs=0.05)


def test_plot_draws_the_ropes_of_an_elastic_run_only(bags, tmp_path, capsys):
    """A run whose summary gives rope stretch (cable_model: elastic) gets rope_stretch.png;
    the rigid twin-lift's bag skips it, saying why."""
    path, _ = bags['twin']
    assert plot_main([str(path), '--out', str(tmp_path / 'rigid')]) == 0
    assert 'skipped rope_stretch: no elastic ropes' in capsys.readouterr().err
    elastic = tmp_path / 'elastic'
    make_bag(elastic, 2, scenario='twin_lift_elastic')
    summary = json.loads((elastic / 'summary.json').read_text())
    summary['sim'].update(max_stretch=[4e-4, 3e-4], peak_tension=[6.0, 5.0])
    (elastic / 'summary.json').write_text(json.dumps(summary))
    assert plot_main([str(elastic), '--out', str(tmp_path / 'figs')]) == 0
    written = _printed_paths(capsys.readouterr().out)
    assert {p.stem for p in written} == ALL_FIGURES | {'rope_stretch'}
    _pngs_ok(written)


def test_plot_draws_the_clearance_of_a_run_with_a_world(tmp_path, capsys):
    """A run whose summary gives clearances (a `world:` section) gets clearance.png, the
    obstacles drawn in the views; the twin-lift's bag skips it, saying why. The series is the
    tick's measure at given states: beside window's wall, checked by hand."""
    from multilift_sim.statistics.clearance import clearance_series
    from multilift_sim.scenario import load
    world = tmp_path / 'world'
    make_bag(world, 2, scenario='window')
    summary = json.loads((world / 'summary.json').read_text())
    summary['sim'].update(clearance={}, least_clearance=None, contact=None)
    (world / 'summary.json').write_text(json.dumps(summary))
    assert plot_main([str(world), '--out', str(tmp_path / 'figs')]) == 0
    written = _printed_paths(capsys.readouterr().out)
    assert {p.stem for p in written} == ALL_FIGURES | {'clearance'}
    _pngs_ok(written)
    make_bag(tmp_path / 'twin', 2, scenario='twin_lift')
    assert plot_main([str(tmp_path / 'twin'), '--out', str(tmp_path / 'twin_figs')]) == 0
    assert 'skipped clearance: no clearances' in capsys.readouterr().err
    # uav1 at (1, 0, 1.5), 0.475 m before the wall's face and 0.15 m off the window's left
    # edge (wall_left): sqrt(0.475^2 + 0.15^2) less its radius 0.07; uav2 0.5 m behind it
    scenario = load('window')
    level = np.tile([1.0, 0.0, 0.0, 0.0], (2, 1, 1))
    series = clearance_series(scenario, np.array([[[1.0, 0.0, 1.5]], [[0.5, 0.0, 1.5]]]),
                              level, np.array([[0.75, 0.0, 1.067]]))
    assert series[0, 0] == pytest.approx(math.hypot(0.475, 0.15) - 0.07, abs=1e-12)
    assert series[0, 3] == pytest.approx(0.5 - 0.14, abs=1e-12)  # UAV - UAV
