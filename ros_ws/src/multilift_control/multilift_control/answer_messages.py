"""A controller's answer as CDR bytes by topic (no rclpy): what the controller nodes publish
as they are and what the headless bag writes, so both carry the same messages (see
multilift_sim.tick_messages for the simulator's side)."""
from __future__ import annotations

from multilift_control.runtime import ControllerAnswer
from multilift_sim import cdr
from multilift_sim.msgvalues import uav_frame
from multilift_sim.scenario import Scenario
from multilift_sim.tick_messages import Message
from multilift_sim.topics import (ATTITUDE_SETPOINT, FORMATION_ERROR, REFERENCE, ROTOR_CMD,
                                  uav_topic)


class AnswerMessages:
    """Every UAV's answer messages of one run (`scenario`)."""

    def __init__(self, scenario: Scenario) -> None:
        self._uavs = [(uav_topic(i, ROTOR_CMD),
                       cdr.RotorCommand(scenario.uavs[i - 1].vehicle.n_rotors, uav_frame(i)),
                       uav_topic(i, ATTITUDE_SETPOINT), cdr.AttitudeSetpoint(uav_frame(i)),
                       uav_topic(i, REFERENCE), uav_topic(i, FORMATION_ERROR))
                      for i in range(1, scenario.n_uavs + 1)]
        self._reference = cdr.TrackingReference()
        self._errors: dict[int, cdr.FloatSequences] = {}  # by the number of rows

    def of(self, answer: ControllerAnswer) -> list[Message]:
        """/uav{i}/rotor_cmd first (what the simulator waits for), then
        /uav{i}/attitude_setpoint, then the leader's /uav1/reference or a follower's
        /uav{i}/formation_error; all stamped with the answered state's time."""
        cmd_topic, cmd, setpoint_topic, setpoint, ref_topic, error_topic = \
            self._uavs[answer.index]
        t_ns, out = answer.t_ns, answer.output
        roll, pitch, yaw = out.attitude_setpoint.tolist()
        messages = [(cmd_topic, cmd.pack(t_ns, out.rotor_speeds.tolist(),
                                         [bool(s) for s in out.saturated])),
                    (setpoint_topic, setpoint.pack(t_ns, roll, pitch, yaw, float(out.thrust)))]
        ref = answer.reference
        if ref is not None:
            messages.append((ref_topic, self._reference.pack(
                t_ns, *ref.position.tolist(), *ref.velocity.tolist(),
                *ref.acceleration.tolist())))
        if answer.formation_error is not None:
            rows = len(answer.formation_error)
            packer = self._errors.get(rows)
            if packer is None:
                packer = self._errors[rows] = cdr.virtual_constraint_error(rows)
            messages.append((error_topic, packer.pack(t_ns, answer.formation_error.tolist(),
                                                      answer.formation_error_rate.tolist())))
        return messages
