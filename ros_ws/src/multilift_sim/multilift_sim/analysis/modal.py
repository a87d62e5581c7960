"""The open-loop formation linearised about a static equilibrium and its eigen-decomposition
(seed Sec. 2.8, Eq. 2.71-2.72, Fig. 2.12): steps 2 and 3 of the package docstring
(multilift_sim/analysis/__init__.py), and a state displaced along a mode.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from multilift_sim.analysis.coordinates import (coordinate_accelerations, displaced_state,
                                                formation_jacobian, formation_residuals,
                                                mass_matrix)
from multilift_sim.analysis.equilibrium import Equilibrium, scenario_equilibrium
from multilift_sim.analysis.modes import MODE_KINDS, mode_kind, motion_shares, real_shapes
from multilift_sim.cables import CABLE_MODELS
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.physics.layout import POSITION, seed_payload_slot, seed_uav_slot
from multilift_sim.scenario import Scenario


def default_dependent_coordinates(jacobian: np.ndarray,
                                  held: tuple[int, ...] = ()) -> tuple[int, ...]:
    """n dependent coordinates where G restricted to them has full rank.

    The UAV altitudes z_i (the seed's choice for the twin-lift, Sec. 2.8.2), whose block of G
    is diag(-2 (z_p - z_i)): fine unless a cable is (nearly) horizontal; then, or when the
    coordinates `held` (clamped, not free) include them, the first n pivots of a
    column-pivoted QR of G over the free coordinates.
    """
    n = jacobian.shape[0]
    altitudes = tuple(seed_uav_slot(i) + POSITION + 2 for i in range(n))
    rows = np.linalg.norm(jacobian, axis=1)                     # 2 l_i on the manifold
    if not held and np.min(np.abs(jacobian[np.arange(n), altitudes]) / rows) > 1e-3:
        return altitudes
    free = [k for k in range(jacobian.shape[1]) if k not in held]
    _, _, pivots = scipy.linalg.qr(jacobian[:, free], pivoting=True)
    return tuple(sorted(free[int(k)] for k in pivots[:n]))


def elimination_basis(jacobian: np.ndarray, dependent: tuple[int, ...],
                      held: tuple[int, ...] = ()) -> tuple[np.ndarray, tuple[int, ...]]:
    """(T (size, size - n - len(held)), independent indices): ``dq = T dq_i`` solves
    ``G dq = 0`` to first order with ``dq_d = -G_d^-1 G_i dq_i``, the coordinates `held`
    clamped (their rows of T zero). Raises ValueError when G_d is singular."""
    n, size = jacobian.shape
    dependent = tuple(int(k) for k in dependent)
    if len(set(dependent)) != n or not all(0 <= k < size and k not in held for k in dependent):
        raise ValueError(f'need {n} distinct dependent coordinates in 0..{size - 1}, none held, '
                         f'got {dependent}')
    independent = tuple(k for k in range(size) if k not in dependent and k not in held)
    block = jacobian[:, dependent]
    if np.linalg.cond(block) > 1e10:
        raise ValueError(f'G restricted to the dependent coordinates {dependent} is singular')
    basis = np.zeros((size, len(independent)))
    basis[independent, np.arange(len(independent))] = 1.0
    basis[list(dependent)] = -np.linalg.solve(block, jacobian[:, independent])
    return basis, independent


@dataclass(frozen=True)
class ModalAnalysis:
    """Linearised open-loop formation about an equilibrium and its eigen-decomposition.

    Eigenvalues [1/s] are sorted: non-rigid modes by decreasing |Im| then |Re| (conjugates
    adjacent, positive imaginary part first), rigid-body (zero) modes last. ``shapes[k]`` is
    mode k's shape in all 6n + 3 coordinates q_f ([m] and [rad], complex; a rigid payload's
    rotation vector [rad], payload frame, after them: 6n + 6), scaled so that its largest
    component is 1.
    """

    params: FormationParams
    equilibrium: Equilibrium
    basis_kind: str                   # 'elimination' or 'nullspace'
    dependent: tuple[int, ...]        # indices into q_f ('elimination'); () for 'nullspace'
    basis: np.ndarray                 # T (or N_f), (6n+3, 5n+3); rigid (6n+6, 5n+6)
    mass: np.ndarray                  # M_r = T^T M T
    stiffness: np.ndarray             # K_r = T^T M J_q T: M_r dq_i_ddot = K_r dq_i + D_r dq_i_dot
    damping: np.ndarray               # D_r = T^T M J_v T (zero: nothing damps at rest)
    state_matrix: np.ndarray          # A, (2(5n+3), 2(5n+3))
    eigenvalues: np.ndarray           # (2(5n+3),) complex [1/s]
    shapes: np.ndarray                # (2(5n+3), 6n+3) complex
    kinds: tuple[str, ...]            # one of MODE_KINDS per eigenvalue
    zero_tolerance: float             # |lambda| below this is a rigid-body mode [1/s]
    inertia: np.ndarray               # M at the equilibrium (6n+3 or 6n+6 square) [kg, kg m^2]
    held_uavs: bool                   # the UAVs' coordinates clamped (modal_analysis hold_uavs)

    def indices(self, kind: str) -> np.ndarray:
        """Indices of the eigenvalues of one kind (MODE_KINDS)."""
        return np.array([k for k, c in enumerate(self.kinds) if c == kind], dtype=int)

    @property
    def pendulum_modes(self) -> np.ndarray:
        """Indices of the pendulum modes with positive imaginary part (one per pair)."""
        return np.array([k for k in self.indices('pendulum') if self.eigenvalues[k].imag > 0],
                        dtype=int)

    @property
    def pendulum_periods(self) -> np.ndarray:
        """Periods 2 pi / omega [s] of the pendulum pairs, fastest first (repeats kept)."""
        return 2.0 * np.pi / self.eigenvalues[self.pendulum_modes].imag

    @property
    def rigid_count(self) -> int:
        """Number of zero (rigid-body) eigenvalues."""
        return len(self.indices('rigid'))

    def motion(self, mode: int, least: float = 0.05, most: int = 3) -> str:
        """Mode `mode` named by where its kinetic energy sits (motion_shares): the `most`
        largest shares of at least `least`, e.g. 'yaw 0.99' or 'UAVs 0.57, swing y 0.30,
        roll 0.13'."""
        shares = sorted(motion_shares(self, mode).items(), key=lambda item: -item[1])
        kept = [item for item in shares[:most] if item[1] >= least] or shares[:1]
        return ', '.join(f'{name} {share:.2f}' for name, share in kept)


