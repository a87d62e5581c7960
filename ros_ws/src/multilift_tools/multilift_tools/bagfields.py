"""What each multilift message type becomes when `bagdata.load_run` reads a bag: one function
per type turning a deserialized message into named numbers (`EXTRACT`), in the message's units
(world frame, z up, SI units), and the error a bag that is no multilift run raises.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from multilift_sim.estimators.published import COVARIANCE_SIDE
from multilift_sim.topics import (ATTITUDE_SETPOINT_TYPE, FLOAT64_TYPE, FORMATION_ERROR_TYPE,
                                  FORMATION_EVENT_TYPE, FORMATION_STATE_TYPE, ODOMETRY_TYPE,
                                  ROTOR_COMMAND_TYPE, TRACKING_REFERENCE_TYPE,
                                  VECTOR3_STAMPED_TYPE, topic_type)


class RunDataError(ValueError):
    """A bag could not be read as a multilift run, or lacks a topic; says which bag and why."""


def _vec(v: Any) -> list[float]:
    return [float(v.x), float(v.y), float(v.z)]


def _odometry(msg: Any) -> dict[str, list[float]]:
    pose, twist = msg.pose.pose, msg.twist.twist
    q = pose.orientation
    variances = np.asarray(msg.pose.covariance, dtype=float).reshape(
        COVARIANCE_SIDE, COVARIANCE_SIDE).diagonal()
    return {'position': _vec(pose.position),
            'orientation': [float(q.x), float(q.y), float(q.z), float(q.w)],
            'linear': _vec(twist.linear), 'angular': _vec(twist.angular),
            'pose_variance': variances.tolist()}   # the 6 x 6 pose covariance's diagonal


def _formation_state(msg: Any) -> dict[str, Any]:
    # bags from before the `taut` field (rigid cables) hold every cable taut
    taut = getattr(msg, 'taut', None)
    if taut is None or len(taut) != len(msg.cable_tension):
        taut = [True] * len(msg.cable_tension)
    return {'tension': msg.cable_tension, 'g': msg.constraint_position,
            'g_dot': msg.constraint_velocity, 'taut': [bool(v) for v in taut]}


def _rotor_command(msg: Any) -> dict[str, Any]:
    return {'omega': msg.angular_velocity, 'saturated': msg.saturated}


def _attitude_setpoint(msg: Any) -> dict[str, Any]:
    return {'euler': [float(msg.roll), float(msg.pitch), float(msg.yaw)],
            'thrust': float(msg.thrust)}


def _reference(msg: Any) -> dict[str, Any]:
    return {'position': _vec(msg.position), 'velocity': _vec(msg.velocity),
            'acceleration': _vec(msg.acceleration)}


def _formation_error(msg: Any) -> dict[str, Any]:
    return {'error': msg.error, 'error_rate': msg.error_rate}


def _vector3_stamped(msg: Any) -> dict[str, Any]:
    return {'vector': _vec(msg.vector)}


def _float64(msg: Any) -> dict[str, Any]:
    return {'data': float(msg.data)}


def _formation_event(msg: Any) -> dict[str, Any]:
    return {'type': str(msg.type), 'uav': int(msg.uav), 'description': str(msg.description)}


EXTRACT: dict[str, Callable[[Any], dict[str, Any]]] = {
    ODOMETRY_TYPE: _odometry, FORMATION_STATE_TYPE: _formation_state,
    ROTOR_COMMAND_TYPE: _rotor_command, ATTITUDE_SETPOINT_TYPE: _attitude_setpoint,
    TRACKING_REFERENCE_TYPE: _reference, FORMATION_ERROR_TYPE: _formation_error,
    VECTOR3_STAMPED_TYPE: _vector3_stamped, FORMATION_EVENT_TYPE: _formation_event,
    FLOAT64_TYPE: _float64,
}


def wanted_type(topic: str) -> str | None:
    """The message type a multilift topic has, or None for a topic this module ignores."""
    wanted = topic_type(topic)
    return wanted if wanted in EXTRACT else None
