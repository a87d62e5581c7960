"""The keys of a formation that reorganises to share its payload (issue 35 item 2; the law:
multilift_control's follower `thrust_margin`, `laws.reorganize`), read and checked once:

- `formation.reorganize`: `none` (the seed's fixed geometry, the default), `thrust_margin`
  (the followers' horizontal offsets move online so that the UAVs' thrust margins stay even,
  or above the floor) or `cable_forces` (they move where the cables carry the shares that
  give the UAVs the least largest share of their largest thrust, by the statics of Eq. 2.73:
  any n >= 2, a point payload; n = 2's follower also changes height) or `heading` (they turn about
  the leader with its heading: its yaw from its start, as a mission's yaw turns it; issue 34,
  the `window` scenario); needs a linear or V formation of two UAVs or more;
- `formation.min_spacing` [m] (default 1.0): the least horizontal distance between two UAVs;
  a point payload's cables meet at the payload, so their spacing grows with the UAVs';
- `formation.max_spread` [m] (default: none): the largest horizontal distance between two UAVs;
- `formation.max_offset_rate` [m/s] (default 0.2): the largest speed of a follower's offset;
- `formation.thrust_margin_floor` [share, 0..1) (default 0.05): the margin below which a UAV's
  shortfall weighs FLOOR_WEIGHT times its spread from the others';
- `formation.start_places` (default: the geometry's places): each follower's [x, y] from the
  leader at t = 0 [m], world: the formation starts at the hover equilibrium of the geometry
  it flies (the UAVs level with the leader, a point payload on rigid or slack cables hanging
  where every cable reaches: `simulation.formation_start`); for `thrust_margin` and
  `cable_forces` only, whose offsets start there (a fixed formation starts at its geometry's).
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
    values['start_places'] = _start_places(f, n, geometry)
    if values['start_places'] and kind not in SPACED:
        raise f.fail('start_places', f.raw('start_places'),
                     f'starts a reorganising formation (thrust_margin, cable_forces), not '
                     f'{kind!r}: a fixed one starts at its geometry\'s places')
    if values['max_spread'] < values['min_spacing']:
        raise f.fail('max_spread', values['max_spread'],
                     f'must be >= formation.min_spacing ({values["min_spacing"]})')
    return values


def _start_places(f: Section, n: int, geometry: str) -> tuple[tuple[float, float], ...]:
    """`formation.start_places`: n - 1 [x, y] pairs [m], for linear and V formations."""
    if not f.has('start_places'):
        return ()
    raw = f.raw('start_places')
    if geometry not in ('v', 'linear'):
        raise f.fail('start_places', raw, f'places linear or V followers, not a {geometry!r} '
                                          'formation')
    if not isinstance(raw, list) or len(raw) != n - 1:
        raise f.fail('start_places', raw, f'must list one [x, y] per follower ({n - 1})')
    holder = Section({str(k): v for k, v in enumerate(raw)}, f.key('start_places'), f.where)
    places = tuple(tuple(holder.vector(str(k), length=2)) for k in range(n - 1))
    holder.done()
    return places


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


def point_statics_refused(scenario) -> str | None:
    """Why the statics of a point payload on cables that keep their length, held at the UAVs'
    centres (`simulation.formation_start`, `laws.reorganize`), do not hold the scenario's
    formation at rest (a rigid body, a cable model, attach points), or None when they do."""
    return ('a rigid-body payload' if scenario.payload.type == 'rigid_body' else
            f'cable_model {scenario.cable_model!r}' if scenario.cable_model not in ('rigid',
                                                                                    'slack')
            else 'cables held off the UAVs\' centres' if any(any(u.attach_point)
                                                             for u in scenario.uavs) else None)


def starts_at_rest(scenario) -> bool:
    """Whether the formation starts at the static equilibrium of Eq. 2.73 with its controllers
    trimmed to it (`start.start_equilibrium`): a reorganising formation (thrust_margin,
    cable_forces) of a point payload whose statics hold (`point_statics_refused`) or of a rigid
    body (`rigid_start`); every other starts level (the seed's start)."""
    f = scenario.formation
    return (f is not None and f.reorganize in SPACED and scenario.n_uavs > 1
            and (point_statics_refused(scenario) is None or rigid_start(scenario)))


def rigid_start(scenario) -> bool:
    """A rigid body on cables that keep their length from the UAVs' centres, hung level at the
    geometry's places or where it hangs from `start_places` (`start.start_body_pose`): what
    the rigid statics of the law (`laws.rigid_statics`) and the start's equilibrium hold."""
    return (scenario.payload.type == 'rigid_body' and scenario.cable_model in ('rigid', 'slack')
            and not any(any(u.attach_point) for u in scenario.uavs))


def check_start_places(scenario) -> None:
    """`formation.start_places` hangs a point payload or a rigid body (`rigid_start`) from
    cables that keep their length, held at the UAVs' centres (the start's statics,
    `simulation.formation_start`)."""
    why = point_statics_refused(scenario)
    if why is not None and not rigid_start(scenario):
        raise ScenarioError(f'{scenario.source}: formation.start_places: hangs a point payload '
                            f'on rigid or slack cables from the UAVs\' centres, not {why}')


def check_payload(scenario) -> None:
    """`cable_forces` allocates a point payload's cables (its triangle of forces meets at one
    point) or a rigid body's (`laws.rigid_allocation`, `rigid_start`): another body is
    refused."""
    f = scenario.formation
    if f is not None and f.reorganize == 'cable_forces' and scenario.payload.type == 'rigid_body' \
            and not rigid_start(scenario):
        raise ScenarioError(f'{scenario.source}: formation.reorganize: \'cable_forces\' allocates '
                            'a point payload\'s cables or a rigid body\'s on cables that keep '
                            'their length from the UAVs\' centres, not this one')
