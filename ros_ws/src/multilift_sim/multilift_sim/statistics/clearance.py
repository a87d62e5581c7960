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


def clearance_series(scenario, uavs: np.ndarray, uav_quaternions: np.ndarray,
                     payload: np.ndarray, payload_quaternions: np.ndarray | None = None
                     ) -> np.ndarray:
    """The clearance of each kind (T, CLEARANCE_KINDS) [m] (+inf: none measured) of T states
    given by their parts: UAV positions (n, T, 3) [m] and attitudes (n, T, 4) (w, x, y, z),
    world, the payload's positions (T, 3) [m] and a rigid payload's attitudes (T, 4); each
    measured by the tick's own function (physics.clearance.measure): a recorded run's
    clearance over time (`multilift plot`'s clearance figure)."""
    from multilift_sim.formulations import make_formulation
    from multilift_sim.physics.clearance import measure
    from multilift_sim.scenario.world import world_arrays
    n, samples = scenario.n_uavs, len(payload)
    rigid = payload_quaternions is not None
    state = np.zeros(layout.attitude_slot(n) + (layout.PAYLOAD_ATTITUDE if rigid else 0))
    constants = make_formulation(scenario.simulation.integrator, scenario.formation_params(),
                                 scenario.cable_model).physics_constants()[0]
    world, obstacles, radii = world_arrays(scenario)
    least = np.zeros((layout.CLEARANCE_KINDS, layout.CLEARANCE_COLUMNS))
    contact = np.zeros(layout.CLEARANCE_COLUMNS)
    out = np.empty((samples, layout.CLEARANCE_KINDS))
    for k in range(samples):
        for i in range(n):
            state[layout.uav_slot(i) + layout.POSITION:layout.uav_slot(i) + 3] = uavs[i, k]
        state[layout.payload_slot(n):layout.payload_slot(n) + 3] = payload[k]
        for i in range(n):
            base = layout.uav_attitude_slot(n, i) + layout.BODY_QUATERNION
            state[base:base + 4] = uav_quaternions[i, k]
        if rigid:
            base = layout.attitude_slot(n) + layout.PAYLOAD_QUATERNION
            state[base:base + 4] = payload_quaternions[k]
        least[:, layout.CLEARANCE_VALUE] = math.inf
        contact[:] = -1.0
        measure(world, obstacles, radii, constants, state, 0.0, least, contact)
        out[k] = least[:, layout.CLEARANCE_VALUE]
    return out
