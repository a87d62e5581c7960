"""The numbers our messages carry, computed once from model values (no rclpy, no message types).

multilift_sim.wire.cdr packs CDR straight from these functions (the bytes the nodes publish and the
headless bag writes), and multilift_sim.ros.messages fills rclpy messages from them, the
reference the packed bytes are tested against. World frame, SI units.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from multilift_sim.estimators.published import payload_read
from multilift_sim.events import kind_at
from multilift_sim.kernels import uncompiled
from multilift_sim.physics.measurement import euler_quaternion
from multilift_sim.physics.layout import (EVENT_KIND, EVENT_TIME, MEASURED_BODY_RATES,
                                          MEASURED_EULER, MEASURED_POSITION, MEASURED_VELOCITY)


WORLD_FRAME = 'world'
_euler_quaternion = uncompiled(euler_quaternion)  # `quaternion`: plain floats, no dispatch
PAYLOAD_FRAME = 'payload'

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
IDENTITY: Quat = (0.0, 0.0, 0.0, 1.0)
# a FormationSnapshot's per-UAV blocks, 3 numbers per UAV each, in its order: position,
# velocity, euler, body rates (their slots in a measured state, physics.layout MEASURED_*)
SNAPSHOT_BLOCKS = (MEASURED_POSITION, MEASURED_VELOCITY, MEASURED_EULER, MEASURED_BODY_RATES)


def uav_frame(index: int) -> str:
    """`uav{index}/base_link`, index from 1 (1 is the leader)."""
    return f'uav{index}/base_link'


def stamp(t_ns: int) -> tuple[int, int]:
    """(sec, nanosec) of builtin_interfaces/Time for a time [ns]."""
    return int(t_ns // 1_000_000_000), int(t_ns % 1_000_000_000)


def stamps(t_ns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`stamp` of K times [ns] at once: (sec (K,), nanosec (K,)), columns for
    `cdr_layout.Layout.pack_rows`."""
    t_ns = np.asarray(t_ns, dtype=np.int64)
    return t_ns // 1_000_000_000, t_ns % 1_000_000_000


def quaternion(euler: Sequence[float]) -> Quat:
    """(x, y, z, w) of ZYX Euler angles [rad], for the markers (scene.py): physics.measurement
    .euler_quaternion (the odometry's), run uncompiled on plain floats (one attitude per
    message: a compiled call's or numpy's per-call cost would be most of it)."""
    roll, pitch, yaw = euler
    return _euler_quaternion(float(roll), float(pitch), float(yaw))


def vec3(values: Sequence[float]) -> Vec3:
    return float(values[0]), float(values[1]), float(values[2])


def odometry(position: Sequence[float], velocity_world: Sequence[float],
             orientation: Sequence[float] | None, body_velocity: Sequence[float] | None,
             body_rates: Sequence[float] | None) -> tuple[Vec3, Quat, Vec3, Vec3]:
    """(position, orientation, linear twist, angular twist) of a nav_msgs/Odometry in `world`:
    the twist is in the child frame as nav_msgs/Odometry specifies. A UAV's `orientation`
    (x, y, z, w), `body_velocity` R^T v and `body_rates` are its simulation.UavSnapshot's
    (physics.measurement.odometry_states computes them); without an orientation (the payload)
    the orientation is the identity and the twist the world velocity."""
    if orientation is None:
        orientation, linear = IDENTITY, vec3(velocity_world)
    else:
        orientation, linear = _quat(orientation), vec3(body_velocity)
    angular = (0.0, 0.0, 0.0) if body_rates is None else vec3(body_rates)
    return vec3(position), orientation, linear, angular


def _quat(values: Sequence[float]) -> Quat:
    return float(values[0]), float(values[1]), float(values[2]), float(values[3])


def formation_snapshot(snapshot, previous_rotor_speeds: Sequence[np.ndarray] | None
                       ) -> tuple[np.ndarray, ...]:
    """The arrays of a multilift_msgs/FormationSnapshot from a simulation.Snapshot and the
    rotor speeds applied up to it (None at t = 0): (position, velocity, euler, body_rates)
    3 per UAV, what the controllers receive (its `measured` rows), payload position and
    velocity (its estimate with a payload estimator: what the controllers read), previous
    rotor speeds UAV by UAV (empty at t = 0)."""
    measured = snapshot.measured  # what the controllers receive (multilift_sim.sensors)
    previous = (np.concatenate(previous_rotor_speeds).astype(float)
                if previous_rotor_speeds is not None else np.empty(0))
    payload = ((snapshot.payload_position, snapshot.payload_velocity)
               if snapshot.payload_estimate is None else payload_read(snapshot.payload_estimate))
    return tuple(measured[:, block:block + 3].reshape(-1) for block in SNAPSHOT_BLOCKS) + (
        np.asarray(payload[0], dtype=float), np.asarray(payload[1], dtype=float), previous)


FormationEventValues = tuple[str, int, int, float, float, str]


def formation_event(row: Sequence[float]) -> FormationEventValues:
    """A multilift_msgs/FormationEvent's (type, uav (from 1), rotor (from 1; 0: none), value,
    scheduled_time [s], description) from an event row (physics.layout EVENT_*): what its
    kind's module (multilift_sim.events) `describe`s."""
    kind = kind_at(int(row[EVENT_KIND]))
    uav, rotor, value, text = kind.describe(row)  # by its registered module
    return kind.NAME, uav, rotor, value, float(row[EVENT_TIME]), text
