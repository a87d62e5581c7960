"""Every rotor of the leader at one speed (`control.mode: constant_rotor_speed`, the seed's
open-loop test of §4.1): `control.constant_rotor_speed` [rad/s], or without it (null) the speed
whose thrust balances the whole formation's weight shared equally, clipped to the rotors'
range (then flagged saturated)."""
from __future__ import annotations

import math

import numpy as np

from multilift_control.cascade import balancing_rotor_speed
from multilift_control.laws import jit
from multilift_control.laws.layout import CASCADE_THRUST_COEFFICIENT, REFERENCE_SIZE
from multilift_control.laws.mixer import collective_thrust
from multilift_sim.scenario import Scenario

NAME = 'constant_rotor_speed'
KEYS = ('constant_rotor_speed',)
TRACKS_MISSION = False

# its constants
SPEED = 0       # every rotor's speed [rad/s], within the rotors' range
SATURATED = 1   # 1: the speed asked was outside the range (clipped); 0: not
SIZE = 2


def parse(c) -> dict:
    """constant_rotor_speed [rad/s] > 0, or null (the balancing speed)."""
    speed = c.raw('constant_rotor_speed', None)
    return {'constant_rotor_speed': None if speed is None
            else c.positive('constant_rotor_speed')}


def arrays(scenario: Scenario, index: int) -> tuple[np.ndarray, np.ndarray]:
    """(constants: SPEED, SATURATED; memory: none)."""
    vehicle = scenario.uavs[index].vehicle
    speed = scenario.control.constant_rotor_speed
    if speed is None:  # balance the whole formation's weight, shared equally
        mass = sum(u.vehicle.mass for u in scenario.uavs) + scenario.payload.mass
        speed = balancing_rotor_speed(vehicle, mass / scenario.n_uavs,
                                      scenario.simulation.gravity)
    clipped = min(max(speed, vehicle.rotor_speed_min), vehicle.rotor_speed_max)
    constants = np.empty(SIZE)
    constants[SPEED] = clipped
    constants[SATURATED] = float(clipped != speed)
    return constants, np.zeros(0)


@jit
def answer(constants, memory, cascade, mixer, mission, segments, steps, t, states,
           payload_position, payload_velocity, speeds, saturated, setpoint, reference):
    """The same command every tick: every rotor at SPEED, no attitude set-point (zeros), no
    reference (NaN); returns the rotors' collective thrust [N]."""
    for k in range(speeds.shape[0]):
        speeds[k] = constants[SPEED]
        saturated[k] = constants[SATURATED] != 0.0
    for k in range(3):
        setpoint[k] = 0.0
    for k in range(REFERENCE_SIZE):
        reference[k] = math.nan
    return collective_thrust(cascade[CASCADE_THRUST_COEFFICIENT], speeds)
