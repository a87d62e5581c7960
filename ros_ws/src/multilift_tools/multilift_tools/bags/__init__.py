"""`multilift bag info|play|reindex DIR`: what `ros2 bag info|play|reindex` do, for our bags
(rosbag2 directories with one MCAP file).

    command  the command line (`bag_main`)
    summary  a bag's summary, read from metadata.yaml or its MCAP, and printed as `ros2 bag info`
    play     publishing a bag's messages with their recorded timing (`BagPlayer`)
    reindex  rebuilding the MCAP summary and metadata.yaml of a bag whose recorder was killed
"""
