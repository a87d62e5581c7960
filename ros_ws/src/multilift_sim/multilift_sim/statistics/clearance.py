"""The clearance figures a run reports (issue 34 item 5): the least clearance of each kind, when
and between what, and the first contact, from the memory's `clearance` and `contact` rows
(physics.layout CLEARANCE_*; measured by physics.clearance in the one tick). Names: `uav1`,
`cable2`, `payload`, `obstacle 'pillar3'`, `ground`. No numba."""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.physics import layout
from multilift_sim.scenario.world import contact_names

# the kinds as the summary names them, in CLEARANCE_* order
KIND_NAMES = ('uav_world', 'cable_world', 'payload_world', 'uav_uav', 'uav_cable',
              'cable_cable')


def contact_message(scenario, contact: np.ndarray) -> str:
    """The one line of a contact (the memory's `contact` row): what touched what, when."""
    first, second = contact_names(scenario, contact)
    return (f'contact: {first} touched {second} at t = '
            f'{contact[layout.CLEARANCE_TIME]:.3f} s (clearance '
            f'{contact[layout.CLEARANCE_VALUE]:.3g} m; world.on_contact: record flies on)')


def clearance_figures(scenario, clearance: np.ndarray, contact: np.ndarray) -> dict:
    """{'clearance': {kind: {'value' [m], 'time' [s], 'between': [a, b]}, ... measured kinds
    only}, 'least_clearance' [m] (None: none measured), 'contact': {...} or None} of a run
    with a `world:` section; {} without one."""
    if scenario.world is None:
        return {}
    kinds = {}
    for kind, name in enumerate(KIND_NAMES):
        row = clearance[kind]
        if math.isfinite(row[layout.CLEARANCE_VALUE]):
            kinds[name] = {'value': float(row[layout.CLEARANCE_VALUE]),
                           'time': float(row[layout.CLEARANCE_TIME]),
                           'between': list(contact_names(scenario, row, kind))}
    touched = None
    if contact[layout.CLEARANCE_KIND] >= 0:
        touched = {'kind': KIND_NAMES[int(contact[layout.CLEARANCE_KIND])],
                   'value': float(contact[layout.CLEARANCE_VALUE]),
                   'time': float(contact[layout.CLEARANCE_TIME]),
                   'between': list(contact_names(scenario, contact))}
    least = min((k['value'] for k in kinds.values()), default=None)
    return {'clearance': kinds, 'least_clearance': least, 'contact': touched}
