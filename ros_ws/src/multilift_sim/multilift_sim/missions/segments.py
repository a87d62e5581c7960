"""`mission.type: segments` (the default): the seed's mission (§4.2), piecewise-constant
velocity segments from `mission.start`, each with a `velocity` [m/s] (world) and a `duration`
or an `until` [s]; `reference_filter_time` tau [s] the prefilter of its corners
(`multilift_control.mission.MissionPath`)."""
from __future__ import annotations

from pathlib import Path

from multilift_sim.scenario.config import MissionConfig, MissionSegment, ScenarioError
from multilift_sim.scenario.reading import Section

NAME = 'segments'
FORM = 'velocity_segments'


def read(m: Section, start: tuple[float, float, float], folder: Path) -> MissionConfig:
    """`mission.start`, `segments`, `reference_filter_time`."""
    start = m.vector('start', list(start))
    segments = []
    t_prev = 0.0
    for i, entry in enumerate(m.sequence('segments', [])):
        seg = Section(entry, f'mission.segments[{i}]', m.where)
        velocity = seg.vector('velocity')
        if seg.has('duration') == seg.has('until'):
            raise ScenarioError(f'{m.where}: {seg.path}: give exactly one of duration, until')
        if seg.has('duration'):
            end = t_prev + seg.positive('duration')
        else:
            end = seg.number('until', ..., lambda t: t > t_prev, f'must be > {t_prev}')
        seg.done()
        segments.append(MissionSegment(velocity=velocity, end_time=end))
        t_prev = end
    return MissionConfig(start=start, segments=tuple(segments),
                         reference_filter_time=m.non_negative('reference_filter_time', 0.0))
