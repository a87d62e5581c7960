"""Bags without rclpy or rosbag2: rosbag2 (Jazzy) directories with MCAP storage, as `ros2 bag
record -s mcap` writes them.

    mcap_writer    `BagWriter` (a bag written tick by tick or a block of ticks at a time,
                   readable up to its last chunk if the process dies) and `recover` (a killed
                   bag's MCAP and metadata rebuilt)
    mcap_records   the MCAP file below mcap's Writer: unbuffered, Message records packed in one
                   call each, or a block of ticks' records at once with numpy (`write_block`)
    metadata_yaml  YAML as rosbag2 (yaml-cpp) writes it: metadata.yaml, offered QoS profiles
    recording      what the recorder decides without ROS: topic specs, which topics, log time

The writer's names are imported from here (`from multilift_sim.bag import BagWriter`).
"""
from multilift_sim.bag.mcap_writer import (TORN_RECORD_ERRORS, BagError,  # noqa: F401
                                           BagWriter, Column, recover)
