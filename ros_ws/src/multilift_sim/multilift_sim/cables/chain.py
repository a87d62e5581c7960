"""Heavy cables (`cable_model: chain`, issue 32 item 2; physics.chain_cables): each cable N
rigid links with N - 1 point masses between its UAV and the payload, so it sags, folds when
slack and swings on its own. docs/cables.md, "Heavy cables".

Keys of the `cable:` section (SI; every cable alike): `links` N (an integer >= 2),
`mass_per_length` mu [kg/m] (> 0: each inner node carries mu l_i / (N - 1)),
`drag_coefficient` C_d [-] and `diameter` d [m] (default 0: no drag; each node's quadratic
drag is 0.5 rho C_d d (l_i / N) |v_rel| v_rel, rho = AIR_DENSITY, the cable's length l_i / N
about the node seen by the air from any direction). Elastic links: the rope's keys of
`cable_model: elastic` (`stiffness` k [N/m] or `axial_stiffness` EA [N], `damping` c
[N s/m], the whole cable's; then a `uavs[i].cable:` may override them as for ropes): each link
is N k stiff and N c damped (N springs in series make the whole rope's k and c).
Without them the links are rigid (no `uavs[i].cable:`).
"""
from __future__ import annotations

import math
from typing import Any

from multilift_sim.cables import elastic
from multilift_sim.cables.elastic import ROPE_KEYS

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
            'diameter': sec.non_negative('diameter', 0.0), 'elastic_links': False}
    if any(sec.has(key) for key in ROPE_KEYS):  # elastic links: the rope's keys
        keys.update(elastic.rope_keys(sec, None), elastic_links=True)
        if keys['stiffness'] is None and keys['axial_stiffness'] is None:
            raise sec.fail('damping', keys['damping'], 'needs stiffness [N/m] or '
                           'axial_stiffness [N] (elastic links)')
    sec.done()
    return keys


def parse_uav_cable(u: Any, length: float, base: dict[str, Any]) -> tuple[float, float]:
    """Rigid links: (0, 0), a UAV's own `cable:` refused in one line; elastic links: the whole
    cable's (k [N/m], c [N s/m]) as an elastic rope's (`elastic.parse_uav_cable`)."""
    if base['elastic_links']:
        return elastic.parse_uav_cable(u, length, base)
    if u.has('cable'):
        raise u.fail('cable', u.data['cable'], 'is not read with rigid links (every cable is '
                     'the top-level cable: section\'s; stiffness makes them elastic)')
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
    axial = 0.0
    if keys['elastic_links']:
        axial = max(link_rate(u.cable_stiffness, u.cable_damping, keys['links'],
                              keys['mass_per_length'], u.cable_length, short)
                    for u, short in zip(scenario.uavs, shortest))
    return chain_stepping(lengths, keys['links'], keys['mass_per_length'],
                          scenario.payload.mass, sim.gravity, sim.physics_rate, sim.substeps,
                          shortest, axial)


def link_rate(stiffness: float, damping: float, links: int, mass_per_length: float,
              length: float, shortest: float) -> float:
    """A bound on an elastic chain's fastest axial mode [rad/s]: each link N k l / l_s stiff
    and N c l / l_s damped (reeled in to l_s; k, c the whole cable's at its length l) between
    nodes of mu l / (N - 1); by Gershgorin omega^2 <= 4 k_link / m_node, the damping adding at
    most 4 c_link / m_node."""
    node = mass_per_length * length / (links - 1)
    scale = links * length / shortest
    return 2.0 * math.sqrt(stiffness * scale / node) + 4.0 * damping * scale / node


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
                   shortest=None, axial: float = 0.0) -> str | None:
    """One line naming the sub-steps or rate needed unless the chains' transverse waves (and
    elastic links' axial ones, `axial` [rad/s] from `link_rate`) are stepped at omega h <=
    ELASTIC_OMEGA_H (None then; `shortest` as `chain_rate`'s)."""
    rate = max(chain_rate(lengths, links, mass_per_length, payload_mass, gravity, shortest),
               axial)
    return elastic.stepping('chain', rate, physics_rate, substeps)