def modal_analysis(params: FormationParams, equilibrium: Equilibrium,
                   dependent: tuple[int, ...] | None = None, basis: str = 'elimination',
                   zero_tolerance: float = 1e-4, imaginary_tolerance: float = 1e-6,
                   position_step: float = 1e-5, rate_step: float = 1e-3,
                   hold_uavs: bool = False) -> ModalAnalysis:
    """Linearise the open-loop formation about `equilibrium` and find its modes.

    dependent: indices into q_f (a rigid payload: and its rotation vector) of the n eliminated
    coordinates (default: the UAV altitudes, see default_dependent_coordinates); basis:
    'elimination' (T of the package docstring) or 'nullspace' (orthonormal N_f, Eq. 2.71).
    hold_uavs: the UAVs' 6n coordinates clamped (the cables' upper ends held still; only the
    payload moves). zero_tolerance [1/s]: smaller |lambda| are rigid-body modes; a pair is
    purely imaginary when |Re| <= imaginary_tolerance |lambda|, and a pendulum mode when also
    0.1 sqrt(g / l_max) <= |omega| <= 10 sqrt(g / l_min) (pendulum size; 'oscillatory'
    otherwise). position_step [m or rad] and rate_step [m/s or rad/s]: central-difference steps
    (the accelerations are even in the rates at rest, so rate_step only meets rounding).
    """
    if basis not in ('elimination', 'nullspace'):
        raise ValueError(f"basis must be 'elimination' or 'nullspace', got {basis!r}")
    # still air, exact index-reduced DAE: drag (zero slope at rest) and gusts out, no Baumgarte
    still = dataclasses.replace(params, gusts=(), payload_drag_coefficient=0.0,
                                baumgarte_alpha=0.0, baumgarte_beta=0.0)
    model = FormationModel(still)
    layout = model.layout
    x_e = np.asarray(equilibrium.state, dtype=float)
    jacobian = formation_jacobian(still, x_e)
    size = jacobian.shape[1]                     # 6n + 3, a rigid payload's 6n + 6
    held = tuple(range(seed_payload_slot(params.n_uavs))) if hold_uavs else ()
    if basis == 'elimination':
        dependent = (default_dependent_coordinates(jacobian, held) if dependent is None
                     else tuple(dependent))
        transform, _ = elimination_basis(jacobian, dependent, held)
    else:
        dependent = ()
        free = [k for k in range(size) if k not in held]
        transform = np.zeros((size, len(free) - params.n_uavs))
        transform[free] = scipy.linalg.null_space(jacobian[:, free] if held else jacobian)
    n_free = transform.shape[1]

    def acceleration(dq: np.ndarray, dq_dot: np.ndarray) -> np.ndarray:
        """q_ddot (and a rigid payload's alpha_p [rad/s^2], = theta_ddot at rest) at x_e
        moved by (dq, dq_dot) (displaced_state)."""
        moved = displaced_state(layout, x_e, dq, dq_dot)
        return coordinate_accelerations(
            layout, moved, model.accelerations_from_wrenches(moved, equilibrium.wrenches)[0])

    still_rates = np.zeros(size)
    j_q = np.empty((size, n_free))
    j_v = np.empty((size, n_free))
    for k in range(n_free):
        direction = transform[:, k]
        h = position_step / max(1.0, float(np.linalg.norm(direction)))
        j_q[:, k] = (acceleration(h * direction, still_rates)
                     - acceleration(-(h * direction), still_rates)) / (2.0 * h)
        h = rate_step / max(1.0, float(np.linalg.norm(direction)))
        j_v[:, k] = (acceleration(still_rates, h * direction)
                     - acceleration(still_rates, -(h * direction))) / (2.0 * h)
    inertia = mass_matrix(still, layout.uav_euler(x_e))
    mass = transform.T @ inertia @ transform                         # Eq. 2.72, left side
    stiffness = transform.T @ inertia @ j_q
    damping = transform.T @ inertia @ j_v
    state_matrix = np.block([[np.zeros((n_free, n_free)), np.eye(n_free)],
                             [np.linalg.solve(mass, stiffness), np.linalg.solve(mass, damping)]])
    eigenvalues, vectors = np.linalg.eig(state_matrix)

    lengths = np.asarray(still.cable_lengths)
    band = (0.1 * math.sqrt(still.gravity / lengths.max()),
            10.0 * math.sqrt(still.gravity / lengths.min()))
    kinds = [mode_kind(value, zero_tolerance, imaginary_tolerance, band) for value in eigenvalues]
    rank = {kind: r for r, kind in enumerate(MODE_KINDS)}
    order = sorted(range(eigenvalues.size), key=lambda k: (
        kinds[k] == 'rigid', -round(abs(eigenvalues[k].imag), 9),
        -round(abs(eigenvalues[k].real), 9), rank[kinds[k]], -eigenvalues[k].imag))
    eigenvalues, kinds = eigenvalues[order], [kinds[k] for k in order]
    shapes = (transform @ vectors[:n_free, order]).T
    for shape in shapes:
        shape /= shape[np.argmax(np.abs(shape))]
    if np.abs(damping).max() <= 1e-9 * max(1.0, np.abs(stiffness).max()):
        real_shapes(eigenvalues, kinds, shapes, np.linalg.solve(mass, stiffness), transform)
    return ModalAnalysis(params=params, equilibrium=equilibrium, basis_kind=basis,
                         dependent=tuple(dependent), basis=transform, mass=mass,
                         stiffness=stiffness, damping=damping, state_matrix=state_matrix,
                         eigenvalues=eigenvalues, shapes=shapes, kinds=tuple(kinds),
                         zero_tolerance=zero_tolerance, inertia=inertia, held_uavs=hold_uavs)


