"""Cable-force allocation (`formation.reorganize: cable_forces`, issue 35 item 3, two UAVs or
more): for a point payload each tick the share of the payload's apparent weight each cable
should carry so that the UAVs' largest thrust utilisation is least (the least effort under the
thrust limits; `laws.cable_forces.load_shares`, closed form), and the places where the cables
pull those forces (`allocated_places`: for three, the triangle of forces); for a rigid body the
places whose rigid statics make that utilisation least (`laws.rigid_allocation`, searched); the
followers' offsets move there at `formation.max_offset_rate` within the spacing and spread
limits (`laws.cable_forces.allocate`) and the followers fly the seed's virtual-constraint law
to them.
Its arrays are `thrust_margin`'s in REORGANIZE_ALLOCATE mode, its answer that part's."""
from __future__ import annotations

import numpy as np

from multilift_control.controllers.followers import thrust_margin
from multilift_control.laws.layout import REORGANIZE_ALLOCATE
from multilift_sim.scenario import Scenario

NAME = 'cable_forces'
KEYS = ()  # its keys are the formation section's
shared = thrust_margin.shared
answer = thrust_margin.answer


def arrays(scenario: Scenario, index: int
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(constants, memory at t = 0, P, Q) of follower `index` (from 1): the allocation's."""
    return thrust_margin.mode_arrays(scenario, index, REORGANIZE_ALLOCATE)
