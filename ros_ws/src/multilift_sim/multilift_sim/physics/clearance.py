"""Clearance (issue 34 item 5): the signed distances between the formation's bodies and the
world, measured at each control tick of the one tick (`physics.tick`), compiled.

Bodies: each UAV a sphere of `vehicle.radius` about r_i; each cable the segment from its UAV's
attach point r_i + R_i a_i to its payload end (r_p, or r_p + R_p b_i on a rigid body); the
payload a sphere of `payload.radius` about r_p (a rigid body: the sphere that holds its shape).
The world: the obstacles (`world.obstacles`, each type's signed distance to a point, a
registered part's compiled `distance`, reached through `obstacle_distance`, the dispatcher
generated from `multilift_sim.obstacles.OBSTACLE_TYPES`) and the ground (a plane z = h).

Distances: point to obstacle is the type's; a segment to an obstacle is the least of the
type's distance along it, which is convex for a convex obstacle (a signed distance of a convex
set is convex; along a line it stays so), found by golden-section search to 1e-10 of the
segment (skipped where a lower bound shows it cannot matter); point to segment and segment to
segment in closed form (the clamped projections of
Ericson, Real-Time Collision Detection, 2005, §5.1.2 and §5.1.9). A sphere's clearance is its
centre's distance less its radius. Units: SI, world frame z up. Slots: physics.layout
OBSTACLE_*, WORLD_*, CLEARANCE_*.
"""
import math

import numpy as np

from multilift_sim import obstacles as registry
from multilift_sim import part_dispatch
from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import quaternion_rotation
from multilift_sim.physics.free_motion import attached_off_centre
from multilift_sim.physics.layout import (
    CLEARANCE_CABLE_CABLE, CLEARANCE_CABLE_WORLD, CLEARANCE_FIRST, CLEARANCE_KIND,
    CLEARANCE_PAYLOAD_WORLD, CLEARANCE_SECOND, CLEARANCE_TIME, CLEARANCE_UAV_CABLE,
    CLEARANCE_UAV_UAV, CLEARANCE_UAV_WORLD, CLEARANCE_VALUE, OBSTACLE_BOUND, OBSTACLE_CENTER,
    OBSTACLE_GROUND, OBSTACLE_TYPE, POSITION, UAV_ATTACH, UAV_PAYLOAD_ATTACH, WORLD_GROUND,
    WORLD_PAYLOAD_RADIUS)
from multilift_sim.physics.state_slots import (attitude_slot, payload_slot,
                                               rigid_payload_state, uav_attitude_slot,
                                               uav_slot)

OBSTACLES = part_dispatch.declare(
    'obstacles', 'obstacle_distance(kind, row, x, y, z, out)', step='distance',
    caller=f'{__name__}.point_distance', parts=lambda: registry.OBSTACLE_TYPES)
obstacle_distance = OBSTACLES.compiled()  # rebound when the registry changes (OBSTACLES.refresh)

INVERSE_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
GOLDEN_STEPS = 48           # the search's interval shrinks to 0.618^48 = 1e-10 of the segment


@jit
def point_distance(row, x, y, z, scratch):
    """The signed distance [m] from (x, y, z), world, to the obstacle of `row` (its type's
    `distance`; scratch (1,) its answer)."""
    obstacle_distance(int(row[OBSTACLE_TYPE]), row, x, y, z, scratch)
    return scratch[0]


@jit
def _along(row, a, b, s, scratch):
    return point_distance(row, a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]),
                          a[2] + s * (b[2] - a[2]), scratch)


@jit
def segment_distance(row, a, b, scratch):
    """The least signed distance [m] from the segment a-b ((3,) each [m], world) to the
    (convex) obstacle of `row`: golden-section search of the convex distance along it, and
    its ends."""
    low, high = 0.0, 1.0
    c, d = high - INVERSE_GOLDEN, INVERSE_GOLDEN
    fc, fd = _along(row, a, b, c, scratch), _along(row, a, b, d, scratch)
    for _ in range(GOLDEN_STEPS):
        if fc < fd:
            high, d, fd = d, c, fc
            c = high - INVERSE_GOLDEN * (high - low)
            fc = _along(row, a, b, c, scratch)
        else:
            low, c, fc = c, d, fd
            d = low + INVERSE_GOLDEN * (high - low)
            fd = _along(row, a, b, d, scratch)
    return min(min(fc, fd), min(_along(row, a, b, 0.0, scratch), _along(row, a, b, 1.0, scratch)))


