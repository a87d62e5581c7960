"""multilift_sim.topics: the table of a run's topics against README's ROS interface table."""
from __future__ import annotations

from multilift_sim import topics

README_TWIN = {  # README.md, "ROS interface", for n = 2
    '/clock': 'rosgraph_msgs/msg/Clock', '/payload/odom': 'nav_msgs/msg/Odometry',
    '/payload/gust': 'geometry_msgs/msg/Vector3Stamped',
    '/formation/state': 'multilift_msgs/msg/FormationState',
    '/formation/snapshot': 'multilift_msgs/msg/FormationSnapshot',
    '/visualization/markers': 'visualization_msgs/msg/MarkerArray',
    '/tf': 'tf2_msgs/msg/TFMessage',
    '/uav1/reference': 'multilift_msgs/msg/TrackingReference',
    '/uav1/odom': 'nav_msgs/msg/Odometry', '/uav2/odom': 'nav_msgs/msg/Odometry',
    '/uav1/rotor_cmd': 'multilift_msgs/msg/RotorCommand',
    '/uav2/rotor_cmd': 'multilift_msgs/msg/RotorCommand',
    '/uav1/attitude_setpoint': 'multilift_msgs/msg/AttitudeSetpoint',
    '/uav2/attitude_setpoint': 'multilift_msgs/msg/AttitudeSetpoint',
    '/uav2/formation_error': 'multilift_msgs/msg/VirtualConstraintError',
}


def test_run_topics_of_a_twin_lift_are_the_readme_table():
    listed = topics.run_topics(2)
    assert len(listed) == len(dict(listed))  # no topic twice
    assert dict(listed) == README_TWIN
    # a scenario with events: /formation/events too
    assert dict(topics.run_topics(2, events=True)) == {
        **README_TWIN, '/formation/events': 'multilift_msgs/msg/FormationEvent'}


def test_run_topics_grow_by_four_per_follower_and_three_for_the_leader():
    assert len(topics.run_topics(1)) == 8 + 3
    assert len(topics.run_topics(5)) == 8 + 3 + 4 * 4
    assert '/uav1/formation_error' not in dict(topics.run_topics(3))


def test_every_run_topic_has_its_type_and_others_none():
    for name, kind in topics.run_topics(3, events=True):
        assert topics.topic_type(name) == kind
    for name in ('/chatter', '/uav0/odom', '/uav1/odom/x', '/uav1/cmd', 'uav1/odom'):
        assert topics.topic_type(name) is None


def test_parse_uav_topic_inverts_uav_topic():
    assert topics.parse_uav_topic(topics.uav_topic(12, topics.ROTOR_CMD)) == (12, 'rotor_cmd')
    assert topics.parse_uav_topic('/payload/odom') is None
    assert topics.parse_uav_topic('/uav01/odom') is None
