"""Obstacle types as registered parts (issue 34 item 5): one module per `world.obstacles[k]
.type`, `OBSTACLE_TYPES` the registry (name -> module) that the scenario's validation
(`scenario.world`), the clearance checks (`physics.clearance`, through the dispatcher
generated from it), the markers and the plots read; nothing else names a type.

A type's module declares:
- `NAME`, the scenario's `type:`, and `KEYS`, its keys besides `type`, `name`, `center`, `yaw`;
- `parse(o) -> (half, bound)`: its size keys read from `o` (the obstacle's
  `scenario.reading.Section`, one-line errors naming the key): half its extent along its own
  axes [m] (3,) (physics.layout OBSTACLE_HALF) and the radius [m] of a sphere about its centre
  that holds it;
- `distance(row, x, y, z, out)`: compiled (`kernels.jit`), the signed distance [m] from the
  point (x, y, z) [m], world, to the obstacle of that row (physics.layout OBSTACLE_*), into
  out[0]: negative inside. It must be the distance to a convex set (the clearance of a cable,
  a segment, is found by a line search that relies on it: `physics.clearance`);
- `outline(half) -> (kind, scale)`: how the markers and plots draw it (`'cube'`, `'cylinder'`
  or `'sphere'`, and its full size along its axes [m]).

A type's index in the registry is the row's OBSTACLE_TYPE. `register` adds one (a test's toy
type: `registered`); the compiled dispatcher follows (`physics.clearance.OBSTACLES`).
"""
from __future__ import annotations

from multilift_sim.obstacles import box, cylinder, sphere
from multilift_sim.registry import Registry


def _changed() -> None:
    from multilift_sim.physics import clearance  # numba's side, loaded only when types change
    clearance.OBSTACLES.refresh()


OBSTACLE_TYPES = Registry('obstacle type', ('NAME', 'KEYS', 'parse', 'distance', 'outline'),
                          (box, cylinder, sphere), changed=_changed)
register, unregister, registered = (OBSTACLE_TYPES.register, OBSTACLE_TYPES.unregister,
                                    OBSTACLE_TYPES.registered)


def type_index(name: str) -> int:
    """The registry's index of type `name`: its rows' OBSTACLE_TYPE."""
    return list(OBSTACLE_TYPES).index(name)


def type_at(index: int):
    """The type of a row's OBSTACLE_TYPE."""
    return list(OBSTACLE_TYPES.values())[int(index)]