@jit
def point_segment(px, py, pz, a, b):
    """The distance [m] from (px, py, pz) to the segment a-b ((3,) each), world."""
    ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    wx, wy, wz = px - a[0], py - a[1], pz - a[2]
    length_sq = ux * ux + uy * uy + uz * uz
    s = 0.0 if length_sq == 0.0 else min(max((wx * ux + wy * uy + wz * uz) / length_sq, 0.0),
                                         1.0)
    dx, dy, dz = wx - s * ux, wy - s * uy, wz - s * uz
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@jit
def segment_segment(p1, q1, p2, q2):
    """The distance [m] between the segments p1-q1 and p2-q2 ((3,) each), world (Ericson
    §5.1.9: the closest points' parameters clamped to [0, 1] in turn)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = np.dot(d1, d1), np.dot(d2, d2), np.dot(d2, r)
    if a == 0.0 and e == 0.0:
        return math.sqrt(np.dot(r, r))
    if a == 0.0:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = np.dot(d1, r)
        if e == 0.0:
            s, t = min(max(-c / a, 0.0), 1.0), 0.0
        else:
            b = np.dot(d1, d2)
            denominator = a * e - b * b
            s = min(max((b * f - c * e) / denominator, 0.0), 1.0) if denominator > 0.0 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = min(max(-c / a, 0.0), 1.0), 0.0
            elif t > 1.0:
                s, t = min(max((b - c) / a, 0.0), 1.0), 1.0
    gap = p1 + d1 * s - p2 - d2 * t
    return math.sqrt(np.dot(gap, gap))


@jit
def note(clearance, contact, kind, value, t, first, second):
    """A clearance `value` [m] of `kind` at t [s] between `first` and `second` (CLEARANCE_*):
    the least of its kind lowered, the first contact (value <= 0) kept. Returns value <= 0."""
    if value < clearance[kind, CLEARANCE_VALUE]:
        clearance[kind, CLEARANCE_VALUE] = value
        clearance[kind, CLEARANCE_TIME] = t
        clearance[kind, CLEARANCE_FIRST] = first
        clearance[kind, CLEARANCE_SECOND] = second
    if value <= 0.0 and contact[CLEARANCE_KIND] < 0.0:
        contact[CLEARANCE_KIND] = kind
        contact[CLEARANCE_VALUE] = value
        contact[CLEARANCE_TIME] = t
        contact[CLEARANCE_FIRST] = first
        contact[CLEARANCE_SECOND] = second
    return value <= 0.0


@jit
def cable_ends(state, uavs, n, ends):
    """Each cable's ends into ends (n, 2, 3) [m], world: its UAV's attach point r_i + R_i a_i
    and its payload end (r_p, or r_p + R_p b_i on a rigid payload)."""
    p = payload_slot(n)
    rigid = rigid_payload_state(state.shape[0], n)
    payload_rotation = quaternion_rotation(state, attitude_slot(n)) if rigid else np.eye(3)
    for i in range(n):
        for j in range(3):
            ends[i, 0, j] = state[uav_slot(i) + POSITION + j]
            ends[i, 1, j] = state[p + j]
        if attached_off_centre(uavs, i):
            rotation = quaternion_rotation(state, uav_attitude_slot(n, i))
            for j in range(3):
                for k in range(3):
                    ends[i, 0, j] += rotation[j, k] * uavs[i, UAV_ATTACH + k]
        if rigid:
            for j in range(3):
                for k in range(3):
                    ends[i, 1, j] += payload_rotation[j, k] * uavs[i, UAV_PAYLOAD_ATTACH + k]


@jit
def measure(world, obstacles, radii, uavs, state, t, clearance, contact):
    """Every clearance of the formation state x (n UAVs: radii (n,) [m]) at t [s] to the world
    (`world` (WORLD_COLUMNS,), `obstacles` (k, OBSTACLE_COLUMNS)) and between its bodies, into
    the least of each kind (clearance (CLEARANCE_KINDS, CLEARANCE_COLUMNS)) and the first
    contact (contact (CLEARANCE_COLUMNS,)). Returns whether any clearance is <= 0."""
    n = radii.shape[0]
    ends = np.empty((n, 2, 3))
    cable_ends(state, uavs, n, ends)
    scratch = np.empty(1)
    p = payload_slot(n)
    payload_radius = world[WORLD_PAYLOAD_RADIUS]
    rigid = rigid_payload_state(state.shape[0], n)
    touched = False
    ground = world[WORLD_GROUND]
    if not math.isnan(ground):
        for i in range(n):
            z = state[uav_slot(i) + POSITION + 2]
            touched |= note(clearance, contact, CLEARANCE_UAV_WORLD, z - radii[i] - ground, t,
                            i, OBSTACLE_GROUND)
            touched |= note(clearance, contact, CLEARANCE_CABLE_WORLD,
                            min(ends[i, 0, 2], ends[i, 1, 2]) - ground, t, i, OBSTACLE_GROUND)
        touched |= note(clearance, contact, CLEARANCE_PAYLOAD_WORLD,
                        state[p + 2] - payload_radius - ground, t, 0, OBSTACLE_GROUND)
    for k in range(obstacles.shape[0]):
        row = obstacles[k]
        bound = row[OBSTACLE_BOUND]
        cx, cy, cz = row[OBSTACLE_CENTER], row[OBSTACLE_CENTER + 1], row[OBSTACLE_CENTER + 2]
        for i in range(n):
            x, y, z = (state[uav_slot(i) + POSITION], state[uav_slot(i) + POSITION + 1],
                       state[uav_slot(i) + POSITION + 2])
            touched |= note(clearance, contact, CLEARANCE_UAV_WORLD,
                            point_distance(row, x, y, z, scratch) - radii[i], t, i, k)
            # a lower bound of the cable's distance (the segment's from the centre less the
            # bounding radius; the distance at its middle less half its length, a signed
            # distance changing at most as fast as the point moves): not searched when the
            # bound cannot lower the least of its kind nor touch
            a, b = ends[i, 0], ends[i, 1]
            half = 0.5 * math.sqrt((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2 + (b[2] - a[2]) ** 2)
            floor = max(point_segment(cx, cy, cz, a, b) - bound,
                        point_distance(row, 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]),
                                       0.5 * (a[2] + b[2]), scratch) - half)
            if floor <= 0.0 or floor < clearance[CLEARANCE_CABLE_WORLD, CLEARANCE_VALUE]:
                touched |= note(clearance, contact, CLEARANCE_CABLE_WORLD,
                                segment_distance(row, ends[i, 0], ends[i, 1], scratch), t, i, k)
        touched |= note(clearance, contact, CLEARANCE_PAYLOAD_WORLD,
                        point_distance(row, state[p], state[p + 1], state[p + 2], scratch)
                        - payload_radius, t, 0, k)
    for i in range(n):
        xi, yi, zi = (state[uav_slot(i) + POSITION], state[uav_slot(i) + POSITION + 1],
                      state[uav_slot(i) + POSITION + 2])
        for j in range(n):
            if j == i:
                continue
            if j > i:
                dx = xi - state[uav_slot(j) + POSITION]
                dy = yi - state[uav_slot(j) + POSITION + 1]
                dz = zi - state[uav_slot(j) + POSITION + 2]
                touched |= note(clearance, contact, CLEARANCE_UAV_UAV,
                                math.sqrt(dx * dx + dy * dy + dz * dz) - radii[i] - radii[j],
                                t, i, j)
                if rigid:  # a point payload's cables all meet at r_p: no pair is measured
                    touched |= note(clearance, contact, CLEARANCE_CABLE_CABLE,
                                    segment_segment(ends[i, 0], ends[i, 1], ends[j, 0],
                                                    ends[j, 1]), t, i, j)
            touched |= note(clearance, contact, CLEARANCE_UAV_CABLE,
                            point_segment(xi, yi, zi, ends[j, 0], ends[j, 1]) - radii[i], t, i, j)
    return touched
