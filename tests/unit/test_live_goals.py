"""Live goals and paths (issue 34 item 2), without ROS: the leader holds its mission's start,
a goal is flown rest to rest within mission.max_speed and max_acceleration (checked on the
reference the compiled law gives, differentiated numerically), a path passes its points at
their times, a new target replaces the old from where the reference is, the payload's offset
is kept; bad targets and limits are refused."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from multilift_control.controllers import LeaderController, tracked_offset
from multilift_control.live_goals import LiveMission, LiveTarget, check_target
from multilift_sim import scenario as scenario_io


def _live(name: str = 'single_lift', **mission):
    scenario = scenario_io.load(name)
    if mission:
        scenario = dataclasses.replace(scenario, mission=dataclasses.replace(scenario.mission,
                                                                             **mission))
    leader = LeaderController(scenario)
    start = leader.path(0.0).position.copy()
    return scenario, leader, LiveMission(leader, scenario), start


def _goal(stamp, point, yaw=np.nan):
    return LiveTarget(stamp, np.array([point], dtype=float), np.array([yaw]))


def _samples(leader, t0, t1, dt=1e-3):
    times = np.arange(t0, t1, dt)
    positions = np.array([leader.path(t).position for t in times])
    return times, positions


def test_the_leader_holds_its_start_until_a_goal_then_flies_it_within_the_limits():
    _, leader, live, start = _live(max_speed=0.8, max_acceleration=0.4)
    for t in (0.0, 3.0, 50.0):
        assert np.array_equal(leader.path(t).position, start)
    goal = start + np.array([3.0, -1.0, 0.5])
    assert live.offer(_goal(2.0, goal, 0.5)) is None
    assert live.apply(1.99) == [] and np.array_equal(leader.path(2.5).position, start)
    assert len(live.apply(2.0)) == 1
    times, positions = _samples(leader, 2.0, 20.0)
    speed = np.linalg.norm(np.gradient(positions, times, axis=0), axis=1)
    acceleration = np.linalg.norm(np.gradient(np.gradient(positions, times, axis=0), times,
                                              axis=0), axis=1)
    assert speed.max() <= 0.8 * 1.001 and acceleration.max() <= 0.4 * 1.01
    # the shortest such move: one of the limits is reached
    assert speed.max() > 0.8 * 0.99 or acceleration.max() > 0.4 * 0.98
    np.testing.assert_allclose(positions[0], start, atol=1e-12)
    np.testing.assert_allclose(leader.path(30.0).position, goal, atol=1e-9)
    assert leader.path(30.0).yaw == pytest.approx(0.5)
    assert np.linalg.norm(leader.path(30.0).velocity) < 1e-9


def test_a_path_is_followed_in_time_and_a_new_target_replaces_the_old_from_where_it_is():
    _, leader, live, start = _live()
    points = start + np.array([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]])
    path = LiveTarget(1.0, points, np.full(3, np.nan), np.array([4.0, 7.0, 10.0]))
    assert live.offer(path) is None
    live.apply(1.0)
    for point, t in zip(points, (4.0, 7.0, 10.0)):
        np.testing.assert_allclose(leader.path(t).position, point, atol=1e-9)
    where = leader.path(5.5).position.copy()
    goal = start + np.array([-1.0, 0.0, 0.0])
    live.offer(_goal(5.5, goal))
    live.apply(5.5)
    np.testing.assert_allclose(leader.path(5.5).position, where, atol=1e-12)
    np.testing.assert_allclose(leader.path(40.0).position, goal, atol=1e-9)


def test_a_late_target_starts_at_the_tick_it_is_taken_and_a_past_path_is_dropped():
    _, leader, live, start = _live()
    live.offer(_goal(1.0, start + [1.0, 0.0, 0.0]))
    [taken] = live.apply(3.0)
    assert taken.stamp == 1.0 and live.applied[-1].stamp == 3.0
    np.testing.assert_allclose(leader.path(3.0).position, start, atol=1e-12)
    assert leader.path(3.5).position[0] > start[0]
    before = leader.path(100.0).position.copy()
    live.offer(LiveTarget(4.0, np.array([start]), np.array([np.nan]), np.array([5.0])))
    live.apply(6.0)  # every pose of it in the past: nothing to follow
    np.testing.assert_allclose(leader.path(100.0).position, before, atol=1e-12)


def test_with_the_payload_tracked_the_leader_flies_the_goal_at_its_offset():
    scenario, leader, live, _ = _live('twin_lift', tracks='payload')
    offset = tracked_offset(scenario)
    goal = np.array([2.0, 1.0, -3.0])
    live.offer(_goal(0.0, goal))
    live.apply(0.0)
    np.testing.assert_allclose(leader.path(60.0).position, goal + offset, atol=1e-9)


@pytest.mark.parametrize('target, why', [
    (LiveTarget(1.0, np.array([[0.0, np.nan, 0.0]]), np.array([0.0])), 'finite'),
    (LiveTarget(1.0, np.zeros((2, 3)), np.zeros(2), np.array([3.0, 2.0])), 'increase'),
    (LiveTarget(5.0, np.zeros((1, 3)), np.zeros(1), np.array([4.0])), 'increase'),
])
def test_a_target_that_cannot_be_flown_says_why(target, why):
    assert why in check_target(target)


@pytest.mark.parametrize('key', ['max_speed', 'max_acceleration'])
def test_live_limits_must_be_positive(tmp_path, key):
    import yaml
    data = yaml.safe_load(scenario_io.resolve('single_lift').read_text())
    data['mission'][key] = 0.0
    path = tmp_path / 'bad.yaml'
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(scenario_io.ScenarioError, match=f'mission.{key}.*must be > 0'):
        scenario_io.load(str(path))
