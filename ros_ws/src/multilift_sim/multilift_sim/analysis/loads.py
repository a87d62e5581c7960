"""Load shares (issue 35, the seed's §5.2 third suggestion): how a formation shares its payload
among its cables and what each UAV's rotors have left, from the statics of Eq. 2.73. World frame
(z up), SI units.

- At hover: the static equilibrium itself (`equilibrium.scenario_equilibrium`: each cable's
  tension, each UAV's thrust u_T, attitudes and attach points included).
- Moving: quasi-statically, the whole formation at one acceleration a and velocity v (the
  mission reference's): in the formation's frame every body feels g e_z + a instead of g e_z,
  and the payload its drag in still air (Eq. 2.53). The UAVs keep their hover places (the
  followers hold the geometry); a point payload hangs where its apparent weight and drag take
  it (the lowest point along them the cables reach: a single lift's swings out fully, a
  twin-lift's about the UAVs' line, three cables or more pin it), its tensions from its rows
  (`equilibrium.payload_multipliers`) over the cables still taut; a rigid body hangs where it
  rests, turned, under them (its force and moment rows with every cable at its length, solved
  by the `hang_body` the caller passes: multilift_control's `laws.rigid_statics.hang_body`,
  which this layer cannot import; four cables or more: its least-norm steps' rest). A UAV
  held off its centre is not solved (it would tilt): its hover only. UAV i's rotors give
  u_T,i = |m_i (g e_z + a) - 2 lambda_i d_i| (its row of Eq. 2.73).

A UAV's thrust margin is 1 - u_T / u_T,max, u_T,max its rotors' thrust at rotor_speed_max (Eq.
2.9): the share of its largest thrust left. Transients (a payload swinging after a corner, the
controllers' overshoot) are not in it: the run summary's least thrust margin measures them.
With four cables or more the statics are indeterminate; the least-norm tensions are the
formation's when the UAVs are equal and symmetric, not in general.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.analysis.coordinates import cable_offsets
from multilift_sim.analysis.equilibrium import (payload_multipliers, scenario_configuration,
                                                scenario_equilibrium)
from multilift_sim.constraints import cable_tension
from multilift_sim.formation_geometry import lowest_reached
from multilift_sim.scenario import Scenario

TAUT = 1e-6  # a cable within this share of its length of taut carries load [-]


@dataclass(frozen=True)
class LoadShares:
    """Each cable's tension and each UAV's thrust under one (quasi-)static load."""
    acceleration: np.ndarray    # a (3,) [m/s^2], world: the formation's
    tensions: np.ndarray        # T_i (n,) [N]
    thrusts: np.ndarray         # u_T,i (n,) [N]
    largest_thrusts: np.ndarray  # u_T,max,i (n,) [N]: every rotor at rotor_speed_max

    @property
    def margins(self) -> np.ndarray:
        """1 - u_T / u_T,max (n,) [-]: negative where the rotors cannot give the thrust."""
        return 1.0 - self.thrusts / self.largest_thrusts


def largest_thrusts(scenario: Scenario) -> np.ndarray:
    """u_T,max (n,) [N]: each UAV's rotors all at rotor_speed_max (Eq. 2.9)."""
    return np.array([u.vehicle.collective_thrust(np.full(u.vehicle.n_rotors,
                                                         u.vehicle.rotor_speed_max))
                     for u in scenario.uavs])


def hover_loads(scenario: Scenario) -> LoadShares:
    """The shares at the formation's hanging rest (Eq. 2.73 exactly; ValueError as
    `static_equilibrium` raises it where the formation cannot hover)."""
    equilibrium = scenario_equilibrium(scenario)
    return LoadShares(np.zeros(3), equilibrium.tensions, equilibrium.wrenches[:, 0].copy(),
                      largest_thrusts(scenario))


