"""Cables that pull but never push (`cable_model: slack`, not in the seed): the rigid cable
while taut, free while slack, snapping taut with an inelastic impulse (multilift_sim.slack,
physics.slack_cables; RotorTM's hybrid model)."""
from __future__ import annotations

from multilift_sim.cables.rigid import check, parse_cable, parse_uav_cable  # noqa: F401

NAME = 'slack'
NEEDS = frozenset({'slack'})
RELEASE_LIMIT_DEG = 180.0  # the payload may start above its UAV: it falls and snaps taut
KEEPS_LENGTH = True
SLACKENS = True
REELS = False  # a reeled cable that snaps taut: not modelled
