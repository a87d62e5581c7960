"""The seed's null-space form (`simulation.integrator: nullspace`, Eq. 2.71-2.72): RK4 then
Newton steps back onto g = 0, g_dot = 0 (multilift_sim.nullspace); rigid cables on a point
payload from the UAVs' centres, no wind, events or rotor lag."""
from __future__ import annotations

from typing import Any

from multilift_sim.formation_params import FormationParams
from multilift_sim.nullspace import NullSpaceModel

NAME = 'nullspace'
SUPPORTS: frozenset[str] = frozenset()


def make(params: FormationParams, cable_model: Any) -> NullSpaceModel:
    """The formation's model in the null-space form."""
    return NullSpaceModel(params)
