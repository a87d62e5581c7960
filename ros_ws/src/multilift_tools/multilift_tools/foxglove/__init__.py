"""`multilift foxglove`: the live ROS graph over the Foxglove WebSocket protocol, and a Foxglove
layout for a scenario.

    command       the command line (`foxglove_main`)
    bridge        the node: topics to channels, their QoS, time base and drops
    server        the Foxglove WebSocket protocol server (asyncio, a thread of its own)
    graph_events  a thread called back on every change of the ROS graph (rcl, ctypes)
    stamps        a message's own time from its CDR bytes
    layout        a Foxglove layout for any scenario (`--layout FILE SCENARIO`)
"""
