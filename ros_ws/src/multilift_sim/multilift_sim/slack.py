"""Cables that pull but never push: the hybrid taut/slack cable model (`cable_model: slack`).

Not in the seed, whose cables are two-way rods (`cable_model: rigid`, FormationModel). The
hybrid model of RotorTM (Li et al., 2023): a taut cable is the seed's constraint g_i = 0
(Eq. 2.42) with its Baumgarte-stabilised multiplier (Eq. 2.60); when that multiplier would push
(lambda_i < 0) the cable goes slack and the payload and UAV i move freely (no constraint, no
tension); when |r_p - r_i| reaches l_i again while they separate, the cable snaps taut with an
inelastic impulse: the velocities are projected, in the mass metric, onto those that keep every
taut cable's length (g_dot = 0), which conserves momentum and does not increase the kinetic
energy. The same holds for a rigid-body payload and for cables held off the UAVs' centres
(issue 20): the metric is then G M^-1 G^T with the bodies' rotations, the matrix A of
docs/rigid_payload.md (which writes the snap out), and the impulse turns the bodies too; an
impulse that leaves another slack cable at its length and separating snaps it at once.

The snap is an event located within the RK4 step (`physics.slack_cables.slack_step`, compiled
with the rest of the physics): when a slack cable would pass its
length during a step, the time of the crossing is found on the RK4 sub-step itself (Illinois
regula falsi started from the cubic Hermite interpolant of g_i, to |g_i| <= 1e-12 l_i^2), the
step is cut there, the positions are projected onto |r_p - r_i| = l_i (what the root finding
leaves: under 5e-13 l_i), the impulse is applied and the rest of the step is integrated with
the new taut set. So a cable does not stretch past its length (1e-10 m at most in
tests/ros/test_slack.py, where the check at the steps' ends this replaces let it overshoot by
3.7 mm). Going slack (the multiplier would push) is decided at the start of each RK4 step and
held within it, as before. The control period and the physics step are unchanged.

The rigid model is this one with every cable taut: the one solve
(`physics.formation_dae.solve`) takes the taut set, a slack cable's multiplier is 0 and it is
left out of the Woodbury sum.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams
from multilift_sim.physics.layout import CABLE_COLUMNS


class SlackCableModel(FormationModel):
    """FormationModel whose cables can go slack; `taut` (n,) bool says which are taut (the
    model's own array: write it in place or assign it)."""

    slack_cables = True

    def __init__(self, params: FormationParams):
        super().__init__(params)

    @property
    def taut(self) -> np.ndarray:
        return self._taut

    @taut.setter
    def taut(self, value: ArrayLike) -> None:
        self._taut[:] = value

    def _physics_functions(self) -> dict[str, Callable]:
        from multilift_sim.physics.slack_cables import integrate_period, snap_velocities
        functions = super()._physics_functions()
        functions.update(integrate_period=integrate_period, snap_velocities=snap_velocities)
        return functions

    def snap_velocities(self, x: np.ndarray, taut: ArrayLike) -> np.ndarray:
        """x with the velocities projected so that every `taut` cable has g_dot = 0:
        u+ = u - M^-1 G^T (G M^-1 G^T)^-1 G u (an inelastic impulse along the cables; linear
        and angular momentum kept, kinetic energy not increased; a rigid payload's body rates
        and, with cables off the UAVs' centres, their Euler rates jump too). Returns a new
        array."""
        x = np.array(self._state_array(x))
        n = self._n
        self._physics()['snap_velocities'](
            x, self._uavs, self._formation, np.array(taut, dtype=bool), np.empty(n),
            np.empty(n), np.empty(n), np.empty((n, CABLE_COLUMNS)))
        return x

    def cable_tension(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """T_i [N]: 0 for a slack cable, >= 0 for a taut one (at the current taut set)."""
        _, multipliers = self.accelerations(t, x, rotor_speeds)
        return 2.0 * self.cable_lengths * np.where(self._taut, np.maximum(multipliers, 0.0), 0.0)
