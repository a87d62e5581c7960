"""The multilift messages as rclpy objects, built from the same model values
(multilift_sim.wire.msgvalues) as the CDR bytes the nodes publish (multilift_sim.wire.tick_messages,
multilift_control.answer_messages): the independent reference tests/unit/test_cdr.py holds
those bytes to. World frame, SI units.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
from geometry_msgs.msg import Point, TransformStamped, Vector3, Vector3Stamped
from multilift_msgs.msg import (AttitudeSetpoint, FormationEvent, FormationSnapshot,
                                FormationState, RotorCommand, TrackingReference,
                                VirtualConstraintError)
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from multilift_sim.wire import msgvalues
from multilift_sim.ros.common import WORLD_FRAME, fill_odometry, stamp_from_ns, uav_frame

PAYLOAD_FRAME = 'payload'

PAYLOAD_FRAME = 'payload'


def clock(t_ns: int) -> Clock:
    return Clock(clock=stamp_from_ns(t_ns))


def uav_odometry(t_ns: int, index: int, uav) -> Odometry:
    """UAV `index` (1 = leader) from a simulation.UavSnapshot."""
    return fill_odometry(Odometry(), t_ns, uav_frame(index), uav.position, uav.velocity,
                         uav.orientation, uav.body_velocity, uav.body_rates)


def payload_odometry(t_ns: int, position: np.ndarray, velocity: np.ndarray) -> Odometry:
    return fill_odometry(Odometry(), t_ns, PAYLOAD_FRAME, position, velocity, None, None, None)


def _transform(t_ns: int, child: str, position: Sequence[float],
               quaternion: Sequence[float]) -> TransformStamped:
    msg = TransformStamped(child_frame_id=child)
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = WORLD_FRAME
    tr = msg.transform.translation
    tr.x, tr.y, tr.z = (float(v) for v in position)
    q = msg.transform.rotation
    q.x, q.y, q.z, q.w = (float(v) for v in quaternion)
    return msg


def transforms(t_ns: int, snapshot) -> TFMessage:
    """/tf of a simulation.Snapshot: world -> uav{i}/base_link (i from 1) and world -> payload
    (no rotation), the poses of the odometry published with it."""
    frames = [_transform(t_ns, uav_frame(i + 1), uav.position, uav.orientation)
              for i, uav in enumerate(snapshot.uavs)]
    frames.append(_transform(t_ns, PAYLOAD_FRAME, snapshot.payload_position,
                             (0.0, 0.0, 0.0, 1.0)))
    return TFMessage(transforms=frames)


def _vector(values: Sequence[float]) -> Vector3:
    return Vector3(x=float(values[0]), y=float(values[1]), z=float(values[2]))


def gust(t_ns: int, velocity: np.ndarray) -> Vector3Stamped:
    msg = Vector3Stamped(vector=_vector(velocity))
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = WORLD_FRAME
    return msg


def formation_state(t_ns: int, tension: np.ndarray, g: np.ndarray,
                    g_dot: np.ndarray, taut: np.ndarray | None = None) -> FormationState:
    """`taut`: per cable (None: every cable taut, the rigid model)."""
    taut = [True] * len(tension) if taut is None else [bool(v) for v in taut]
    msg = FormationState(cable_tension=[float(v) for v in tension],
                         constraint_position=[float(v) for v in g],
                         constraint_velocity=[float(v) for v in g_dot], taut=taut)
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = WORLD_FRAME
    return msg


def formation_snapshot(snapshot, previous_rotor_speeds: Sequence[np.ndarray] | None,
                       rotor_counts: Sequence[int]) -> FormationSnapshot:
    """From a simulation.Snapshot and the rotor speeds applied up to it (None at t = 0)."""
    (position, velocity, euler, body_rates, payload_position, payload_velocity,
     previous) = msgvalues.formation_snapshot(snapshot, previous_rotor_speeds)
    msg = FormationSnapshot(position=position, velocity=velocity, euler=euler,
                            body_rates=body_rates, payload_position=payload_position,
                            payload_velocity=payload_velocity,
                            rotor_count=[int(c) for c in rotor_counts],
                            previous_rotor_speeds=previous if previous.size else [])
    msg.header.stamp = stamp_from_ns(snapshot.t_ns)
    msg.header.frame_id = WORLD_FRAME
    return msg


def formation_event(t_ns: int, row: Sequence[float]) -> FormationEvent:
    """From an event row (physics.layout EVENT_*) that happened at the tick t_ns."""
    kind, uav, rotor, value, scheduled, description = msgvalues.formation_event(row)
    msg = FormationEvent(type=kind, uav=uav, rotor=rotor, value=value, scheduled_time=scheduled,
                         description=description)
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = WORLD_FRAME
    return msg


def rotor_command(t_ns: int, index: int, output) -> RotorCommand:
    """From a cascade.ControlOutput; the stamp is the state time it answers."""
    msg = RotorCommand(angular_velocity=[float(v) for v in output.rotor_speeds],
                       saturated=[bool(s) for s in output.saturated])
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = uav_frame(index)
    return msg


def attitude_setpoint(t_ns: int, index: int, output) -> AttitudeSetpoint:
    roll, pitch, yaw = (float(a) for a in output.attitude_setpoint)
    msg = AttitudeSetpoint(roll=roll, pitch=pitch, yaw=yaw, thrust=float(output.thrust))
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = uav_frame(index)
    return msg


def tracking_reference(t_ns: int, reference) -> TrackingReference:
    """From a mission.Reference."""
    p = reference.position
    msg = TrackingReference(position=Point(x=float(p[0]), y=float(p[1]), z=float(p[2])),
                            velocity=_vector(reference.velocity),
                            acceleration=_vector(reference.acceleration))
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = WORLD_FRAME
    return msg


def formation_error(t_ns: int, errors: np.ndarray, rates: np.ndarray) -> VirtualConstraintError:
    msg = VirtualConstraintError(error=[float(e) for e in errors],
                                 error_rate=[float(e) for e in rates])
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = WORLD_FRAME
    return msg
