"""The controllers a scenario can pick (`control.mode`), behind one `update(t, states)` call.

A controller answers the formation's states at simulated time t [s] (`FormationStates`: every
UAV's, its own first, and the payload's velocity) with a `ControlOutput` and the reference it
tracked (or None).
"""
from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from multilift_control import laws
from multilift_control.cascade import (CascadeController, ControlOutput, FormationStates,
                                       balancing_rotor_speed)
from multilift_control.laws.cascade import leader_update
from multilift_control.mission import MissionPath, Reference
from multilift_sim.scenario import CONTROL_MODES, INPUT_SHAPERS, Scenario
from multilift_sim.start import formation_start


class Controller(Protocol):
    def update(self, t: float, states: FormationStates
               ) -> tuple[ControlOutput, Reference | None]:
        ...


class ConstantRotorSpeed:
    """Holds every rotor at one speed (the seed's open-loop test of §4.1)."""

    def __init__(self, scenario: Scenario, index: int):
        vehicle = scenario.uavs[index].vehicle
        speed = scenario.control.constant_rotor_speed
        if speed is None:  # balance the whole formation's weight, shared equally
            mass = sum(u.vehicle.mass for u in scenario.uavs) + scenario.payload.mass
            speed = balancing_rotor_speed(vehicle, mass / scenario.n_uavs,
                                          scenario.simulation.gravity)
        clipped = min(max(speed, vehicle.rotor_speed_min), vehicle.rotor_speed_max)
        speeds = np.full(vehicle.n_rotors, clipped)
        self.output = ControlOutput(rotor_speeds=speeds,
                                    saturated=np.full(vehicle.n_rotors, clipped != speed),
                                    attitude_setpoint=np.zeros(3),
                                    thrust=vehicle.collective_thrust(speeds))

    def update(self, t: float, states: FormationStates
               ) -> tuple[ControlOutput, Reference | None]:
        return self.output, None


class MissionLeader:
    """The leader: cascade control along the mission path, one law a tick
    (`laws.cascade.leader_update`) over the cascade's and the path's arrays."""

    def __init__(self, scenario: Scenario, index: int):
        uav = scenario.uavs[index]
        hover_mass = uav.vehicle.mass + scenario.payload.mass / scenario.n_uavs
        self.cascade = CascadeController(uav.vehicle, scenario.control, hover_mass,
                                         scenario.simulation.gravity, swing_rest(scenario))
        control = scenario.control
        self.path = MissionPath(scenario.mission, INPUT_SHAPERS[control.input_shaping],
                                swing_period(scenario))
        self.swing_feedback = bool(control.swing_stiffness or control.swing_damping)
        self._law = laws.runnable(leader_update)

    def update(self, t: float, states: FormationStates
               ) -> tuple[ControlOutput, Reference | None]:
        c, p = self.cascade, self.path
        states = FormationStates.of(states)
        payload = states.payload_position, states.payload_velocity
        if payload[0] is None or payload[1] is None:
            if self.swing_feedback:
                raise ValueError('control.payload_feedback needs the payload\'s position and '
                                 'velocity (FormationStates.payload_position, _velocity)')
            payload = np.zeros(3), np.zeros(3)  # not read without the feedback
        *out, reference = self._law(c.constants, c.mixer.rows, c.memory, p.mission, p.segments,
                                    p.steps, float(t), states.array, *payload)
        return ControlOutput(*out), Reference.of(reference)


def swing_rest(scenario: Scenario) -> tuple[float, float]:
    """s_0 of the swing feedback (`laws.swing`): the payload's (x, y) from the UAVs' mean
    position at the formation's hanging rest [m] (`simulation.formation_start`, without the
    payload.swing_deg release); 0 for one UAV, whose payload hangs straight below."""
    if scenario.n_uavs == 1:
        return 0.0, 0.0
    uavs, payload = formation_start(scenario)
    offset = payload - uavs.mean(axis=0)
    return float(offset[0]), float(offset[1])


def swing_period(scenario: Scenario) -> float:
    """The hanging payload's pendulum period 2 pi sqrt(h / g) [s], h its depth below the UAVs'
    mean position at the formation's hanging rest (one UAV: its cable's length): what
    `control.payload_feedback.input_shaping` shapes the mission's corners for. For two UAVs it
    is the swing across their line (along it the cables hold the payload to the UAVs)."""
    if scenario.n_uavs == 1:
        depth = scenario.uavs[0].cable_length
    else:
        uavs, payload = formation_start(scenario)
        depth = float(uavs.mean(axis=0)[2] - payload[2])
    return 2.0 * math.pi * math.sqrt(depth / scenario.simulation.gravity)


# the leader's controller by `control.mode`: the names are the scenario's registry
# (multilift_sim.scenario.CONTROL_MODES, which validation reads), in its order
LEADER_CONTROLLERS = {'cascade': MissionLeader, 'constant_rotor_speed': ConstantRotorSpeed}
if tuple(LEADER_CONTROLLERS) != CONTROL_MODES:
    raise ImportError(f'LEADER_CONTROLLERS {tuple(LEADER_CONTROLLERS)} must be the scenario\'s '
                      f'control modes {CONTROL_MODES}')


def make_controller(scenario: Scenario, index: int) -> Controller:
    """The leader's controller named by the scenario's control.mode."""
    return LEADER_CONTROLLERS[scenario.control.mode](scenario, index)
