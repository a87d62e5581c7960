"""What a scenario asks that its bodies cannot be or its vehicles cannot fly, refused at load
(after `parse` has read every key): each a one-line `ScenarioError` naming the file, the key,
the value and the rule.

- A rigid payload's attach points lie on or inside its shape
  (`payloads.rigid_body.distance_outside`, within `attach_margin`: 1 mm or 1 % of its largest
  dimension).
- A mission segment's speed is at most MAX_MISSION_SPEED [m/s]: a generous cap (a fast
  multirotor's top speed; the seed flies 0.5 m/s), not a derived limit; a cable-carried payload
  flies well below it.
- Each horizontal corner of a filtered mission (`mission.reference_filter_time` tau > 0, the
  critically damped prefilter of `multilift_control.mission.MissionPath`) asks a peak
  acceleration |dv| / (e tau) [m/s^2] of the reference; it must be at most what the formation
  can give while it holds its altitude, g min(tan(max_tilt), sqrt((T / W)^2 - 1)) with T the
  sum of the UAVs' top thrusts and W the formation's weight (the thrust left after the weight,
  tilted, and the controllers' tilt limit). That bound is necessary, not sufficient: what it
  refuses no UAV of the formation can fly, what it passes may still saturate a rotor. Raw
  velocity steps (tau = 0, the seed's path) ask an unbounded acceleration by construction and
  the outer loop's tilt limit shapes them, so only their speed is checked.
"""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.payloads.rigid_body import attach_margin, distance_outside, shape_extent
from multilift_sim.scenario.config import Scenario, ScenarioError

MAX_MISSION_SPEED = 20.0  # [m/s] a mission segment's speed, at most


def check_limits(scenario: Scenario) -> None:
    """Raise ScenarioError for the first thing `scenario` asks beyond its bodies or vehicles
    (the module docstring's rules)."""
    _check_attach_points(scenario)
    _check_mission(scenario)


def _fail(scenario: Scenario, key: str, value, rule: str) -> ScenarioError:
    return ScenarioError(f'{scenario.source}: {key}: {value!r} {rule}')


def _check_attach_points(scenario: Scenario) -> None:
    p = scenario.payload
    if p.type != 'rigid_body' or not p.attach_points:
        return
    margin = attach_margin(p.shape, p.size)
    for k, point in enumerate(p.attach_points):
        outside = distance_outside(p.shape, p.size, point)
        if outside > margin:
            raise _fail(scenario, f'payload.attach_points[{k}]', list(point),
                        f'must lie on or inside the {p.shape} of size {list(p.size)} m '
                        f'({shape_extent(p.shape, p.size)}, within {margin:g} m): it is '
                        f'{outside:.3g} m outside')


def max_mission_acceleration(scenario: Scenario) -> float:
    """The horizontal acceleration [m/s^2] the formation can give while holding its altitude:
    g min(tan(max_tilt), sqrt((T / W)^2 - 1)) (the module docstring)."""
    g = scenario.simulation.gravity
    ratio = sum(u.vehicle.max_thrust for u in scenario.uavs) / scenario.total_weight()
    return g * min(math.tan(scenario.control.max_tilt), math.sqrt(max(ratio * ratio - 1.0, 0.0)))


def _check_polynomial(scenario: Scenario) -> None:
    """A polynomial mission's speed (sampled 64 times a piece) at most MAX_MISSION_SPEED; no
    input shaper (it shapes the segments' velocity steps)."""
    mission = scenario.mission
    if scenario.control.input_shaping != 'none':
        raise _fail(scenario, 'mission.type', mission.type,
                    f'cannot be flown with input_shaping {scenario.control.input_shaping!r} '
                    f'(it shapes the velocity steps of mission.type segments)')
    powers = np.arange(1, 8)
    for k, piece in enumerate(mission.coefficients):
        duration = mission.knots[k + 1] - mission.knots[k]
        local = np.linspace(0.0, duration, 64)[:, None]
        velocity = (np.array(piece)[:3, 1:] * powers) @ (local ** (powers - 1)).T
        speed = float(np.sqrt((velocity ** 2).sum(axis=0)).max())
        if speed > MAX_MISSION_SPEED:
            raise _fail(scenario, 'mission.type', mission.type,
                        f'asks a speed of {speed:.3g} m/s between {mission.knots[k]:g} and '
                        f'{mission.knots[k + 1]:g} s, more than {MAX_MISSION_SPEED:g} m/s '
                        f'(limits.MAX_MISSION_SPEED)')


def _check_mission(scenario: Scenario) -> None:
    if scenario.mission.knots:
        _check_polynomial(scenario)
    segments = scenario.mission.segments
    for k, segment in enumerate(segments):
        speed = math.sqrt(sum(v * v for v in segment.velocity))
        if speed > MAX_MISSION_SPEED:
            raise _fail(scenario, f'mission.segments[{k}].velocity', list(segment.velocity),
                        f'must have a speed of at most {MAX_MISSION_SPEED:g} m/s '
                        f'(limits.MAX_MISSION_SPEED), got {speed:.3g} m/s')
    tau = scenario.mission.reference_filter_time
    if tau <= 0.0 or not segments or scenario.control.mode != 'cascade':
        return
    limit = max_mission_acceleration(scenario)
    velocities = np.array([s.velocity for s in segments] + [(0.0, 0.0, 0.0)])[:, :2]
    steps = np.diff(np.vstack((np.zeros((1, 2)), velocities)), axis=0)  # from and to rest
    for k, dv in enumerate(steps):
        peak = float(np.hypot(*dv)) / (math.e * tau)
        if peak > limit:
            key = (f'mission.segments[{k}].velocity' if k < len(segments)
                   else f'mission.segments[{k - 1}].velocity')
            value = list(segments[min(k, len(segments) - 1)].velocity)
            raise _fail(scenario, key, value,
                        f'asks {peak:.3g} m/s^2 at its corner (|dv| / (e reference_filter_time)'
                        f'), more than the formation can fly: {limit:.3g} m/s^2 = g min(tan '
                        f'max_tilt, sqrt((T/W)^2 - 1)), T/W the rotors\' top thrust over the '
                        f'weight')
