"""Where the UAVs of a formation sit and where the payload hangs at the start (world frame).

The followers' nominal places satisfy the virtual constraints of seed Table 3.1 with every UAV
at the leader's altitude; the payload starts at rest on the constraint manifold (Eq. 2.42, 2.56)
below the formation.
"""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.frames import seed_to_world_vector


def v_offset(index: int, distance: float, half_angle: float) -> np.ndarray:
    """v_1i of seed §3.2.1: follower `index` (2..n) sits at r_1 + v_1i.

    The seed writes v_1i = (i/2)(-d c_g, -d s_g, 0) for even i and ((i-1)/2)(-d c_g, d s_g, 0)
    for odd i in its z-down frame; mapped here to world (even followers on +y, odd on -y).
    """
    c, s = math.cos(half_angle), math.sin(half_angle)
    if index % 2 == 0:
        seed = (index / 2) * np.array([-distance * c, -distance * s, 0.0])
    else:
        seed = ((index - 1) / 2) * np.array([-distance * c, distance * s, 0.0])
    return seed_to_world_vector(seed)


def _linear_place(i: int, n: int, offsets, distance: float, half_angle: float) -> np.ndarray:
    """r_i - r_1 = -offset_i."""
    return -np.asarray(offsets[i - 1], dtype=float)


def _v_place(i: int, n: int, offsets, distance: float, half_angle: float) -> np.ndarray:
    """r_i - r_1 = v_1i."""
    return v_offset(i + 1, distance, half_angle)


def _distance_place(i: int, n: int, offsets, distance: float, half_angle: float) -> np.ndarray:
    """Evenly on the rear half-circle of radius d about the leader."""
    angle = math.pi / 2 + math.pi * i / n
    return distance * np.array([math.cos(angle), math.sin(angle), 0.0])


def _circle_place(i: int, n: int, offsets, distance: float, half_angle: float) -> np.ndarray:
    """A vertex of the regular polygon of side d whose vertex 0 is the leader."""
    radius = distance / (2 * math.sin(math.pi / n))
    angle = 2 * math.pi * i / n
    return radius * np.array([math.cos(angle) - 1.0, math.sin(angle), 0.0])


# The formation geometries of seed Table 3.1, by the name `formation.geometry` takes: the one
# registry (scenario validation and the followers' constraint rows read its names), each
# follower i's nominal place relative to the leader r_i - r_1 [m], world
NOMINAL_PLACES = {'linear': _linear_place, 'distance': _distance_place, 'v': _v_place,
                  'circle': _circle_place}
FORMATION_GEOMETRIES = tuple(NOMINAL_PLACES)


def nominal_positions(geometry: str, n: int, leader_position, offsets=(), distance: float = 0.0,
                      half_angle: float = 0.0) -> np.ndarray:
    """(n, 3) positions [m] with every virtual constraint satisfied, all at the leader's height
    (`NOMINAL_PLACES`: linear r_i = r_1 - offset_i; v: r_i = r_1 + v_1i; distance: followers
    evenly on the rear half-circle of radius d; circle: a regular polygon of side d with the
    leader a vertex)."""
    if geometry not in NOMINAL_PLACES:
        raise ValueError(f'unknown formation geometry {geometry!r}')
    place = NOMINAL_PLACES[geometry]
    leader = np.asarray(leader_position, dtype=float)
    out = np.tile(leader, (n, 1))
    for i in range(1, n):
        out[i] = leader + place(i, n, offsets, distance, half_angle)
    return out


def hanging_payload(uav_positions: np.ndarray, cable_lengths, attach_points=None,
                    uav_offsets=None) -> tuple[np.ndarray, np.ndarray]:
    """(uav_positions, payload_position) with every cable at its length, payload below.

    The payload sits under the UAVs' horizontal centroid (their equilibrium point when that
    is equidistant, as for the twin-lift, the V of three and circles); the leader keeps its
    altitude and each follower's altitude is set so its cable has exactly its length. A rigid
    payload (`attach_points` b_i (n, 3), its frame, level: the identity attitude) hangs with
    its centre under the centroid of r_i - b_i, cable i from UAV i to r_p + b_i; a cable held
    off its UAV's centre (`uav_offsets` R_i a_i (n, 3), world) starts at r_i + R_i a_i.
    Raises ValueError naming the cable when a UAV is farther from that point than its cable.
    """
    uavs = np.array(uav_positions, dtype=float)
    lengths = np.asarray(cable_lengths, dtype=float)
    attach = np.zeros((len(uavs), 3)) if attach_points is None else np.asarray(
        attach_points, dtype=float)
    offsets = np.zeros((len(uavs), 3)) if uav_offsets is None else np.asarray(uav_offsets,
                                                                               dtype=float)
    uavs = uavs + offsets  # the cables' upper ends
    centre = (uavs[:, :2] - attach[:, :2]).mean(axis=0)
    spans = np.linalg.norm(uavs[:, :2] - attach[:, :2] - centre, axis=1)
    for i, (span, length) in enumerate(zip(spans, lengths)):
        if span >= length:
            raise ValueError(f'cable {i + 1} ({length:g} m) is shorter than the horizontal '
                             f'distance {span:.2f} m from UAV {i + 1} to the payload below '
                             'the formation')
    drops = np.sqrt(lengths ** 2 - spans ** 2) + attach[:, 2]
    payload = np.array([centre[0], centre[1], uavs[0, 2] - drops[0]])
    uavs[:, 2] = payload[2] + drops
    return uavs - offsets, payload


