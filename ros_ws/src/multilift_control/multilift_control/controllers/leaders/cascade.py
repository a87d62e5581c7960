"""The mission leader (`control.mode: cascade`, seed Ch. 3 and §4.2): the cascade along the
mission path, one law a tick (`laws.cascade.leader_update`), with the swing feedback of
`control.payload_feedback` (issue 20; `laws.swing`).

Its gains are the vehicle's cascade's (`CascadeController`: the CASCADE_* constants every UAV
has, the swing gains among them); its memory is the position loop's, laws.layout's
CASCADE_INTEGRAL (3) [m/s^2] and CASCADE_LAST_T [s] (NaN before the first tick)."""
from __future__ import annotations

import math

import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.cascade import leader_update
from multilift_control.laws.layout import (CASCADE_HOVER_MASS, CASCADE_INTEGRAL,
                                           CASCADE_LAST_T, CASCADE_MEMORY_SIZE, REFERENCE_SIZE)
from multilift_sim.scenario import Scenario
from multilift_sim.scenario.reorganize import starts_at_rest
from multilift_sim.start import start_equilibrium

NAME = 'cascade'
KEYS = ()                # its gains are the control section's shared keys
TRACKS_MISSION = True    # answers with the mission reference (/uav1/reference)


def arrays(scenario: Scenario, index: int) -> tuple[np.ndarray, np.ndarray]:
    """(constants: none of its own, memory at t = 0: CASCADE_* memory slots; the integral
    zero, or for a formation that starts at rest (`scenario.reorganize.starts_at_rest`) the one
    that holds it there: `start_integral`)."""
    memory = np.zeros(CASCADE_MEMORY_SIZE)
    memory[CASCADE_LAST_T] = math.nan
    if starts_at_rest(scenario):
        memory[CASCADE_INTEGRAL:CASCADE_INTEGRAL + 3] = start_integral(scenario, index)
    return np.zeros(0), memory


def start_integral(scenario: Scenario, index: int) -> np.ndarray:
    """The position loop's integral [m/s^2] (3,) at which UAV `index` asks, at rest on its
    reference, the thrust u_i that holds it at the formation's static equilibrium
    (`multilift_sim.start.start_equilibrium`, a reorganising formation's start): u_i / M_i
    - g e_z, M_i its cascade's hover mass (`position_force`: M_i (integral + g e_z)). The
    integral the seed's start would build as its cable pulls it (a trimmed start)."""
    from multilift_control.controllers import vehicle_cascade  # the registry imports this
    hover_mass = vehicle_cascade(scenario, index).constants[CASCADE_HOVER_MASS]
    integral = start_equilibrium(scenario)[1][index] / hover_mass
    integral[2] -= scenario.simulation.gravity
    return integral


@jit
def answer(constants, memory, cascade, mixer, mission, segments, steps, t, states,
           payload_position, payload_velocity, speeds, saturated, setpoint, reference):
    """The leader's tick at t [s] (`leader_update`): rotor speeds [rad/s] and saturation into
    speeds, saturated (its rotors), roll, pitch, yaw [rad] into setpoint, the mission reference
    (REFERENCE_* slots) into reference; returns the collective thrust asked [N]."""
    s, sat, attitude, thrust, tracked = leader_update(
        cascade, mixer, memory, mission, segments, steps, t, states, payload_position,
        payload_velocity)
    for k in range(s.shape[0]):
        speeds[k] = s[k]
        saturated[k] = sat[k]
    for k in range(3):
        setpoint[k] = attitude[k]
    for k in range(REFERENCE_SIZE):
        reference[k] = tracked[k]
    return thrust
