"""Heavy cables (`cable_model: chain`, issue 32 item 2; physics.chain_cables): each cable N
rigid links with N - 1 point masses between its UAV and the payload, so it sags, folds when
slack and swings on its own. docs/cables.md, "Heavy cables".

Keys of the `cable:` section (SI; every cable alike, no `uavs[i].cable:`): `links` N (an
integer >= 2), `mass_per_length` mu [kg/m] (> 0: each inner node carries mu l_i / (N - 1)),
`drag_coefficient` C_d [-] and `diameter` d [m] (default 0: no drag; each node's quadratic
drag is 0.5 rho C_d d (l_i / N) |v_rel| v_rel, rho = AIR_DENSITY, the cable's length l_i / N
about the node seen by the air from any direction).
"""
from __future__ import annotations

import math
from typing import Any

from multilift_sim.cables.elastic import ELASTIC_OMEGA_H

NAME = 'chain'
NEEDS = frozenset({'chain'})
RELEASE_LIMIT_DEG = 90.0
KEEPS_LENGTH = True   # each link is the seed's constraint (per link); the start hangs at l_i
SLACKENS = False      # (a chain folds by itself: its links keep their lengths)
# a winch reels every link alike (l_i(t) / N), the nodes keep their masses and drag
# (physics.chain_cables; docs/cables.md)
REELS = True

CHAIN_KEYS = ('links', 'mass_per_length', 'drag_coefficient', 'diameter')
AIR_DENSITY = 1.225   # rho [kg/m^3], the ISA's at sea level


def parse_cable(top: Any) -> dict[str, Any]:
    """The `cable:` section's keys (`top` the scenario's reading.Section)."""
    sec = top.section('cable', {})
    links = sec.raw('links', None)
    if isinstance(links, bool) or not isinstance(links, int) or links < 2:
        raise sec.fail('links', links, 'must be an integer >= 2 (cable_model: chain)')
    keys = {'links': links, 'mass_per_length': sec.positive('mass_per_length'),
            'drag_coefficient': sec.non_negative('drag_coefficient', 0.0),
            'diameter': sec.non_negative('diameter', 0.0)}
    sec.done()
    return keys


def parse_uav_cable(u: Any, length: float, base: dict[str, Any]) -> tuple[float, float]:
    """(0, 0): no stiffness or damping; a UAV's own `cable:` is refused in one line."""
    if u.has('cable'):
        raise u.fail('cable', u.data['cable'], 'is not read with cable_model: chain (every '
                     'cable is the top-level cable: section\'s)')
    return 0.0, 0.0


def drag_per_length(keys: dict[str, Any]) -> float:
    """0.5 rho C_d d [kg/m^2]: a node's drag coefficient per metre of cable it stands for."""
    return 0.5 * AIR_DENSITY * keys['drag_coefficient'] * keys['diameter']


def check(scenario: Any) -> str | None:
    """A point or rigid payload (the UAVs' attach points too), no UAV prescribed, the chains'
    transverse waves stepped at omega h <= ELASTIC_OMEGA_H (`chain_stepping`) at their
    fastest: a winch's chain reeled in to its min_length."""
    if scenario.prescribed:
        return ('cable_model: chain is not for a formation with prescribed UAVs '
                '(uavs[i].trajectory)')
    keys, sim = scenario.cable, scenario.simulation
    lengths = [u.cable_length for u in scenario.uavs]
    shortest = [u.winch.min_length if u.winch else u.cable_length for u in scenario.uavs]
    return chain_stepping(lengths, keys['links'], keys['mass_per_length'],
                          scenario.payload.mass, sim.gravity, sim.physics_rate, sim.substeps,
                          shortest)


def chain_rate(lengths, links: int, mass_per_length: float, payload_mass: float,
               gravity: float, shortest=None) -> float:
    """A bound on the chains' fastest transverse mode [rad/s]: a string of N masses under
    tension T has its highest mode at 2 sqrt(T / mu) / s (s = l / N its link), T bounded by
    the whole weight (payload and cables) on one cable. A chain reeled in from l to l_s
    (`shortest` [m], each cable's; default `lengths`) keeps its nodes' masses on links l_s / N:
    mu l / l_s per metre, so 2 sqrt(T / mu) N / sqrt(l l_s)."""
    tension = (payload_mass + mass_per_length * sum(lengths)) * gravity
    shortest = lengths if shortest is None else shortest
    span = min(math.sqrt(length * short) for length, short in zip(lengths, shortest))
    return 2.0 * math.sqrt(tension / mass_per_length) / (span / links)


def chain_stepping(lengths, links: int, mass_per_length: float, payload_mass: float,
                   gravity: float, physics_rate: float, substeps: int,
                   shortest=None) -> str | None:
    """One line naming the sub-steps or rate needed unless the chains' transverse waves are
    stepped at omega h <= ELASTIC_OMEGA_H (None then; `shortest` as `chain_rate`'s)."""
    rate = chain_rate(lengths, links, mass_per_length, payload_mass, gravity, shortest)
    omega_h = rate / (physics_rate * substeps)
    if omega_h <= ELASTIC_OMEGA_H:
        return None
    needed = math.ceil(rate / (physics_rate * ELASTIC_OMEGA_H))
    return (f'simulation.substeps: {substeps} steps the chain cables at omega h = '
            f'{omega_h:.2f} (their fastest transverse mode is bounded by {rate:.0f} rad/s), '
            f'beyond {ELASTIC_OMEGA_H}: set simulation.substeps >= {needed} (or physics_rate '
            f'>= {rate / ELASTIC_OMEGA_H / substeps:.0f} Hz)')
