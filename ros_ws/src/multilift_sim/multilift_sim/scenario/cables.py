"""Elastic ropes (`cable_model: elastic`, issue 32; physics.elastic_cables): the `cable:`
section and each `uavs[i].cable:` override read into each cable's axial stiffness k [N/m] and
damping c [N s/m], and the rate their stepping needs.

Keys (SI): `stiffness` k [N/m], or `axial_stiffness` EA [N] (k = EA / l_i, each cable's own
rest length), and `damping` c [N s/m] (default 0). A UAV's `cable:` overrides what it gives.
"""
from __future__ import annotations

import math
from typing import Any

from multilift_sim.scenario.config import ScenarioError
from multilift_sim.scenario.reading import Section

ROPE_KEYS = ('stiffness', 'axial_stiffness', 'damping')
# the largest omega h [-] an elastic formation is stepped at (omega its fastest mode's bound,
# h the RK4 step): RK4 then loses about (omega h)^6 / 72 = 2.2e-4 of an oscillation's energy
# per step, 0.3 % per period (stable up to 2.8)
ELASTIC_OMEGA_H = 0.5


def base_rope(top: Section, cable_model: str) -> dict[str, Any] | None:
    """The `cable:` section's keys (None unless the cables are elastic; ScenarioError for a
    `cable:` section with other cable models)."""
    if cable_model != 'elastic':
        if top.has('cable'):
            raise top.fail('cable', top.data['cable'], 'needs cable_model: elastic')
        return None
    return _rope_keys(top.section('cable', {}), None)


def uav_rope(u: Section, length: float, base: dict[str, Any] | None) -> tuple[float, float]:
    """UAV i's cable's (k [N/m], c [N s/m]) from its `cable:` over `base`; (0, 0) for a
    cable that is not elastic (base None)."""
    if base is None:
        if u.has('cable'):
            raise u.fail('cable', u.data['cable'], 'needs cable_model: elastic')
        return 0.0, 0.0
    keys = _rope_keys(u.section('cable', {}), base)
    if keys['stiffness'] is None and keys['axial_stiffness'] is None:
        raise ScenarioError(f'{u.where}: cable.stiffness: missing key (cable_model: elastic '
                            'needs stiffness [N/m] or axial_stiffness [N], in cable: or '
                            f'{u.key("cable")})')
    stiffness = keys['stiffness'] if keys['stiffness'] is not None else \
        keys['axial_stiffness'] / length
    return stiffness, keys['damping']


def _rope_keys(sec: Section, base: dict[str, Any] | None) -> dict[str, Any]:
    if sec.has('stiffness') and sec.has('axial_stiffness'):
        raise sec.fail('axial_stiffness', sec.data['axial_stiffness'],
                       'goes without stiffness: give one of them')
    keys = dict(base) if base else {'stiffness': None, 'axial_stiffness': None, 'damping': 0.0}
    if sec.has('stiffness'):
        keys.update(stiffness=sec.positive('stiffness'), axial_stiffness=None)
    if sec.has('axial_stiffness'):
        keys.update(axial_stiffness=sec.positive('axial_stiffness'), stiffness=None)
    keys['damping'] = sec.non_negative('damping', keys['damping'])
    sec.done()
    return keys


def rope_rate(stiffness, damping, masses, payload_mass: float) -> float:
    """A bound on the fastest |lambda| [1/s] of the ropes' mass-spring-damper system (n
    ropes of k_i [N/m], c_i [N s/m] between UAVs of m_i [kg] and the payload): by
    Gershgorin, omega^2 <= 2 max(k_i / m_i, sum_i k_i / m_p), and the damping adds at most
    2 max(c_i / m_i, sum_i c_i / m_p)."""
    omega_sq = 2.0 * max(max(k / m for k, m in zip(stiffness, masses)),
                         sum(stiffness) / payload_mass)
    decay = 2.0 * max(max(c / m for c, m in zip(damping, masses)), sum(damping) / payload_mass)
    return math.sqrt(omega_sq) + decay


def check_rope_stepping(where: str, stiffness, damping, masses, payload_mass: float,
                        physics_rate: float, substeps: int) -> None:
    """ScenarioError (one line: the sub-steps or rate needed) unless the ropes are stepped at
    omega h <= ELASTIC_OMEGA_H."""
    rate = rope_rate(stiffness, damping, masses, payload_mass)
    omega_h = rate / (physics_rate * substeps)
    if omega_h > ELASTIC_OMEGA_H:
        needed = math.ceil(rate / (physics_rate * ELASTIC_OMEGA_H))
        raise ScenarioError(
            f'{where}: simulation.substeps: {substeps} steps the elastic cables at omega h = '
            f'{omega_h:.2f} (their fastest mode is bounded by {rate:.0f} rad/s), beyond '
            f'{ELASTIC_OMEGA_H}: set simulation.substeps >= {needed} (or physics_rate >= '
            f'{rate / ELASTIC_OMEGA_H / substeps:.0f} Hz)')