def swing_about_uav_axis(payload: np.ndarray, first: np.ndarray, second: np.ndarray,
                         angle: float) -> np.ndarray:
    """The payload rotated by `angle` [rad] about the line through two UAVs (both cables keep
    their lengths): a release out of the UAVs-payload plane."""
    axis = np.asarray(second, float) - np.asarray(first, float)
    axis /= np.linalg.norm(axis)
    arm = payload - first
    rotated = (arm * math.cos(angle) + np.cross(axis, arm) * math.sin(angle)
               + axis * np.dot(axis, arm) * (1 - math.cos(angle)))
    return first + rotated


def lowest_reached(uavs: np.ndarray, lengths: np.ndarray,
                   down: np.ndarray) -> np.ndarray | None:
    """Where a point payload hangs from cables of `lengths` (n,) [m] tied to `uavs` (n, 3) [m]
    when its apparent weight pulls along the unit vector `down`: the lowest point along `down`
    within every cable's reach (analysis.loads, the start of `formation.start_places`). A
    linear potential over the balls' intersection is least on its boundary, where one cable
    (the end of a straight cable), two (the lowest point of their circle) or three (a corner of
    the spheres) are at their length: the lowest candidate every cable reaches; None when
    none is (the cables cannot all reach one point)."""
    down = np.asarray(down, dtype=float)
    n = len(lengths)
    candidates = [uavs[i] + lengths[i] * down for i in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            circle = _circle(uavs[i], lengths[i], uavs[j], lengths[j])
            if circle is None:
                continue
            centre, axis, radius = circle
            across = down - (down @ axis) * axis
            if np.linalg.norm(across) > 1e-12:
                candidates.append(centre + radius * across / np.linalg.norm(across))
            for k in range(j + 1, n):
                candidates.extend(_corners(circle, uavs[k], lengths[k]))
    reached = [p for p in candidates
               if np.all(np.linalg.norm(p - uavs, axis=1) <= lengths * (1.0 + 1e-9))]
    if not reached:
        return None
    return max(reached, key=lambda p: float(down @ p))


def _circle(a: np.ndarray, ra: float, b: np.ndarray, rb: float):
    """The circle where spheres (a, ra) and (b, rb) meet: (centre, unit axis a -> b, radius),
    or None."""
    span = b - a
    distance = float(np.linalg.norm(span))
    if distance == 0.0 or distance > ra + rb or distance < abs(ra - rb):
        return None
    axis = span / distance
    along = (distance ** 2 + ra ** 2 - rb ** 2) / (2.0 * distance)
    return a + along * axis, axis, float(np.sqrt(max(ra ** 2 - along ** 2, 0.0)))


def _corners(circle, c: np.ndarray, rc: float) -> list[np.ndarray]:
    """The points of `circle` (centre, axis, radius) at distance rc from c."""
    centre, axis, radius = circle
    offset = c - centre
    height = float(offset @ axis)                 # c above the circle's plane
    flat = offset - height * axis
    reach = float(np.linalg.norm(flat))
    # |p - c|^2 = radius^2 + reach^2 + height^2 - 2 radius reach cos(angle) = rc^2
    if reach == 0.0:
        return []
    cosine = (radius ** 2 + reach ** 2 + height ** 2 - rc ** 2) / (2.0 * radius * reach) \
        if radius > 0.0 else 2.0
    if abs(cosine) > 1.0:
        return []
    e1 = flat / reach
    e2 = np.cross(axis, e1)
    sine = float(np.sqrt(1.0 - cosine ** 2))
    return [centre + radius * (cosine * e1 + sign * sine * e2) for sign in (1.0, -1.0)]
