"""Cables that pull but never push: the hybrid taut/slack cable model (`cable_model: slack`).

Not in the seed, whose cables are two-way rods (`cable_model: rigid`, FormationModel). The
hybrid model of RotorTM (Li et al., 2023): a taut cable is the seed's constraint g_i = 0
(Eq. 2.42) with its Baumgarte-stabilised multiplier (Eq. 2.60); when that multiplier would push
(lambda_i < 0) the cable goes slack and the payload and UAV i move freely (no constraint, no
tension); when |r_p - r_i| reaches l_i again while they separate, the cable snaps taut with an
inelastic impulse: the velocities are projected, in the mass metric, onto those that keep every
taut cable's length (g_dot = 0), which conserves momentum and does not increase the kinetic
energy. The taut set is decided at the start of each RK4 step and held within it.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.dynamics import FormationModel, FormationParams, Integration


class SlackCableModel(FormationModel):
    """FormationModel whose cables can go slack; `taut` (n,) bool says which are taut."""

    def __init__(self, params: FormationParams):
        super().__init__(params, kernel='numpy')
        self.taut = np.ones(params.n_uavs, dtype=bool)

    # ------------------------------------------------------------------ pieces of Eq. 2.60
    def _schur(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(G M^-1 G^T (n, n), d_i = r_p - r_i (n, 3)) at state x."""
        n = self._n
        offsets = x[6 * n:6 * n + 3] - x[:6 * n].reshape(n, 6)[:, :3]
        schur = (4.0 * self._inv_payload_mass) * (offsets @ offsets.T)
        schur[np.diag_indices(n)] += 4.0 * np.einsum('ij,ij->i', offsets, offsets) \
            * self._inv_masses
        return schur, offsets

    def _solve_taut(self, x: np.ndarray, wrench: np.ndarray,
                    taut: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """q_ddot and Lambda with only the `taut` cables constrained (slack ones: 0)."""
        q_ddot, full = FormationModel._solve_arrays(self, x, wrench)
        if taut.all():
            return q_ddot, full
        n = self._n
        schur, offsets = self._schur(x)
        rhs = schur @ full  # the right side of Eq. 2.60 (full = schur^-1 rhs)
        multipliers = np.zeros(n)
        if taut.any():
            multipliers[taut] = np.linalg.solve(schur[np.ix_(taut, taut)], rhs[taut])
        change = (2.0 * (multipliers - full))[:, None] * offsets
        q_ddot = q_ddot.copy()
        uav_acc = q_ddot[:6 * n].reshape(n, 6)
        uav_acc[:, :3] += change * self._inv_masses[:, None]
        q_ddot[6 * n:] -= change.sum(axis=0) * self._inv_payload_mass
        return q_ddot, multipliers

    def _solve_arrays(self, x: np.ndarray, wrench: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self._solve_taut(x, wrench, self.taut)

    # ------------------------------------------------------------------------ the modes
    def _update_taut_set(self, x: np.ndarray, wrench: np.ndarray) -> np.ndarray:
        """Drop taut cables whose multiplier would push, most negative first; returns the
        multipliers of the remaining taut set."""
        while True:
            _, multipliers = self._solve_taut(x, wrench, self.taut)
            pushing = np.flatnonzero(self.taut & (multipliers < 0.0))
            if pushing.size == 0:
                return multipliers
            self.taut[pushing[np.argmin(multipliers[pushing])]] = False

    def _snap(self, x: np.ndarray) -> np.ndarray:
        """Slack cables stretched to l_i while separating become taut; then the inelastic,
        momentum-conserving velocity jump (class docstring)."""
        g, g_dot = self.constraint_residuals(x)
        snapping = ~self.taut & (g >= 0.0) & (g_dot > 0.0)
        if not snapping.any():
            return x
        self.taut |= snapping
        return self.snap_velocities(x, self.taut)

    def snap_velocities(self, x: np.ndarray, taut: np.ndarray) -> np.ndarray:
        """x with the translational velocities projected so that every `taut` cable has
        g_dot = 0: v+ = v - M^-1 G^T (G M^-1 G^T)^-1 G v (an inelastic impulse along the
        cables; total momentum kept, kinetic energy not increased)."""
        n, nq = self._n, self._nq
        x = np.array(x, dtype=float)
        schur, offsets = self._schur(x)
        _, g_dot = self.constraint_residuals(x)
        impulses = np.zeros(n)
        impulses[taut] = np.linalg.solve(schur[np.ix_(taut, taut)], g_dot[taut])
        pull = (2.0 * impulses)[:, None] * offsets  # G^T impulse per body
        uav_v = x[nq:nq + 6 * n].reshape(n, 6)
        uav_v[:, :3] += pull * self._inv_masses[:, None]
        x[nq + 6 * n:] -= pull.sum(axis=0) * self._inv_payload_mass
        return x

    def integrate(self, x: np.ndarray, rotor_speeds: Sequence[ArrayLike], dt: float,
                  steps: int) -> Integration:
        wrenches = self.wrenches(rotor_speeds)
        x = np.asarray(x, dtype=float)
        multipliers = self._update_taut_set(x, wrenches)
        for k in range(steps):
            if k:
                self._update_taut_set(x, wrenches)
            x = self._snap(self._rk4_arrays(x, wrenches, dt))
        g, g_dot = self.constraint_residuals(x)
        return Integration(x, 2.0 * self.cable_lengths * multipliers, g, g_dot)

    def cable_tension(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """T_i [N]: 0 for a slack cable, >= 0 for a taut one (at the current taut set)."""
        del t
        wrenches = self.wrenches(rotor_speeds)
        taut = self.taut.copy()
        _, multipliers = self._solve_taut(np.asarray(x, dtype=float), wrenches, taut)
        return 2.0 * self.cable_lengths * np.where(taut, np.maximum(multipliers, 0.0), 0.0)
