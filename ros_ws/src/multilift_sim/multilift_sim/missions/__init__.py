"""Mission sources as registered parts (issues 31 and 34): `MISSION_SOURCES` (the scenario's
`mission.type` -> its module) is the one registry that validation reads; the leader's
reference (`multilift_control.mission.MissionPath`, which the leader's law, the controller nodes
and the engine fly) reads the part's `FORM`. docs/missions.md, docs/extending.md ("A mission
source") adds one.

A source (a module, or any object, with these names) declares:
- `NAME`: the scenario's `mission.type`;
- `FORM`: the compiled reference it fills, one of FORMS: `velocity_segments` (the seed's
  piecewise-constant velocities with their prefilter and shaper, MissionConfig.segments) or
  `polynomial` (a piecewise polynomial of degree 7 at most in x, y, z [m] and yaw [rad],
  MissionConfig.knots and .coefficients, `polynomials`' layout);
- `read(section, start, folder) -> MissionConfig`: its keys of `mission:` read with checks
  (`scenario.reading.Section`: one-line errors naming the key), `start` the leader's start
  position (world [m], the default of `mission.start`), `folder` the scenario file's folder
  (files it names are relative to it).

Shipped: `segments` (the seed's, the default), `waypoints` (minimum snap), `file` (a CSV).
`mission.tracks` (TRACKED) says which point follows the reference: the leader UAV, or the
payload (then the leader flies the reference shifted by its static offset from the payload).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from types import ModuleType
from typing import Any

from multilift_sim.missions import csv_file, segments, waypoints
from multilift_sim.registry import Registry

FORMS = ('velocity_segments', 'polynomial')
TRACKED = ('leader', 'payload')
DEFAULT_SOURCE = 'segments'


def _check_form(source: Any) -> None:
    if source.FORM not in FORMS:
        raise ValueError(f'mission source {source.NAME!r}: FORM {source.FORM!r} must be one of '
                         f'{", ".join(FORMS)}')


SHIPPED: tuple[ModuleType, ...] = (segments, waypoints, csv_file)
MISSION_SOURCES = Registry('mission source', ('NAME', 'FORM', 'read'), SHIPPED,
                           check=_check_form)
register, unregister, registered = (MISSION_SOURCES.register, MISSION_SOURCES.unregister,
                                    MISSION_SOURCES.registered)


def read_mission(top: Any, start: tuple[float, float, float]) -> Any:
    """The scenario's `mission:` (top: the file's `Section`) as a MissionConfig, read by the
    source its `type` names; `start` the leader's start position, world [m]."""
    from multilift_sim.scenario.config import MissionConfig, ScenarioError  # (imports us)
    config_defaults = MissionConfig(start=(0.0, 0.0, 0.0), segments=())
    m = top.section('mission')
    kind = m.text('type', DEFAULT_SOURCE, choices=tuple(MISSION_SOURCES))
    tracks = m.text('tracks', 'leader', choices=TRACKED)
    source = Path(top.where)
    folder = source.parent if source.is_file() else Path.cwd()
    if tracks == 'payload' and kind == DEFAULT_SOURCE and not m.has('start'):
        raise ScenarioError(f'{top.where}: mission.start: missing key (with mission.tracks: '
                            f'payload the segments start at the payload\'s start position)')
    limits = {key: m.positive(key, getattr(config_defaults, key))
              for key in ('max_speed', 'max_acceleration')}  # a live goal's (run --live)
    config = MISSION_SOURCES[kind].read(m, start, folder)
    m.done()
    return dataclasses.replace(config, type=kind, tracks=tracks, **limits)


def source_of(mission: Any) -> Any:
    """The registered source of a MissionConfig (its `type`)."""
    return MISSION_SOURCES[mission.type]
