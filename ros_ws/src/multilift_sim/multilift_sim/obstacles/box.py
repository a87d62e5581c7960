"""A box (`type: box`): `size` [m] (its full extent along its own x, y, z; z stays world z,
`yaw` turns it about its centre). Its signed distance is the exact one of a box (outside: the
distance to its nearest point; inside: minus the distance to its nearest face)."""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import OBSTACLE_CENTER, OBSTACLE_COS_YAW, OBSTACLE_HALF, \
    OBSTACLE_SIN_YAW

NAME = 'box'
KEYS = ('size',)


def parse(o):
    """(half extent (3,) [m], bounding radius [m]) of `size: [sx, sy, sz]` (each > 0)."""
    half = np.array(o.vector('size', check=lambda v: v > 0, rule='must be > 0')) / 2.0
    return half, float(np.linalg.norm(half))


def outline(half):
    return 'cube', tuple(2.0 * h for h in half)


@jit
def local_point(row, x, y, z):
    """(x, y, z) [m], world, in the obstacle's own frame: from its centre, turned by -yaw."""
    dx, dy = x - row[OBSTACLE_CENTER], y - row[OBSTACLE_CENTER + 1]
    c, s = row[OBSTACLE_COS_YAW], row[OBSTACLE_SIN_YAW]
    return c * dx + s * dy, -s * dx + c * dy, z - row[OBSTACLE_CENTER + 2]


@jit
def distance(row, x, y, z, out):
    """The signed distance [m] from (x, y, z), world, to the box of `row`, into out[0]."""
    lx, ly, lz = local_point(row, x, y, z)
    qx = abs(lx) - row[OBSTACLE_HALF]
    qy = abs(ly) - row[OBSTACLE_HALF + 1]
    qz = abs(lz) - row[OBSTACLE_HALF + 2]
    ox, oy, oz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
    out[0] = math.sqrt(ox * ox + oy * oy + oz * oz) + min(max(qx, max(qy, qz)), 0.0)
