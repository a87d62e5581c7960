"""A ball (`type: sphere`): `radius` [m] about `center`."""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import OBSTACLE_CENTER, OBSTACLE_HALF

NAME = 'sphere'
KEYS = ('radius',)


def parse(o):
    """(half extent (radius, radius, radius) [m], bounding radius [m])."""
    radius = o.positive('radius')
    return np.full(3, radius), radius


def outline(half):
    return 'sphere', tuple(2.0 * h for h in half)


@jit
def distance(row, x, y, z, out):
    """The signed distance [m] from (x, y, z), world, to the ball of `row`, into out[0]."""
    dx, dy = x - row[OBSTACLE_CENTER], y - row[OBSTACLE_CENTER + 1]
    dz = z - row[OBSTACLE_CENTER + 2]
    out[0] = math.sqrt(dx * dx + dy * dy + dz * dz) - row[OBSTACLE_HALF]
