"""The tasks a learning environment poses (one registry, `TASKS`), and the scenario it flies.

A task says where the payload should be at each tick (its target, world frame z up [m], and
the target's velocity [m/s]) and how a reset draws it. Every environment's observation and
reward are built on that target (`multilift_learning.batch`).

- `hover`: hold the payload still at its rest place under the UAVs' start (statistics.swing.
  equilibrium_point: a scenario may release it swinging) moved by a horizontal offset drawn
  at each reset, uniform in a disc of `target_radius` [m] (0: the rest place itself). The
  scenario's leader, when it has a mission, gets one that hovers there (`task_scenario`; the
  mission's place follows each draw), so the seed's controllers hold the target too.
- `mission`: follow the scenario's mission (seed §4.2): the payload's target is the leader's
  mission reference (`multilift_control.laws.reference.mission_reference`) less the leader's
  start offset from the payload's rest place; its velocity the reference's.
- `navigate` (issue 34 item 7): bring the payload to a goal past the world's obstacles
  (`world:`, docs/obstacles.md): the target is where the mission leaves the payload, its
  reference at the end less the leader's offset, held from the start (the scenario's own
  leader flies the mission's waypoints around the obstacles: the baseline); a contact stops
  the formation (Algorithm 1's stop, `physics.clearance`), which ends the episode.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import yaml

from multilift_control.laws.layout import (FORM_POLYNOMIAL, MISSION_FINAL, MISSION_FORM,
                                           MISSION_START, PIECE_COEFFICIENTS, PIECE_ORDER,
                                           REFERENCE_POSITION, REFERENCE_VELOCITY,
                                           SEGMENT_ORIGIN)
from multilift_sim import scenario as scenario_io
from multilift_sim.registry import one_of
from multilift_sim.scenario import MissionConfig, MissionSegment, Scenario
from multilift_tools.campaign import edited, format_value, load_base, parse_key


@dataclass(frozen=True)
class Task:
    """A task's name, what it asks, and whether it needs the scenario's mission."""
    name: str
    summary: str
    needs_mission: bool


TASKS = {
    'hover': Task('hover', 'hold the payload still at a point drawn near its start', False),
    'mission': Task('mission', "follow the scenario's mission with the payload", True),
    'navigate': Task('navigate', "bring the payload to the mission's end past the world's "
                     'obstacles; a contact ends the episode', True),
}


def task(name: str) -> Task:
    """The registered task `name` (ValueError naming the known ones otherwise)."""
    one_of('task', name, TASKS)
    return TASKS[name]


def scenario_of(source: str | Scenario, overrides: dict[str, Any] | None = None,
                duration: float | None = None) -> Scenario:
    """The scenario an environment flies: a Scenario, or a scenario name or path with
    `overrides` ({'payload.mass': 1.2, ...}: the keys of `multilift sweep --set`), validated by
    the scenario loader; `duration` [s] replaces simulation.duration (the episode's length)."""
    if isinstance(source, Scenario):
        if overrides:
            raise ValueError('overrides apply to a scenario name or path, not a Scenario')
        scenario = source
    elif overrides:
        path, base = load_base(source)
        edits = [(key, tuple(parse_key(key, 'overrides')), value)
                 for key, value in overrides.items()]
        label = f'{path} with ' + ', '.join(f'{k}={format_value(v)}' for k, _, v in edits)
        scenario = scenario_io.loads(yaml.safe_dump(edited(base, edits), sort_keys=False), label)
    else:
        scenario = scenario_io.load(source)
    return scenario if duration is None else scenario.with_duration(duration)


def task_scenario(scenario: Scenario, task_name: str, start: str = 'rest') -> Scenario:
    """The scenario as `task_name` flies it: its cables slack-capable (`learning_cable_model`:
    a cable pulls, never pushes); with start 'rest' the payload hangs still at its rest place
    (no release swing; multilift_learning.options.STARTS); for hover, a leader with a mission
    hovers at its start for the whole duration (one segment at rest)."""
    task(task_name)
    scenario = replace(scenario, cable_model=learning_cable_model(scenario))
    if start == 'rest':
        scenario = replace(scenario, payload=replace(scenario.payload, swing=0.0, alpha=0.0,
                                                     beta=0.0))
    if task_name != 'hover' or scenario.control.mode != 'cascade':
        return scenario
    hold = MissionSegment(velocity=(0.0, 0.0, 0.0), end_time=scenario.simulation.duration)
    if _seed_mission(scenario):
        return replace(scenario, mission=replace(scenario.mission, segments=(hold,)))
    # another source (waypoints, a file, the payload tracked): a segments mission from the
    # leader's start
    return replace(scenario, mission=MissionConfig(start=scenario.uavs[0].position,
                                                   segments=(hold,)))


def learning_cable_model(scenario: Scenario) -> str:
    """The cable model a learning task flies: the seed's rigid cables become `slack` (a cable
    that pulls, never pushes), except on winches, which the slack model does not reel yet (a
    reeled rigid cable stays bilateral: docs/learning.md); other models as they are (an
    elastic rope pushes never)."""
    if scenario.cable_model == 'rigid' and not scenario.winches:
        return 'slack'
    return scenario.cable_model


def _seed_mission(scenario: Scenario) -> bool:
    """Whether the scenario's mission is the default source's (segments) for the leader."""
    return scenario.mission.type == 'segments' and scenario.mission.tracks == 'leader'


def task_scenario_yaml(source: str, task_name: str, start: str = 'rest',
                       duration: float | None = None) -> str:
    """The YAML of scenario `source` (a name or path) as `task_name` flies it (`task_scenario`,
    with `duration` [s]): a file `multilift run` flies, so a policy trained on the task flies
    the same physics through ROS (`policy_node`)."""
    path, data = load_base(source)
    scenario = task_scenario(scenario_of(source, duration=duration), task_name, start)
    data = dict(data, cable_model=scenario.cable_model)
    data['simulation'] = dict(data['simulation'], duration=scenario.simulation.duration)
    if start == 'rest':
        data['payload'] = {k: v for k, v in data['payload'].items()
                           if k not in ('swing_deg', 'alpha_deg', 'beta_deg')}
    if task_name == 'hover' and scenario.control.mode == 'cascade':
        hold = [{'velocity': [0.0, 0.0, 0.0], 'until': scenario.simulation.duration}]
        data['mission'] = (dict(data['mission'], segments=hold)
                           if _seed_mission(scenario_of(source))
                           else {'start': list(scenario.mission.start), 'segments': hold})
    header = f'# {path} as the learning task {task_name!r} flies it (multilift_learning.tasks)\n'
    return header + yaml.safe_dump(data, sort_keys=False)


class Targets:
    """The payload's target of B formations of one engine (`engine.arrays`) under `task`:
    `position(t)`, `velocity(t)` (B, 3) at each formation's time t (B,) [s]; `reset(which,
    rngs)` draws new ones (hover)."""

    def __init__(self, name: str, engine, start_payload: np.ndarray, start_offsets: np.ndarray,
                 target_radius: float):
        self.task = task(name)
        self.arrays = engine.arrays
        self.references = engine.references   # (B,) times -> (B, REFERENCE_SIZE), compiled
        self.start_payload = start_payload          # (B, 3): its rest place at the start [m]
        self.leader_offset = start_offsets[:, 0]    # (B, 3): the leader above the payload [m]
        self.target_radius = float(target_radius)
        if self.target_radius < 0:
            raise ValueError(f'target_radius must be >= 0 [m], got {target_radius}')
        self.hold = start_payload.copy()            # hover's targets (B, 3)
        if self.task.name == 'navigate':            # the mission's end, held from the start
            end = self.arrays.tick_count * self.arrays.period_ns * 1e-9
            self.hold = (self.references(end)[:, REFERENCE_POSITION:REFERENCE_POSITION + 3]
                         - self.leader_offset)

    def reset(self, which: np.ndarray, rngs: list[np.random.Generator]) -> None:
        """New targets for the formations in `which` (B,) bool, each from its own generator;
        for hover the leader's mission (its positions: start, end, each segment's origin or
        each polynomial piece's constant term) moves with the target."""
        if self.task.name != 'hover':   # the mission's targets move with it, navigate's stay
            return
        a = self.arrays
        for b in np.flatnonzero(which):
            offset = np.zeros(3)
            if self.task.name == 'hover' and self.target_radius > 0:
                radius = self.target_radius * np.sqrt(rngs[b].uniform())
                angle = rngs[b].uniform(0.0, 2.0 * np.pi)
                offset[:2] = radius * np.cos(angle), radius * np.sin(angle)
            shift = offset - (self.hold[b] - self.start_payload[b])
            self.hold[b] = self.start_payload[b] + offset
            if self.task.name == 'hover':
                a.mission[b, MISSION_START:MISSION_START + 3] += shift
                a.mission[b, MISSION_FINAL:MISSION_FINAL + 3] += shift
                if a.mission[b, MISSION_FORM] == FORM_POLYNOMIAL:  # each piece's constant
                    for axis in range(3):
                        a.segments[b, :, PIECE_COEFFICIENTS + axis * PIECE_ORDER] += shift[axis]
                else:
                    a.segments[b, :, SEGMENT_ORIGIN:SEGMENT_ORIGIN + 3] += shift

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(position, velocity) of each formation's target at its time t (B,) [s]."""
        if self.task.name in ('hover', 'navigate'):
            return self.hold, np.zeros_like(self.hold)
        reference = self.references(t)
        return (reference[:, REFERENCE_POSITION:REFERENCE_POSITION + 3] - self.leader_offset,
                reference[:, REFERENCE_VELOCITY:REFERENCE_VELOCITY + 3])
