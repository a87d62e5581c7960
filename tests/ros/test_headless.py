"""`run --headless` computes what the ROS stack computes: same bag topics, same trajectories to
rounding. This is what proves the nodes thin."""
from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from conftest import ROOT, next_domain
from multilift_tools.bagdata import load_run

MULTILIFT = str(ROOT / 'scripts' / 'multilift')


@pytest.fixture(scope='module')
def twin_bags(tmp_path_factory):
    root = tmp_path_factory.mktemp('headless')
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    for mode in ('ros', 'headless'):
        args = [MULTILIFT, 'run', 'twin_lift', '--duration', '6', '--bag', str(root / mode)]
        if mode == 'headless':
            args.append('--headless')
        out = subprocess.run(args, capture_output=True, text=True, timeout=600, env=env)
        assert out.returncode == 0, out.stderr[-2000:]
    return root / 'ros', root / 'headless'


def test_same_topics_types_and_counts(twin_bags):
    counts = []
    for bag in twin_bags:
        with AnyReader([bag]) as reader:
            counts.append({c.topic: (c.msgtype, c.msgcount) for c in reader.connections})
    assert counts[0] == counts[1]
    # the controllers answer the 600 states before t_max, not the state at t_max (601 ticks)
    assert counts[0]['/uav2/formation_error'] == ('multilift_msgs/msg/VirtualConstraintError', 600)
    assert counts[0]['/uav2/odom'] == ('nav_msgs/msg/Odometry', 601)
    assert counts[0]['/formation/snapshot'][1] == 600


def test_same_trajectories_to_rounding(twin_bags):
    ros, headless = (load_run(b) for b in twin_bags)
    assert np.array_equal(ros.t, headless.t)
    assert np.abs(ros.uav_positions() - headless.uav_positions()).max() < 1e-9
    assert np.abs(ros.payload_position() - headless.payload_position()).max() < 1e-9
    for i in (1, 2):
        assert np.abs(ros.rotor_speeds(i) - headless.rotor_speeds(i)).max() < 1e-6
    assert np.abs(ros.tensions() - headless.tensions()).max() < 1e-6
    assert np.abs(ros.formation_errors(2) - headless.formation_errors(2)).max() < 1e-9
    # and the run is not trivial: the formation moved
    assert np.ptp(headless.uav_positions()[0][:, 2]) > 1.0


def test_same_run_statistics(twin_bags):
    """`run` and `run --headless` leave the same summary (one statistics module)."""
    import json
    ros, headless = (json.loads((b / 'summary.json').read_text()) for b in twin_bags)
    assert set(ros) == set(headless) == {'sim', 'leader', 'follower2'}
    for part in ('leader', 'follower2'):
        assert ros[part].keys() == headless[part].keys()
        for key, value in ros[part].items():
            assert headless[part][key] == pytest.approx(value, rel=1e-6, abs=1e-9), key
    assert headless['leader']['answered_states'] == 600  # the states before t_max
    for key in ('max_abs_constraint', 'min_tension', 'max_tension', 'max_payload_swing',
                'rms_payload_swing', 'simulated_time', 'max_rotor_speed', 'saturated_time'):
        assert headless['sim'][key] == pytest.approx(ros['sim'][key], rel=1e-6, abs=1e-9), key