class QuasiStatic:
    """The quasi-static shares of one scenario's formation (the module's docstring), its hover
    configuration computed once: `loads(acceleration, velocity)` per instant. A rigid body's
    needs `hang_body(uavs (n, 3), lengths (n,), attach (n, 3), load (3,)) -> (p, R, lambda,
    found)`, its rest under `load` [N] (lambda_i d_i its cables' pulls, d_i from the body's
    end to the UAV's)."""

    def __init__(self, scenario: Scenario, hang_body: Callable | None = None):
        self.params = scenario.formation_params(0.0, 0.0)
        if self.params.uav_attach_points is not None or (self.params.rigid_payload
                                                         and hang_body is None):
            raise ValueError('quasi-static loads under acceleration are solved for cables from '
                             'the UAVs\' centres (a UAV held off its centre would tilt): hover '
                             'loads only' if self.params.uav_attach_points is not None else
                             'a rigid body\'s quasi-static loads need its statics '
                             '(multilift_control\'s laws.rigid_statics.hang_body)')
        self.hang_body = hang_body
        self.uavs, self.hover_payload = scenario_configuration(scenario)
        self.lengths = np.asarray(self.params.cable_lengths, dtype=float)
        self.masses = np.array([u.vehicle.mass for u in scenario.uavs])
        self.largest = largest_thrusts(scenario)

    def loads(self, acceleration: ArrayLike, velocity: ArrayLike = (0.0, 0.0, 0.0)
              ) -> LoadShares:
        """The shares with the formation at `acceleration` [m/s^2] and `velocity` [m/s],
        world, in still air. ValueError where no cable holds the payload."""
        params = self.params
        a = np.asarray(acceleration, dtype=float).reshape(3)
        v = np.asarray(velocity, dtype=float).reshape(3)
        effective = np.array([0.0, 0.0, params.gravity]) + a     # g e_z + a [m/s^2]
        speed = float(np.linalg.norm(v))
        # what the cables must give the payload [N]: m_p (g e_z + a) less its drag (Eq. 2.53)
        load = params.payload_mass * effective + params.payload_drag_coefficient * speed * v
        if params.rigid_payload:
            return self._rigid_loads(a, effective, load)
        payload = _hang(self.uavs, self.hover_payload, self.lengths, load)
        offsets = cable_offsets(params, self.uavs, payload, None)  # d_i, (n, 3)
        taut = np.linalg.norm(offsets, axis=1) >= self.lengths * (1.0 - TAUT)
        if not taut.any():
            raise ValueError('every cable is slack: the payload falls')
        multipliers = np.zeros(len(self.lengths))
        multipliers[taut] = payload_multipliers(params, offsets[taut], None, load,
                                                tolerance=1e-6)
        forces = self.masses[:, None] * effective - 2.0 * multipliers[:, None] * offsets
        return LoadShares(a, cable_tension(multipliers, self.lengths),
                          np.linalg.norm(forces, axis=1), self.largest)

    def _rigid_loads(self, acceleration: np.ndarray, effective: np.ndarray,
                     load: np.ndarray) -> LoadShares:
        """A rigid body's shares: at its rest under `load` [N] (`hang_body`), T_i = lambda_i
        |d_i| and u_T,i = |m_i (g e_z + a) + lambda_i d_i|."""
        attach = np.asarray(self.params.payload_attach_points, dtype=float)
        position, rotation, multipliers, found = self.hang_body(self.uavs, self.lengths,
                                                                 attach, load)
        if not found:
            raise ValueError('the rigid body finds no rest under the load '
                             f'{np.array2string(load, precision=3)} N')
        if multipliers.min() < 0.0:
            raise ValueError('a cable of the rigid body would push under the load '
                             f'{np.array2string(load, precision=3)} N')
        gaps = self.uavs - position - attach @ np.asarray(rotation).T      # d_i, (n, 3)
        forces = self.masses[:, None] * effective + multipliers[:, None] * gaps
        return LoadShares(acceleration, multipliers * np.linalg.norm(gaps, axis=1),
                          np.linalg.norm(forces, axis=1), self.largest)


def _hang(uavs: np.ndarray, start: np.ndarray, lengths: np.ndarray,
          load: np.ndarray) -> np.ndarray:
    """Where a point payload hangs with its cables from `uavs` (n, 3) [m] when they must give
    it `load` [N] (its apparent weight and drag): `formation_geometry.lowest_reached` along
    -load; `start` (the hover place) when the cables cannot all reach one point."""
    reached = lowest_reached(uavs, lengths, -load / np.linalg.norm(load))
    return np.asarray(start, dtype=float) if reached is None else reached