def scenario_modal_analysis(scenario: Scenario, **options: Any) -> ModalAnalysis:
    """modal_analysis of a scenario's formation at its static equilibrium (Eq. 2.73).
    ValueError (one line) for cables that stretch (`cable_model: elastic`): the linearisation
    eliminates each cable's length (Eq. 2.71), so it has no rope's axial mode to give; and for
    heavy cables (`cable_model: chain`), whose inner nodes it does not linearise."""
    if scenario.cable_model == 'chain':
        raise ValueError('cable_model: chain: the modal analysis linearises massless cables '
                         '(each a constraint on its UAV and the payload, Eq. 2.71) and not a '
                         'chain\'s inner nodes; analyse the scenario with cable_model: rigid '
                         'for its pendulum modes (the chain\'s own swing: docs/cables.md)')
    if not CABLE_MODELS[scenario.cable_model].KEEPS_LENGTH:
        raise ValueError(f'cable_model: {scenario.cable_model}: the modal analysis linearises '
                         'cables of fixed length (their lengths are the constraints it '
                         'eliminates, Eq. 2.71) and has no rope stretch to give axial modes; '
                         'analyse the scenario with cable_model: rigid for its pendulum modes')
    return modal_analysis(scenario.formation_params(0.0, 0.0), scenario_equilibrium(scenario),
                          **options)


def mode_state(analysis: ModalAnalysis, mode: int, amplitude: float,
               iterations: int = 20) -> np.ndarray:
    """A state at rest displaced along mode `mode`'s (real) shape, back on the manifold.

    The coordinates move by ``amplitude * Re(shape)`` (largest component = amplitude [m or
    rad]; a rigid payload's rotation vector turns its attitude, displaced_state); then
    least-norm Newton steps ``dq = -G^+ g`` (over the free coordinates when the UAVs are held)
    put every cable at its length (a second-order correction). Velocities are zero. Returns
    the packed state.
    """
    params = analysis.params
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    x = np.array(analysis.equilibrium.state, dtype=float)
    size = analysis.shapes.shape[1]
    still = np.zeros(size)
    x = displaced_state(layout, x, amplitude * analysis.shapes[mode].real, still)
    lengths = np.asarray(params.cable_lengths)
    free = np.ones(size, dtype=bool)
    free[:seed_payload_slot(params.n_uavs)] = not analysis.held_uavs
    for _ in range(iterations):
        residual = formation_residuals(params, x)
        if np.max(np.abs(residual) / lengths ** 2) < 1e-15:
            break
        jacobian = formation_jacobian(params, x)
        step = np.zeros(size)
        step[free] = np.linalg.pinv(jacobian[:, free]) @ residual
        x = displaced_state(layout, x, -step, still)
    return x
