"""Cables that pull but never push: the hybrid taut/slack cable model (`cable_model: slack`).

Not in the seed, whose cables are two-way rods (`cable_model: rigid`, FormationModel). The
hybrid model of RotorTM (Li et al., 2023): a taut cable is the seed's constraint g_i = 0
(Eq. 2.42) with its Baumgarte-stabilised multiplier (Eq. 2.60); when that multiplier would push
(lambda_i < 0) the cable goes slack and the payload and UAV i move freely (no constraint, no
tension); when |r_p - r_i| reaches l_i again while they separate, the cable snaps taut with an
inelastic impulse: the velocities are projected, in the mass metric, onto those that keep every
taut cable's length (g_dot = 0), which conserves momentum and does not increase the kinetic
energy.

The snap is an event located within the RK4 step (`_step`): when a slack cable would pass its
length during a step, the time of the crossing is found on the RK4 sub-step itself (Illinois
regula falsi started from the cubic Hermite interpolant of g_i, to |g_i| <= 1e-12 l_i^2), the
step is cut there, the positions are projected onto |r_p - r_i| = l_i (what the root finding
leaves: under 5e-13 l_i), the impulse is applied and the rest of the step is integrated with
the new taut set. So a cable does not stretch past its length (1e-10 m at most in
tests/ros/test_slack.py, where the check at the steps' ends this replaces let it overshoot by
3.7 mm). Going slack (the multiplier would push) is decided at the start of each RK4 step and
held within it, as before. The control period and the physics step are unchanged.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim.dynamics import FormationModel, FormationParams, Integration

# The taut event is located to |g_i| <= EVENT_TOLERANCE l_i^2 (|r_p - r_i| within 5e-13 l_i of
# l_i), in at most EVENT_ITERATIONS RK4 sub-steps (one or two in practice).
EVENT_TOLERANCE = 1e-12
EVENT_ITERATIONS = 40


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

    def _snap(self, x: np.ndarray, snapping: np.ndarray) -> np.ndarray:
        """The `snapping` (slack) cables become taut at x: positions projected onto their
        length, then the inelastic, momentum-conserving velocity jump (class docstring)."""
        self.taut |= snapping
        return self.snap_velocities(self._project_lengths(x, snapping), self.taut)

    def _project_lengths(self, x: np.ndarray, snapping: np.ndarray) -> np.ndarray:
        """x with the positions moved, in the mass metric (so the centre of mass stays), until
        the `snapping` cables have g = 0 while the other taut ones keep their g: Newton steps
        dq = -M^-1 G^T (G M^-1 G^T)^-1 (g - g_target) over the taut set. At a located event
        the residual is ~1e-12 l^2, so the first step already leaves rounding."""
        n, taut = self._n, self.taut
        x = np.array(x, dtype=float)
        target = np.where(snapping, 0.0, self.constraint_residuals(x)[0])
        for _ in range(2):
            schur, offsets = self._schur(x)
            g, _ = self.constraint_residuals(x)
            shifts = np.zeros(n)
            shifts[taut] = np.linalg.solve(schur[np.ix_(taut, taut)], (g - target)[taut])
            pull = (2.0 * shifts)[:, None] * offsets
            x[:6 * n].reshape(n, 6)[:, :3] += pull * self._inv_masses[:, None]
            x[6 * n:6 * n + 3] -= pull.sum(axis=0) * self._inv_payload_mass
        return x

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
        g, g_dot = self.constraint_residuals(x)
        for k in range(steps):
            if k:
                self._update_taut_set(x, wrenches)
            x, g, g_dot = self._step(x, wrenches, dt, g, g_dot)
        return Integration(x, 2.0 * self.cable_lengths * multipliers, g, g_dot)

    # ------------------------------------------------------------------ the taut event
    # Event location for hybrid systems: integrate, test the guard (here g_i = |r_p - r_i|^2
    # - l_i^2 of each slack cable) at the step's ends, and when it changed sign find its
    # zero in the step on the integrator's own map, apply the jump there and restart (Shampine
    # & Thompson, "Event location for ordinary differential equations", Comput. Math. Appl. 39,
    # 2000). RotorTM, this model's reference, does the same with its ODE solver's event
    # function (|x_L - x_Q| - l, terminal, direction +1: slackToTaut / cooperativeGuard passed
    # as ode45's Events, arplaboratory/RotorTM), then applies its inelastic collision map.
    def _step(self, x: np.ndarray, wrenches: np.ndarray, dt: float, g: np.ndarray,
              g_dot: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One RK4 step of dt from x (whose residuals are g, g_dot), cut at each taut event:
        (the state at the end, its g, its g_dot)."""
        left, events = dt, 0
        while True:
            end = self._rk4_arrays(x, wrenches, left)
            g_end, g_dot_end = self.constraint_residuals(end)
            if self.taut.all():
                return end, g_end, g_dot_end
            # an event makes a cable taut: a few per step at most (a bound against cycling)
            event = self._taut_event(x, wrenches, left, (g, g_dot), (end, g_end, g_dot_end)) \
                if events <= 2 * self._n else None
            if event is None:
                break
            events += 1
            tau, x, snapping = event
            x = self._snap(x, snapping)
            self._update_taut_set(x, wrenches)  # a new taut cable may not hold (it would push)
            g, g_dot = self.constraint_residuals(x)
            left -= tau
            if left <= 0.0:
                return x, g, g_dot
        # no crossing located: a cable already at its length when it went slack (g_i >= 0 at
        # the step's start, so no sign change) that separates at the end snaps there
        snapping = ~self.taut & (g_end >= 0.0) & (g_dot_end > 0.0)
        if snapping.any():
            end = self._snap(end, snapping)
            g_end, g_dot_end = self.constraint_residuals(end)
        return end, g_end, g_dot_end

    def _taut_event(self, x: np.ndarray, wrenches: np.ndarray, h: float,
                    start: tuple[np.ndarray, np.ndarray],
                    end: tuple[np.ndarray, np.ndarray, np.ndarray]
                    ) -> tuple[float, np.ndarray, np.ndarray] | None:
        """The first time tau in (0, h] at which a slack cable, shorter than l_i at x, reaches
        l_i on the RK4 sub-step from x: (tau, the state there, which cables snap), or None.

        The guard is f(tau) = max_i g_i(RK4(x, tau)) / l_i^2 over those cables. A crossing is
        bracketed by the step's ends, or, for a cable that goes out and back within the step,
        by the peak of the cubic Hermite interpolant of g_i (from g_i, g_dot_i at both ends).
        The first iterate is the interpolant's root, then Illinois regula falsi (Dowell &
        Jarratt, BIT 11, 1971) on the RK4 map until |f| <= EVENT_TOLERANCE."""
        scale = self._lengths_sq
        g0, g_dot0 = start[0] / scale, start[1] / scale
        x_end, g1, g_dot1 = end[0], end[1] / scale, end[2] / scale
        watched = ~self.taut & (g0 < 0.0)
        if not watched.any():
            return None

        def guard(tau: float) -> tuple[float, np.ndarray, np.ndarray]:
            state = self._rk4_arrays(x, wrenches, tau)
            value = self.constraint_residuals(state)[0] / scale
            return float(value[watched].max()), state, value

        crossing = watched & (g1 >= 0.0)
        if crossing.any():
            hi, f_hi, x_hi, value_hi = h, float(g1[watched].max()), x_end, g1
        else:  # out and back within the step: the interpolant's peak
            crossing = watched & (g_dot0 > 0.0) & (g_dot1 < 0.0)
            peaks = [_hermite_peak(h, g0[i], g_dot0[i], g1[i], g_dot1[i])
                     for i in np.flatnonzero(crossing)]
            peaks = [t for t, value in peaks if value >= 0.0]
            if not peaks:
                return None
            hi = min(peaks)
            f_hi, x_hi, value_hi = guard(hi)
            if f_hi < 0.0:
                return None
        guess = min(_hermite_root(h, g0[i], g_dot0[i], g1[i], g_dot1[i])
                    for i in np.flatnonzero(crossing))
        lo, f_lo = 0.0, float(g0[watched].max())
        tau, f_tau, x_tau, value = hi, f_hi, x_hi, value_hi
        side = 0
        for k in range(EVENT_ITERATIONS):
            if abs(f_tau) <= EVENT_TOLERANCE or hi - lo <= 1e-15 * h:
                break
            tau = guess if k == 0 and lo < guess < hi else \
                (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
            f_tau, x_tau, value = guard(tau)
            if f_tau >= 0.0:  # the crossing is in [lo, tau]
                hi, f_hi, x_hi, value_hi = tau, f_tau, x_tau, value
                if side == 1:
                    f_lo *= 0.5
                side = 1
            else:
                lo, f_lo = tau, f_tau
                if side == -1:
                    f_hi *= 0.5
                side = -1
        if abs(f_tau) > EVENT_TOLERANCE:  # not converged (not seen): the bracket's far end
            tau, x_tau, value = hi, x_hi, value_hi
        return tau, x_tau, watched & (value >= -EVENT_TOLERANCE)

    def cable_tension(self, t: float, x: np.ndarray,
                      rotor_speeds: Sequence[ArrayLike]) -> np.ndarray:
        """T_i [N]: 0 for a slack cable, >= 0 for a taut one (at the current taut set)."""
        del t
        wrenches = self.wrenches(rotor_speeds)
        taut = self.taut.copy()
        _, multipliers = self._solve_taut(np.asarray(x, dtype=float), wrenches, taut)
        return 2.0 * self.cable_lengths * np.where(taut, np.maximum(multipliers, 0.0), 0.0)


def _hermite_coefficients(h: float, p0: float, m0: float, p1: float,
                          m1: float) -> np.ndarray:
    """The cubic Hermite interpolant of values p0, p1 and slopes m0, m1 at t = 0, h, as a
    polynomial in s = t / h (highest power first)."""
    return np.array((2.0 * (p0 - p1) + h * (m0 + m1), 3.0 * (p1 - p0) - h * (2.0 * m0 + m1),
                     h * m0, p0))


def _hermite_root(h: float, p0: float, m0: float, p1: float, m1: float) -> float:
    """The first t in (0, h] where the interpolant (p0 < 0) reaches 0 (h if none)."""
    roots = np.roots(_hermite_coefficients(h, p0, m0, p1, m1))
    real = [r.real for r in roots if abs(r.imag) <= 1e-12 and 0.0 < r.real <= 1.0]
    return h * min(real, default=1.0)


def _hermite_peak(h: float, p0: float, m0: float, p1: float,
                  m1: float) -> tuple[float, float]:
    """(t, value) of the interpolant's highest point in (0, h) (slope + at 0, - at h)."""
    c = _hermite_coefficients(h, p0, m0, p1, m1)
    stationary = [r.real for r in np.roots(np.polyder(c))
                  if abs(r.imag) <= 1e-12 and 0.0 < r.real < 1.0]
    if not stationary:
        return 0.5 * h, float(np.polyval(c, 0.5))
    s = max(stationary, key=lambda r: np.polyval(c, r))
    return h * s, float(np.polyval(c, s))
