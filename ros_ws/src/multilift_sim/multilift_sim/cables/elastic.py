"""Elastic ropes (`cable_model: elastic`, issue 32; physics.elastic_cables): the `cable:`
section and each `uavs[i].cable:` override read into each cable's axial stiffness k [N/m] and
damping c [N s/m], and the rate their stepping needs.

Keys (SI): `stiffness` k [N/m], or `axial_stiffness` EA [N] (k = EA / l_i, each cable's own
rest length), and `damping` c [N s/m] (default 0). A UAV's `cable:` overrides what it gives.
"""
from __future__ import annotations

import math
from typing import Any

NAME = 'elastic'
NEEDS = frozenset({'elastic'})
RELEASE_LIMIT_DEG = 90.0
KEEPS_LENGTH = False  # a rope stretches: no constraint g_i = 0, no check of it
SLACKENS = False      # (a rope shorter than its rest length pulls nothing: its tension law)
REELS = True         # its rest length (physics.winch)

ROPE_KEYS = ('stiffness', 'axial_stiffness', 'damping')
# the largest omega h [-] an elastic formation is stepped at (omega its fastest mode's bound,
# h the RK4 step): RK4 then loses about (omega h)^6 / 72 = 2.2e-4 of an oscillation's energy
# per step, 0.3 % per period (stable up to 2.8)
ELASTIC_OMEGA_H = 0.5


def parse_cable(top: Any) -> dict[str, Any]:
    """The `cable:` section's keys (`top` the scenario's reading.Section)."""
    return rope_keys(top.section('cable', {}), None)


def parse_uav_cable(u: Any, length: float, base: dict[str, Any]) -> tuple[float, float]:
    """UAV i's cable's (k [N/m], c [N s/m]) from its `cable:` over `base`."""
    keys = rope_keys(u.section('cable', {}), base)
    if keys['stiffness'] is None and keys['axial_stiffness'] is None:
        raise u.fail('cable', u.data.get('cable', {}), 'needs stiffness [N/m] or '
                     'axial_stiffness [N] (cable_model: elastic), here or in cable:')
    stiffness = keys['stiffness'] if keys['stiffness'] is not None else \
        keys['axial_stiffness'] / length
    return stiffness, keys['damping']


def check(scenario: Any) -> str | None:
    """A point payload on cables from the UAVs' centres, the ropes stepped at omega h <=
    ELASTIC_OMEGA_H (`rope_stepping`) at their stiffest: a winch's rope reeled in to its
    min_length is EA / min_length stiff (its damping scaled alike, physics.winch)."""
    if scenario.payload.type != 'point' or any(any(u.attach_point) for u in scenario.uavs):
        return ('cable_model: elastic is for a point payload on cables from the UAVs\' '
                'centres')
    uavs, sim = scenario.uavs, scenario.simulation
    shortest = [u.cable_length / u.winch.min_length if u.winch else 1.0 for u in uavs]
    return rope_stepping([u.cable_stiffness * k for u, k in zip(uavs, shortest)],
                         [u.cable_damping * k for u, k in zip(uavs, shortest)],
                         [u.vehicle.mass for u in uavs], scenario.payload.mass,
                         sim.physics_rate, sim.substeps)


def rope_keys(sec: Any, base: dict[str, Any] | None) -> dict[str, Any]:
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


def rope_stepping(stiffness, damping, masses, payload_mass: float, physics_rate: float,
                  substeps: int) -> str | None:
    """One line naming the sub-steps or rate needed unless the ropes are stepped at
    omega h <= ELASTIC_OMEGA_H (None then)."""
    return stepping('elastic', rope_rate(stiffness, damping, masses, payload_mass),
                    physics_rate, substeps)


def stepping(cables: str, rate: float, physics_rate: float, substeps: int) -> str | None:
    """One line naming the sub-steps or rate needed unless the `cables` (the model's word)
    whose fastest mode is bounded by `rate` [rad/s] are stepped at omega h <= ELASTIC_OMEGA_H
    (None then), h = 1 / (physics_rate [Hz] substeps)."""
    omega_h = rate / (physics_rate * substeps)
    if omega_h <= ELASTIC_OMEGA_H:
        return None
    needed = math.ceil(rate / (physics_rate * ELASTIC_OMEGA_H))
    return (f'simulation.substeps: {substeps} steps the {cables} cables at omega h = '
            f'{omega_h:.2f} (their fastest mode is bounded by {rate:.0f} rad/s), beyond '
            f'{ELASTIC_OMEGA_H}: set simulation.substeps >= {needed} (or physics_rate >= '
            f'{rate / ELASTIC_OMEGA_H / substeps:.0f} Hz)')
