"""A cable let go: the formation takes new offsets (`faults.release_targets`)."""
from __future__ import annotations

from multilift_sim.physics.layout import EVENT_UAV

KIND = 'cable_release'


def lets_go(row) -> int:
    """The UAV (from 0) whose cable let go."""
    return int(row[EVENT_UAV])
