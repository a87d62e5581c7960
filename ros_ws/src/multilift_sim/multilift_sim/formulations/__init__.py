"""The formulations of the formation DAE a scenario can name (`simulation.integrator`), as
registered parts (issue 31): `FORMULATIONS`, which the scenario's validation and every
simulation read.

Every formulation has the same interface (`Formulation`): the simulation loop calls
`integrate` once per control period, whatever the formulation and however it computes
(compiled physics functions, numpy), and reads the reporting queries. A formulation's module
declares `NAME` (the scenario's `simulation.integrator`), `SUPPORTS` (what it models beyond the
seed's formation: a subset of `FEATURES`; validation refuses a scenario that uses more, in one
line) and `make(params, cable_model) -> Formulation` (`cable_model` a part of
`cables.CABLE_MODELS`).
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.cables import CABLE_MODELS
from multilift_sim.dynamics import Integration
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.registry import Registry


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


# what a formulation may model beyond the seed's rigid cables on a point payload, each with
# what a scenario that uses it is told (validation: scenario.parse)
FEATURES = {
    'wind': 'wind and vehicle.drag_coefficient need',
    'events': 'events need',
    'lagging_rotors': 'vehicle.motor_time_constant / motor_rate_limit need',
    'rigid_body': 'payload.type: rigid_body needs',
    'attach_points': 'uavs[i].attach_point need',
    'slack': 'cable_model: slack needs',
    'elastic': 'cable_model: elastic needs',
    'chain': 'cable_model: chain needs',
    'prescribed': 'a prescribed motion needs',
    'winch': 'a winch (uavs[i].winch) needs',
}


def _check(part) -> None:
    unknown = set(part.SUPPORTS) - set(FEATURES)
    if unknown:
        raise ValueError(f'formulation {part.NAME!r}: unknown features {sorted(unknown)}')


def _shipped():
    from multilift_sim.formulations import baumgarte, nullspace
    return (baumgarte, nullspace)


FORMULATIONS = Registry('formulation', ('NAME', 'SUPPORTS', 'make'), _shipped(), check=_check)


def unsupported(name: str, used: dict[str, str]) -> str | None:
    """One line for the first feature of `used` (feature -> where the scenario uses it)
    formulation `name` does not model, naming the formulations that do; None if it models all."""
    for feature, where in used.items():
        if feature not in FORMULATIONS[name].SUPPORTS:
            able = [n for n, f in FORMULATIONS.items() if feature in f.SUPPORTS]
            verb = FEATURES[feature].rsplit(' ', 1)[1]
            return (f'{where} {verb} simulation.integrator: {" or ".join(able) or "(none)"}, '
                    f'got {name!r}')
    return None


def make_formulation(name: str, params: FormationParams,
                     cable_model: str = 'rigid') -> Formulation:
    """The formulation a scenario's `simulation.integrator` names for its `cable_model`
    (ValueError otherwise)."""
    if name not in FORMULATIONS:
        raise ValueError(f'unknown integrator {name!r}; valid integrators are '
                         f'{", ".join(FORMULATIONS)}')
    needs = CABLE_MODELS[cable_model].NEEDS - FORMULATIONS[name].SUPPORTS
    if needs:
        raise ValueError(f'integrator {name!r} does not model cable_model {cable_model!r}')
    return FORMULATIONS[name].make(params, CABLE_MODELS[cable_model])
