"""The seed's formulation (`simulation.integrator: baumgarte`, the default): the DAE with
Lagrange multipliers and Baumgarte stabilisation (Eq. 2.59-2.70), compiled (physics/): the one
that models every feature."""
from __future__ import annotations

from typing import Any

from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams
from multilift_sim.slack import SlackCableModel

NAME = 'baumgarte'
SUPPORTS = frozenset({'wind', 'events', 'lagging_rotors', 'rigid_body', 'attach_points',
                      'slack', 'elastic', 'chain', 'prescribed', 'winch'})


def make(params: FormationParams, cable_model: Any) -> FormationModel:
    """The formation's model: the taut/slack one where cables slacken (multilift_sim.slack)."""
    return SlackCableModel(params) if cable_model.SLACKENS else FormationModel(params)
