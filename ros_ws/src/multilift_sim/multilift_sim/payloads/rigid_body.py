"""`payload.type: rigid_body` (issue 20): a body with mass, principal inertia J_p and one
attach point b_i per cable in its own frame (physics.rigid_payload; docs/rigid_payload.md). Its
`shape` (SHAPES) sizes the drawing and, unless `inertia` is given, gives J_p as the uniform
solid's. World frame (z up), SI units.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

NAME = 'rigid_body'
NEEDS = frozenset({'rigid_body'})
MIN_UAVS = 2  # one cable cannot hold a body's attitude

# a rigid body's shapes: name -> what `size` lists [m]
SHAPES = {'box': 'its edges along the payload frame x, y, z',
          'cylinder': 'its length along x and its radius'}
SHAPE_SIZES = {'box': 3, 'cylinder': 2}

# how far outside its shape an attach point may lie: the larger of ATTACH_MARGIN [m] and
# ATTACH_MARGIN_SHARE of the shape's largest dimension (a cable tied around an edge)
ATTACH_MARGIN = 1e-3
ATTACH_MARGIN_SHARE = 0.01


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


def shape_extent(shape: str, size: tuple[float, ...]) -> str:
    """The shape's region in words, payload frame [m] (an error message's rule)."""
    if shape == 'box':
        a, b, c = (v / 2.0 for v in size)
        return f'the box |x| <= {a:g}, |y| <= {b:g}, |z| <= {c:g}'
    if shape == 'cylinder':
        length, radius = size
        return f'the cylinder |x| <= {length / 2.0:g}, sqrt(y^2 + z^2) <= {radius:g}'
    raise ValueError(f'unknown payload shape {shape!r} (known: {", ".join(SHAPES)})')


def attach_margin(shape: str, size: tuple[float, ...]) -> float:
    """How far outside `shape` an attach point may lie [m]: ATTACH_MARGIN or
    ATTACH_MARGIN_SHARE of the largest dimension (a cylinder's: its length or diameter)."""
    largest = max(size[0], 2.0 * size[1]) if shape == 'cylinder' else max(size)
    return max(ATTACH_MARGIN, ATTACH_MARGIN_SHARE * largest)


def distance_outside(shape: str, size: tuple[float, ...], point: tuple[float, ...]) -> float:
    """Euclidean distance [m] from `point` (payload frame [m]) to the solid `shape` of `size`
    centred at the payload frame's origin: 0 on or inside it."""
    x, y, z = point
    if shape == 'box':
        return math.sqrt(sum(max(abs(p) - s / 2.0, 0.0) ** 2 for p, s in zip(point, size)))
    if shape == 'cylinder':
        length, radius = size
        return math.hypot(max(abs(x) - length / 2.0, 0.0), max(math.hypot(y, z) - radius, 0.0))
    raise ValueError(f'unknown payload shape {shape!r} (known: {", ".join(SHAPES)})')


def parse(p: Any, payload: Any, n: int) -> Any:
    """The body's keys of `payload:` (`p` a reading.Section) over `payload` (a
    scenario.PayloadConfig) for n cables: its shape and size, inertia (default the uniform
    solid's; validated as a rigid body's) and one attach point per cable."""
    shape = p.text('shape', choices=tuple(SHAPES))
    size = p.vector('size', length=SHAPE_SIZES[shape], check=lambda v: v > 0, rule='must be > 0')
    inertia = solid_inertia(shape, payload.mass, size)
    if p.has('inertia'):
        inertia = p.vector('inertia', check=lambda v: v > 0, rule='must be > 0')
    if not is_rigid_body_inertia(inertia):
        raise p.fail('inertia', list(inertia), 'is no rigid body\'s: each principal moment must '
                     'be at most the sum of the other two')
    raw = p.sequence('attach_points')
    if len(raw) != n:
        raise p.fail('attach_points', raw, f'must give one [x, y, z] per cable ({n})')
    holder = type(p)({str(k): v for k, v in enumerate(raw)}, p.key('attach_points'), p.where)
    points = tuple(holder.vector(str(k)) for k in range(n))
    holder.done()
    if payload.swing:
        raise p.fail('swing_deg', math.degrees(payload.swing), 'is for a point payload')
    return dataclasses.replace(payload, type=NAME, shape=shape, size=size, inertia=inertia,
                               attach_points=points)
