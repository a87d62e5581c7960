"""Cable models as registered parts (issue 31): `cable_model:` names one of `CABLE_MODELS`,
which the scenario's validation, the tick's arrays, the start and the formulations read.

A cable model's module declares:
- `NAME`, the scenario's `cable_model`;
- `NEEDS`: what the formulation must model for it (features of `formulations.FEATURES`);
- `RELEASE_LIMIT_DEG` [deg]: how far from hanging a single payload may start (`payload.
  alpha_deg`): 90, or 180 where a cable may start slack;
- `KEEPS_LENGTH`: whether the cable is the seed's constraint g_i = 0 (Eq. 2.42), so that
  Algorithm 1's check of g and g_dot applies and the start hangs at the rest lengths;
- `SLACKENS`: whether a cable may go slack and snap taut (physics.slack_cables' taut set);
- `REELS`: whether a winch may reel it (`uavs[i].winch`: cables.winch, physics.winch);
- `parse_cable(top) -> base` (the scenario's `cable:` section, a `reading.Section`; kept as
  `Scenario.cable`) and `parse_uav_cable(u, length, base) -> (k [N/m], c [N s/m])`
  (`uavs[i].cable:` over it);
- `check(scenario) -> str | None`: what it cannot carry, in one line (None: it flies).

How a model's physics is stepped stays in physics/ (the rigid and slack solves, the elastic
ropes: `physics.elastic_cables`), selected by these declarations; docs/cables.md.
"""
from __future__ import annotations

from multilift_sim.cables import chain, elastic, rigid, slack
from multilift_sim.registry import Registry

CABLE_MODELS = Registry(
    'cable model', ('NAME', 'NEEDS', 'RELEASE_LIMIT_DEG', 'KEEPS_LENGTH', 'SLACKENS',
                    'REELS', 'parse_cable', 'parse_uav_cable', 'check'),
    (rigid, slack, elastic, chain))
register, unregister, registered = (CABLE_MODELS.register, CABLE_MODELS.unregister,
                                    CABLE_MODELS.registered)
