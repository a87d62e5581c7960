"""The payload types a scenario can carry (`payload.type`, issue 20): the one registry, which
scenario validation, the docs and the markers read. World frame (z up), SI units.

- `point`: the seed's point mass on cables from the UAVs' centres of mass (the default).
- `rigid_body`: a body with mass, principal inertia J_p and one attach point b_i per cable in
  its own frame (physics.rigid_payload). Its `shape` (SHAPES) sizes the drawing and, unless
  `inertia` is given, gives J_p as the uniform solid's.
"""
from __future__ import annotations

import math

PAYLOAD_TYPES = ('point', 'rigid_body')

# a rigid body's shapes: name -> what `size` lists [m]
SHAPES = {'box': 'its edges along the payload frame x, y, z',
          'cylinder': 'its length along x and its radius'}
SHAPE_SIZES = {'box': 3, 'cylinder': 2}


def solid_inertia(shape: str, mass: float, size: tuple[float, ...]) -> tuple[float, float, float]:
    """Principal moments [kg m^2] of the uniform solid `shape` of `mass` [kg] and `size` [m],
    about its centre, along the payload frame's axes."""
    if shape == 'box':
        a, b, c = size
        return (mass / 12.0 * (b * b + c * c), mass / 12.0 * (a * a + c * c),
                mass / 12.0 * (a * a + b * b))
    if shape == 'cylinder':
        length, radius = size
        across = mass / 12.0 * (3.0 * radius * radius + length * length)
        return (0.5 * mass * radius * radius, across, across)
    raise ValueError(f'unknown payload shape {shape!r} (known: {", ".join(SHAPES)})')


def is_rigid_body_inertia(inertia: tuple[float, float, float]) -> bool:
    """Whether principal moments can be a rigid body's: all > 0 and each at most the sum of
    the other two (the triangle inequality of a mass distribution)."""
    a, b, c = inertia
    return (min(inertia) > 0 and all(math.isfinite(v) for v in inertia)
            and a <= b + c and b <= a + c and c <= a + b)
