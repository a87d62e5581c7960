"""The formulations of the formation DAE a scenario can name (`simulation.integrator`).

Every formulation has the same interface (`Formulation`): the simulation loop calls
`integrate` once per control period, whatever the formulation and however it computes
(compiled physics functions, numpy), and reads the reporting queries. A new formulation is
a class with these methods, added to `FORMULATIONS` under its scenario name.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.dynamics import FormationModel, Integration
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.nullspace import NullSpaceModel
from multilift_sim.slack import SlackCableModel


class Formulation(Protocol):
    """What the simulation loop needs of a formulation of the formation DAE."""
    layout: StateLayout

    def integrate(self, x: np.ndarray, rotor_speeds: Sequence[ArrayLike], dt: float,
                  steps: int) -> Integration:
        """Hold the rotor speeds [rad/s] over `steps` steps of dt [s] from state x."""

    def cable_tension(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """T_i [N] at state x under the rotor speeds, shape (n,)."""

    def constraint_residuals(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(g [m^2], g_dot [m^2/s]) of every cable, shapes (n,)."""

    def gust_velocity_at_payload(self, t: float, x: np.ndarray) -> np.ndarray:
        """Gust (air) velocity at the payload [m/s], world, shape (3,)."""

    def mechanical_energy(self, x: np.ndarray) -> float:
        """Kinetic plus gravitational potential energy [J]."""


# scenario name -> formulation: 'baumgarte' is the seed's DAE with Lagrange multipliers and
# Baumgarte stabilisation (Eq. 2.59-2.70); 'nullspace' its null-space form with projection
# (Eq. 2.71-2.72).
FORMULATIONS: dict[str, Callable[[FormationParams], Formulation]] = {
    'baumgarte': FormationModel,
    'nullspace': NullSpaceModel,
}


# the formulations for cables that can go slack (`cable_model: slack`), by integrator name
SLACK_FORMULATIONS: dict[str, Callable[[FormationParams], Formulation]] = {
    'baumgarte': SlackCableModel,
}


def make_formulation(name: str, params: FormationParams,
                     cable_model: str = 'rigid') -> Formulation:
    """The formulation a scenario's `simulation.integrator` names for its `cable_model`
    (ValueError otherwise)."""
    registry = SLACK_FORMULATIONS if cable_model == 'slack' else FORMULATIONS
    try:
        return registry[name](params)
    except KeyError:
        raise ValueError(f'unknown integrator {name!r} for cable_model {cable_model!r}; valid '
                         f'integrators are {", ".join(registry)}') from None
