"""The keys of a formation that reorganises to share its payload (issue 35 item 2; the law:
multilift_control's follower `thrust_margin`, `laws.reorganize`), read and checked once:

- `formation.reorganize`: `none` (the seed's fixed geometry, the default), `thrust_margin`
  (the followers' horizontal offsets move online so that the UAVs' thrust margins stay even,
  or above the floor) or `cable_forces` (they move where the cables carry the shares that give
  every UAV the same share of its largest thrust: three UAVs) or `heading` (they turn about
  the leader with its heading: its yaw from its start, as a mission's yaw turns it; issue 34,
  the `window` scenario); needs a linear or V formation of two UAVs or more;
- `formation.min_spacing` [m] (default 1.0): the least horizontal distance between two UAVs;
  a point payload's cables meet at the payload, so their spacing grows with the UAVs';
- `formation.max_spread` [m] (default: none): the largest horizontal distance between two UAVs;
- `formation.max_offset_rate` [m/s] (default 0.2): the largest speed of a follower's offset;
- `formation.thrust_margin_floor` [share, 0..1) (default 0.05): the margin below which a UAV's
  shortfall weighs FLOOR_WEIGHT times its spread from the others'.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

from multilift_sim.scenario.config import ScenarioError
from multilift_sim.scenario.reading import Section

REORGANIZE = ('none', 'thrust_margin', 'cable_forces', 'heading')  # each a follower of that name
SPACED = ('thrust_margin', 'cable_forces')  # those held to min_spacing and max_spread


def parse(f: Section, n: int, geometry: str) -> dict[str, Any]:
    """FormationConfig's reorganisation fields from the formation section `f` of n UAVs."""
    kind = f.text('reorganize', 'none', choices=REORGANIZE)
    if kind != 'none' and n < 2:
        raise f.fail('reorganize', kind, 'needs a formation of two UAVs or more (n = 1)')
    if kind == 'cable_forces' and n != 3:
        raise f.fail('reorganize', kind, f'allocates three cables in closed form, not {n}')
    if kind != 'none' and geometry not in ('v', 'linear'):
        raise f.fail('reorganize', kind, f'moves linear or V offsets, not a {geometry!r} '
                                         'formation')
    values = dict(reorganize=kind, min_spacing=f.non_negative('min_spacing', 1.0),
                  max_spread=f.positive('max_spread') if f.has('max_spread') else math.inf,
                  max_offset_rate=f.positive('max_offset_rate', 0.2),
                  thrust_margin_floor=f.number('thrust_margin_floor', 0.05,
                                               lambda v: 0.0 <= v < 1.0,
                                               'must be within [0, 1) (a share of the '
                                               'largest thrust)'))
    if values['max_spread'] < values['min_spacing']:
        raise f.fail('max_spread', values['max_spread'],
                     f'must be >= formation.min_spacing ({values["min_spacing"]})')
    return values


def control_of(c: Section, formation, control):
    """The control section's config with the follower of `formation.reorganize` when the
    formation reorganises (`control.follower` must then be left out or be that follower)."""
    kind = 'none' if formation is None else formation.reorganize
    if control.follower == kind or (kind == 'none' and control.follower not in REORGANIZE):
        return control
    if kind != 'none' and not c.has('follower'):
        return dataclasses.replace(control, follower=kind)
    raise c.fail('follower', control.follower,
                 f'must be the follower of formation.reorganize ({kind!r}) or left out')


def check_start(source: str, formation, uavs) -> None:
    """The formation's start places (uavs (n, 3) [m]) within its spacing and spread limits."""
    if formation is None or formation.reorganize not in SPACED:
        return
    n = len(uavs)
    for i in range(n):
        for j in range(i + 1, n):
            gap = math.hypot(uavs[i][0] - uavs[j][0], uavs[i][1] - uavs[j][1])
            if not formation.min_spacing <= gap <= formation.max_spread:
                raise ScenarioError(
                    f'{source}: formation: UAVs {i + 1} and {j + 1} start {gap:.3g} m apart, '
                    f'outside min_spacing {formation.min_spacing:g} .. max_spread '
                    f'{formation.max_spread:g} m')
