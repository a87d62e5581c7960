"""The formation's geometry at the bag's samples, for the figures and the animation: each
cable's two ends (a rigid payload's attach points R_p b_i + r_p, a UAV's attach point
R_i a_i + r_i), which cables a `cable_release` event let go and when, and a rigid body's
outline (a box's 12 edges through its 8 corners; a cylinder's axis and its two rims). World
frame (z up) [m]; rotations from the odometry's attitude (kinematics.rotation_matrix, body or
payload frame -> world). No matplotlib.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import product
from typing import TYPE_CHECKING

import numpy as np

from multilift_sim.events import releases_cable
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.topics import EVENTS
from multilift_tools.metrics import interp_rows

if TYPE_CHECKING:
    from multilift_sim.scenario import Scenario
    from multilift_tools.bagdata import Run

RIM_POINTS = 24  # points on a cylinder's rim


def released_cables(run: Run) -> dict[int, float]:
    """{i: t}: UAV i's cable was released at t [s] (the first state showing it,
    /formation/events of a kind that releases a cable: `multilift_sim.events.releases_cable`);
    empty without such events."""
    if not run.has(EVENTS):
        return {}
    series = run.topic(EVENTS)
    out: dict[int, float] = {}
    for t, kind, uav in zip(series.t, series['type'], series['uav']):
        if releases_cable(str(kind)):
            out.setdefault(int(uav), float(t))
    return out


def body_corners(shape: str, size: tuple[float, ...]) -> np.ndarray:
    """A box's 8 corners (8, 3) in its own frame [m] (the signs of x, y, z in binary order);
    a cylinder's two end centres (2, 3)."""
    if shape == 'box':
        half = np.asarray(size, dtype=float) / 2.0
        return np.array(list(product((-1.0, 1.0), repeat=3))) * half
    length = float(size[0])
    return np.array([[-length / 2.0, 0.0, 0.0], [length / 2.0, 0.0, 0.0]])


def body_polylines(shape: str, size: tuple[float, ...]) -> list[np.ndarray]:
    """The outline of a rigid body in its own frame: polylines (k, 3) [m]. A box: its 12
    edges (each between two corners of `body_corners`); a cylinder: its axis and two rims."""
    corners = body_corners(shape, size)
    if shape == 'box':
        return [corners[[a, b]] for a in range(8) for b in range(a + 1, 8)
                if bin(a ^ b).count('1') == 1]
    radius = float(size[1])
    angle = np.linspace(0.0, 2.0 * np.pi, RIM_POINTS + 1)
    ring = np.stack([np.zeros_like(angle), radius * np.cos(angle), radius * np.sin(angle)], 1)
    return [corners, *(ring + end for end in corners)]


@dataclass(frozen=True)
class Scene:
    """The formation on the time base `t` (T,) [s] of /uav1/odom: UAV centres `uavs` (n, T, 3),
    the payload's centre `payload` (T, 3) and attitude `payload_rotation` (T, 3, 3), each cable's
    ends `uav_ends` and `payload_ends` (n, T, 3) [m], `released` {i: t [s]}, and the rigid
    body's `shape` and `size` ('' and () for a point payload)."""

    t: np.ndarray
    uavs: np.ndarray
    payload: np.ndarray
    payload_rotation: np.ndarray
    uav_ends: np.ndarray
    payload_ends: np.ndarray
    released: dict[int, float]
    shape: str = ''
    size: tuple[float, ...] = ()

    def cable_attached(self, i: int, k: int) -> bool:
        """Whether UAV i's cable (from 1) holds the payload at sample k (not yet released)."""
        release = self.released.get(i)
        return release is None or self.t[k] < release

    def cable(self, i: int, k: int) -> np.ndarray | None:
        """UAV i's cable at sample k, (2, 3) [m] from the UAV to the payload; None once it is
        released (nothing joins the UAV to the payload)."""
        if not self.cable_attached(i, k):
            return None
        return np.stack([self.uav_ends[i - 1, k], self.payload_ends[i - 1, k]])

    def outline(self, k: int) -> list[np.ndarray]:
        """The rigid body's outline at sample k, world [m] (empty for a point payload)."""
        if not self.shape:
            return []
        rotation, centre = self.payload_rotation[k], self.payload[k]
        return [line @ rotation.T + centre for line in body_polylines(self.shape, self.size)]

    def corners(self, k: int) -> np.ndarray:
        """The rigid body's corners (box: 8, cylinder: its 2 end centres) at sample k, world
        [m]; (0, 3) for a point payload."""
        if not self.shape:
            return np.zeros((0, 3))
        return body_corners(self.shape, self.size) @ self.payload_rotation[k].T + self.payload[k]


def formation_scene(run: Run, scenario: Scenario | None) -> Scene:
    """The `Scene` of `run`; the attach points and the body's shape from `scenario` (without
    one: every cable from centre to centre, the payload a point)."""
    t = run.t
    uavs = run.uav_positions()
    payload = interp_rows(t, run.payload_time, run.payload_position())
    euler = interp_rows(t, run.payload_time, np.unwrap(run.payload_euler(), axis=0))
    rotation = rotation_matrix(euler)
    n = uavs.shape[0]
    uav_ends, payload_ends = uavs.copy(), np.repeat(payload[None], n, axis=0)
    shape, size = '', ()
    if scenario is not None:
        body = scenario.payload
        if body.type == 'rigid_body' and body.attach_points:
            shape, size = body.shape, tuple(body.size)
            points = np.asarray(body.attach_points, dtype=float)  # (n, 3) payload frame
            payload_ends = payload[None] + np.einsum('tab,nb->nta', rotation, points)
        offsets = np.array([u.attach_point for u in scenario.uavs], dtype=float)
        if offsets.any():
            uav_rotation = rotation_matrix(run.uav_euler())  # (n, T, 3, 3)
            uav_ends = uavs + np.einsum('ntab,nb->nta', uav_rotation, offsets)
    return Scene(t, uavs, payload, rotation, uav_ends, payload_ends, released_cables(run),
                 shape, size)
