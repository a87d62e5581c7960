"""An upright cylinder (`type: cylinder`): `radius` and `height` [m], its axis along world z
through `center` (the middle of its height). Its signed distance is the exact one."""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import OBSTACLE_CENTER, OBSTACLE_HALF

NAME = 'cylinder'
KEYS = ('radius', 'height')


def parse(o):
    """(half extent (radius, radius, height / 2) [m], bounding radius [m])."""
    radius, height = o.positive('radius'), o.positive('height')
    return np.array([radius, radius, height / 2.0]), math.hypot(radius, height / 2.0)


def outline(half):
    return 'cylinder', (2.0 * half[0], 2.0 * half[1], 2.0 * half[2])


@jit
def distance(row, x, y, z, out):
    """The signed distance [m] from (x, y, z), world, to the cylinder of `row`, into out[0]."""
    dx, dy = x - row[OBSTACLE_CENTER], y - row[OBSTACLE_CENTER + 1]
    radial = math.sqrt(dx * dx + dy * dy) - row[OBSTACLE_HALF]
    axial = abs(z - row[OBSTACLE_CENTER + 2]) - row[OBSTACLE_HALF + 2]
    # (sqrt, not hypot: numba's hypot and CPython's differ in the last bit)
    outside = math.sqrt(max(radial, 0.0) ** 2 + max(axial, 0.0) ** 2)
    out[0] = outside + min(max(radial, axial), 0.0)
