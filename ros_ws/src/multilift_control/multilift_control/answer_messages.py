"""A controller's answer as CDR bytes by topic (no rclpy): what the controller nodes publish
as they are and what the headless bag writes, so both carry the same messages (see
multilift_sim.wire.tick_messages for the simulator's side)."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from multilift_control.laws.layout import REFERENCE_ACCELERATION, REFERENCE_POSITION
from multilift_control.runtime import ControllerAnswer
from multilift_sim.wire import cdr
from multilift_sim.wire.msgvalues import uav_frame
from multilift_sim.scenario import Scenario
from multilift_sim.wire.tick_messages import Message, MessageRows
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
        out, ref, error = answer.output, answer.reference, answer.formation_error
        return self.answer_of(
            answer.index, answer.t_ns, out.rotor_speeds.tolist(),
            [bool(s) for s in out.saturated], out.attitude_setpoint.tolist(), float(out.thrust),
            None if ref is None else [*ref.position.tolist(), *ref.velocity.tolist(),
                                      *ref.acceleration.tolist()],
            None if error is None else error.tolist(),
            None if error is None else answer.formation_error_rate.tolist())

    def command_of(self, index: int, t_ns: int, speeds: Sequence[float],
                   saturated: Sequence[bool]) -> list[Message]:
        """UAV `index`'s (from 0) /uav{i}/rotor_cmd alone: rotor speeds [rad/s], saturation."""
        cmd_topic, cmd = self._uavs[index][:2]
        return [(cmd_topic, cmd.pack(t_ns, speeds, saturated))]

    def answer_of(self, index: int, t_ns: int, speeds: Sequence[float],
                  saturated: Sequence[bool], setpoint: Sequence[float], thrust: float,
                  reference: Sequence[float] | None, errors: Sequence[float] | None,
                  rates: Sequence[float] | None) -> list[Message]:
        """`of` from plain numbers (the one packing of both): UAV `index`'s (from 0) rotor
        speeds [rad/s] and saturation, attitude setpoint (roll, pitch, yaw) [rad] and thrust
        [N], the leader's reference (position, velocity, acceleration: 9 numbers) or None, a
        follower's formation errors and their rates or None."""
        _, _, setpoint_topic, setpoint_packer, ref_topic, error_topic = self._uavs[index]
        messages = self.command_of(index, t_ns, speeds, saturated)
        messages.append((setpoint_topic, setpoint_packer.pack(t_ns, *setpoint, thrust)))
        if reference is not None:
            # the message's 9 numbers: the heading is the setpoint's yaw
            messages.append((ref_topic, self._reference.pack(
                t_ns, *reference[REFERENCE_POSITION:REFERENCE_ACCELERATION + 3])))
        if errors is not None:
            rows = len(errors)
            packer = self._errors.get(rows)
            if packer is None:
                packer = self._errors[rows] = cdr.virtual_constraint_error(rows)
            messages.append((error_topic, packer.pack(t_ns, errors, rates)))
        return messages

    def answer_rows(self, t_ns: np.ndarray, speeds: Sequence[np.ndarray],
                    saturated: Sequence[np.ndarray], setpoints: np.ndarray | None = None,
                    thrust: np.ndarray | None = None, reference: np.ndarray | None = None,
                    errors: Sequence[np.ndarray] = (), rates: Sequence[np.ndarray] = ()
                    ) -> list[MessageRows]:
        """Every UAV's `answer_of` (`command_of` alone without `setpoints`) of K ticks (t_ns
        (K,) [ns]) at once, topic by topic in their order: per UAV its rotor speeds and
        saturation (K, its rotors), setpoints (K, n, 3) and thrust (K, n), the leader's
        reference (K, 9 or more) or None, each follower's errors and rates (K, rows) (index
        0, the leader's, unused)."""
        out = []
        for i, (cmd_topic, cmd, setpoint_topic, setpoint_packer, ref_topic,
                error_topic) in enumerate(self._uavs):
            out.append((cmd_topic, cmd.pack_rows(t_ns, speeds[i], saturated[i])))
            if setpoints is None:
                continue
            out.append((setpoint_topic, setpoint_packer.pack_rows(
                t_ns, np.concatenate((setpoints[:, i], thrust[:, i, None]), axis=1))))
            if i == 0 and reference is not None:
                out.append((ref_topic, self._reference.pack_rows(
                    t_ns, reference[:, REFERENCE_POSITION:REFERENCE_ACCELERATION + 3])))
            if i:
                rows = errors[i].shape[1]
                packer = self._errors.get(rows)
                if packer is None:
                    packer = self._errors[rows] = cdr.virtual_constraint_error(rows)
                out.append((error_topic, packer.pack_rows(t_ns, errors[i], rates[i])))
        return out
