"""What both controller nodes read from the simulator: `/formation/snapshot` -> model types."""
from __future__ import annotations

import numpy as np
from multilift_msgs.msg import FormationSnapshot

from multilift_control.cascade import UavState
from multilift_sim.ros import messages
from multilift_sim.ros.common import ns_from_stamp
from multilift_sim.topics import FORMATION_SNAPSHOT as SNAPSHOT_TOPIC  # noqa: F401 (nodes)


def snapshot_input(msg: FormationSnapshot) -> tuple[int, list[UavState], list[np.ndarray]]:
    """(t [ns], every UAV's state at t from the leader on, the rotor speeds applied up to t
    per UAV (empty at t = 0))."""
    positions, velocities, euler, rates, previous = messages.snapshot_arrays(msg)
    states = [UavState(*row) for row in zip(positions, velocities, euler, rates)]
    return ns_from_stamp(msg.header.stamp), states, previous
