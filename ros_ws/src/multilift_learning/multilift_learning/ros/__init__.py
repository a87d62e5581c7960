"""The ROS adapter of the learning environments: a policy flying a run (`policy_node`)."""
