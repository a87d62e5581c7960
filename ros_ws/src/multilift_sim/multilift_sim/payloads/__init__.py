"""Payload types as registered parts (issue 31): `payload.type` names one of `PAYLOAD_TYPES`,
which the scenario's validation, the docs and the markers read.

A payload type's module declares `NAME` (the scenario's `payload.type`), `NEEDS` (what the
formulation must model for it: features of `formulations.FEATURES`), `MIN_UAVS` and
`parse(p, payload, n) -> PayloadConfig`: its own keys of `payload:` (a reading.Section) over
the common ones (mass, drag, release angles) for n cables. How its physics is stepped stays in
physics/ (`rigid_payload` for the body: the state's payload attitude block).
"""
from __future__ import annotations

from multilift_sim.payloads import point, rigid_body
from multilift_sim.registry import Registry

PAYLOAD_TYPES = Registry('payload type', ('NAME', 'NEEDS', 'MIN_UAVS', 'parse'),
                         (point, rigid_body))