def test_headless_bad_scenario_is_exit_2(tmp_path):
    out = subprocess.run([MULTILIFT, 'run', 'nope', '--headless'], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 2 and 'unknown scenario' in out.stderr


def test_headless_bags_are_byte_identical(tmp_path):
    """The headless bag packs its CDR with zeroed padding and writes no wall-clock time: two
    runs of a scenario give the same bytes (metadata.yaml included)."""
    import dataclasses

    from multilift_sim import scenario as scenario_io
    from multilift_tools.headless_bag import record_headless
    scenario = scenario_io.load('twin_lift')
    scenario = dataclasses.replace(scenario, simulation=dataclasses.replace(
        scenario.simulation, duration=0.5))
    for run in ('a', 'b'):
        record_headless(scenario, tmp_path / run / 'bag')
    first, second = tmp_path / 'a' / 'bag', tmp_path / 'b' / 'bag'
    assert sorted(p.name for p in first.iterdir()) == ['bag_0.mcap', 'metadata.yaml']
    for name in ('bag_0.mcap', 'metadata.yaml'):
        assert (first / name).read_bytes() == (second / name).read_bytes(), name
    with AnyReader([first]) as reader:
        assert {c.topic: c.msgcount for c in reader.connections}['/formation/state'] == 51


def test_tf_is_the_odometry_at_every_tick(twin_bags):
    """/tf: world -> uav{i}/base_link and world -> payload at every state tick, the poses of
    the odometry, in the ROS bag and the headless bag alike."""
    for bag in twin_bags:
        poses: dict[tuple[str, int], tuple] = {}
        frames: dict[tuple[str, int], tuple] = {}
        with AnyReader([bag]) as reader:
            wanted = [c for c in reader.connections
                      if c.topic in ('/tf', '/uav1/odom', '/uav2/odom', '/payload/odom')]
            for connection, _, raw in reader.messages(connections=wanted):
                msg = reader.deserialize(raw, connection.msgtype)
                if connection.topic == '/tf':
                    for tf in msg.transforms:
                        t = tf.header.stamp.sec * 10**9 + tf.header.stamp.nanosec
                        assert tf.header.frame_id == 'world'
                        p, q = tf.transform.translation, tf.transform.rotation
                        frames[tf.child_frame_id, t] = (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
                else:
                    t = msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec
                    p, q = msg.pose.pose.position, msg.pose.pose.orientation
                    poses[msg.child_frame_id, t] = (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
        assert len(poses) == 3 * 601
        assert frames == poses


def _moved_earlier(tmp_path, name: str, events: list[dict]):
    """Scenario `name` with `events` instead of its own, as a YAML file in tmp_path."""
    import yaml

    from conftest import SCENARIOS
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['events'] = events
    path = tmp_path / f'{name}_early.yaml'
    path.write_text(yaml.safe_dump(data))
    return path


def test_events_fly_and_are_recorded_alike_through_ros_and_headless(tmp_path):
    """`v3_uav_loss` with its release at 1.5 s, after a rotor's fault and a silent controller
    (docs/events.md), through the ROS nodes and headless: the same /formation/events messages
    (one per event, stamped with the first state that shows it), the same states and formation
    errors after them (the leader's mixer reallocated, the followers' new offsets), and the
    summary names them."""
    import json

    scenario = _moved_earlier(tmp_path, 'v3_uav_loss', [
        {'time': 0.503, 'type': 'rotor_effectiveness', 'uav': 1, 'rotor': 2,
         'effectiveness': 0.9},
        {'time': 1.0, 'type': 'controller_silence', 'uav': 2, 'duration': 0.3},
        {'time': 1.5, 'type': 'cable_release', 'uav': 3}])
    ros_run, headless_run = _ros_and_headless(tmp_path, str(scenario), '3.0',
                                              'event at 1.5 s   uav3 releases its cable')
    events, summaries = [], []
    for mode in ('ros', 'headless'):
        with AnyReader([tmp_path / mode]) as reader:
            connections = [c for c in reader.connections if c.topic == '/formation/events']
            events.append([reader.deserialize(raw, c.msgtype)
                           for c, _, raw in reader.messages(connections)])
        summaries.append(json.loads((tmp_path / mode / 'summary.json').read_text()))
    ros, headless = events
    assert len(ros) == len(headless) == 3
    for a, b in zip(ros, headless):
        assert (a.header.stamp.sec, a.header.stamp.nanosec, a.type, a.uav, a.rotor, a.value,
                a.scheduled_time, a.description) == (
            b.header.stamp.sec, b.header.stamp.nanosec, b.type, b.uav, b.rotor, b.value,
            b.scheduled_time, b.description)
    first, silence, release = headless
    assert (first.header.stamp.sec, first.header.stamp.nanosec) == (0, 510_000_000)  # tick 51
    assert (first.type, first.uav, first.rotor, first.value) == ('rotor_effectiveness', 1, 2,
                                                                   0.9)
    assert (silence.type, silence.uav, silence.value) == ('controller_silence', 2, 0.3)
    assert (release.type, release.uav, release.description) == ('cable_release', 3,
                                                                'uav3 releases its cable')
    assert summaries[0]['sim']['events'] == summaries[1]['sim']['events']
    assert [e['type'] for e in summaries[1]['sim']['events']] == [
        'rotor_effectiveness', 'controller_silence', 'cable_release']
    for i in (2, 3):
        assert np.abs(ros_run.formation_errors(i) - headless_run.formation_errors(i)).max() < 1e-9
    assert not headless_run.taut()[-1, 2] and headless_run.taut()[-1, :2].all()


def _ros_and_headless(tmp_path, scenario: str, duration: str, says: str):
    """`run SCENARIO --duration D` through the ROS nodes and headless, each saying `says` in
    its summary: (ros, headless) runs, their UAVs in the same places to rounding."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    for mode in ('ros', 'headless'):
        args = [MULTILIFT, 'run', scenario, '--duration', duration, '--bag',
                str(tmp_path / mode)] + (['--headless'] if mode == 'headless' else [])
        out = subprocess.run(args, capture_output=True, text=True, timeout=600, env=env)
        assert out.returncode == 0, out.stderr[-2000:]
        assert says in out.stdout
    ros, headless = (load_run(tmp_path / mode) for mode in ('ros', 'headless'))
    assert np.abs(ros.uav_positions() - headless.uav_positions()).max() < 1e-9
    return ros, headless


def test_hexa_rotor_failure_through_ros_is_the_headless_run(tmp_path):
    """`hexa_rotor_failure` with its fault at 1 s: the leader's controller node reallocates
    over the other five rotors at that tick (multilift_control.faults), as the headless run
    does (the whole mission headless: tests/unit/test_faults.py)."""
    scenario = _moved_earlier(tmp_path, 'hexa_rotor_failure', [
        {'time': 1.0, 'type': 'rotor_effectiveness', 'uav': 1, 'rotor': 1,
         'effectiveness': 0.0}])
    _, headless = _ros_and_headless(tmp_path, str(scenario), '2.5',
                                    'event at 1 s   uav1 rotor 1 at 0 % of its thrust')
    speeds = headless.rotor_speeds(1)
    after = headless.topic('/uav1/rotor_cmd').t >= 1.0
    assert (speeds[after, 0] == 0.0).all() and (speeds[~after, 0] > 1000.0).all()


def test_sensors_fly_alike_through_ros_and_headless(tmp_path):
    """`twin_lift_sensors` (docs/sensors.md) through the ROS nodes and headless: the controllers
    receive the same measurements (the snapshot, every /uav{i}/measured_odom) and fly the same
    states to rounding; the measurements are not the state; the summary records the seed."""
    import json

    ros_run, headless_run = _ros_and_headless(tmp_path, 'twin_lift_sensors', '2.0',
                                              'seeds            sensors 1')
    for i in (1, 2):
        ros, headless = (run.topic(f'/uav{i}/measured_odom') for run in (ros_run, headless_run))
        assert len(ros.t) == len(headless.t) == 201
        assert np.abs(ros['position'] - headless['position']).max() < 1e-9
        state = headless_run.topic(f'/uav{i}/odom')
        error = headless['position'] - state['position']
        assert 1e-3 < np.abs(error).max() < 0.1
    for mode in ('ros', 'headless'):
        summary = json.loads((tmp_path / mode / 'summary.json').read_text())
        assert summary['sim']['seeds'] == {'sensors': 1}


def test_a_rigid_payload_flies_alike_through_ros_and_headless(tmp_path):
    """`box_lift` (docs/rigid_payload.md): the simulator node flies the box's attitude as the
    headless run does (the same UAV places to rounding) and publishes it on /payload/odom."""
    ros_run, headless_run = _ros_and_headless(tmp_path, 'box_lift', '3.0', 'box_lift')
    with AnyReader([tmp_path / 'ros']) as reader:
        odom = [c for c in reader.connections if c.topic == '/payload/odom']
        tilt = [reader.deserialize(raw, c.msgtype).pose.pose.orientation.w
                for c, _, raw in reader.messages(odom)]
    assert len(tilt) == 301 and min(tilt) < 1.0 - 1e-6
    assert np.abs(ros_run.payload_position() - headless_run.payload_position()).max() < 1e-9


def test_the_payload_feedback_flies_alike_through_ros_and_headless(tmp_path):
    """`twin_lift` with `control.payload_feedback` (the corners shaped, the leader's swing
    feedback on the payload's state from /formation/snapshot): the leader node flies what the
    headless run flies, through the released swing and the first corner."""
    import yaml

    from conftest import SCENARIOS
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    data['control']['payload_feedback'] = {'input_shaping': 'zvdd', 'swing_stiffness': 0.25,
                                           'swing_damping': -0.2, 'acceleration_limit': 0.15}
    path = tmp_path / 'twin_lift_feedback.yaml'
    path.write_text(yaml.safe_dump(data))
    _, headless = _ros_and_headless(tmp_path, str(path), '12.0',
                                    'payload feedback zvdd shaping of the corners')
    seed = tmp_path / 'seed'
    env = dict(os.environ, ROS_DOMAIN_ID=str(next_domain()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    out = subprocess.run([MULTILIFT, 'run', 'twin_lift', '--duration', '12.0', '--headless',
                          '--bag', str(seed)], capture_output=True, text=True, timeout=600,
                         env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    moved = np.abs(load_run(seed).uav_positions() - headless.uav_positions()).max()
    assert moved > 1e-2  # the feedback acted
