"""Modal analysis of the formation about a static equilibrium (seed Sec. 2.8, Eq. 2.71-2.73).

World frame (z up), SI units, coordinates ``q_f`` of docs/conventions.md (6n + 3 of them).

1. Equilibrium (Eq. 2.73 with q_dot = 0): ``f_g + G^T Lambda = B_f u_f``, ``g = 0``. Written in
   the world frame the rows are

       payload:   m_p g e_z + sum_i 2 lambda_i d_i = 0              (d_i = r_p - r_i)
       UAV i:     m_i g e_z - 2 lambda_i d_i = u_T,i R(eta_i) e_z   (B_r of Eq. 2.20)
       attitude:  0 = W^T tau_i, so tau_i = 0

   The payload rows give the multipliers (least squares, exact when the payload can hang at
   rest there), the UAV rows each UAV's thrust and its roll and pitch at the scenario's yaw, the
   allocation the rotor speeds. The UAVs are level only where their cable hangs vertically
   (n = 1): a level UAV's thrust is vertical and cannot balance a slanted cable's horizontal
   pull, so for n >= 2 Eq. 2.73 has no level solution and each UAV tilts away from the payload
   (1.57 deg in the twin_lift scenario). For n >= 4 the payload rows do not fix Lambda
   (statically indeterminate); the least-norm split is taken.
2. Linearisation, open loop: rotor speeds held at the equilibrium values, the exact
   index-reduced DAE of Eq. 2.58 (FormationModel with alpha_f = beta_f = 0) differentiated by
   central differences. Its multipliers are eliminated, not linearised: with n dependent
   coordinates q_d (the UAV altitudes by default, as the seed does for the twin-lift; usable
   while no cable is horizontal) and the constraint Jacobian G = [G_i G_d] at equilibrium,

       dq = T dq_i,   T = [I; -G_d^-1 G_i]   (rows of q_i, then of q_d; G T = 0, Eq. 2.71)

   and projecting ``M dq_ddot = dF - G^T dLambda`` with T^T (Eq. 2.72, T plays N_f) gives

       T^T M T dq_i_ddot = T^T M J_q T dq_i + T^T M J_v T dq_i_dot,

   J_q, J_v the Jacobians of the DAE's accelerations (the G^T dLambda part drops out since
   T^T G^T = 0). ``basis='nullspace'`` uses an orthonormal null-space basis N_f of G instead of
   T; the eigenvalues are the same (test_modal.py).
3. Eigenvalues of the first-order system ``A = [[0, I], [M_r^-1 K_r, M_r^-1 D_r]]``. A free
   formation under held rotor speeds has rigid-body modes (translation of the whole formation,
   and each UAV's attitude, which nothing restores in open loop) at zero: they are reported
   apart. Purely imaginary pairs of pendulum size are the pendulum modes.

Payload drag and gusts do not enter: the quadratic drag has zero slope at zero air speed, and
the analysis is of the formation in still air.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from multilift_sim.constraints import cable_residuals, cable_tension, constraint_jacobian
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.multirotor import euler_mass_matrix
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import formation_start

MODE_KINDS = ('pendulum', 'oscillatory', 'unstable', 'damped', 'rigid')


@dataclass(frozen=True)
class Equilibrium:
    """A static equilibrium of the formation (seed Eq. 2.73), world frame, SI units."""

    state: np.ndarray                     # packed x_e (docs/conventions.md), rates zero
    rotor_speeds: tuple[np.ndarray, ...]  # per UAV [rad/s], rotor order of the conventions
    wrenches: np.ndarray                  # (n, 4): u_T [N], tau [N m] (FLU), from the speeds
    multipliers: np.ndarray               # Lambda_e (n,) [N/m]
    tensions: np.ndarray                  # T_i = 2 l_i lambda_i (n,) [N], positive = taut


def static_equilibrium(params: FormationParams, uav_positions: ArrayLike,
                       payload_position: ArrayLike, yaws: ArrayLike | None = None,
                       tolerance: float = 1e-9) -> Equilibrium:
    """Rotor speeds, attitudes and multipliers that hold the given configuration at rest.

    uav_positions (n, 3) and payload_position (3,) [m] in the world frame, on the constraint
    manifold (every cable at its length); yaws (n,) [rad], default 0. Solves Eq. 2.73 as the
    module docstring says. Raises ValueError naming the cable or UAV when the payload cannot
    hang at rest there, a cable would be slack, or a rotor would leave its speed limits.
    """
    n = params.n_uavs
    uavs = np.asarray(uav_positions, dtype=float).reshape(n, 3)
    payload = np.asarray(payload_position, dtype=float).reshape(3)
    yaws = np.zeros(n) if yaws is None else np.asarray(yaws, dtype=float).reshape(n)
    lengths = np.asarray(params.cable_lengths)
    residual = cable_residuals(uavs, payload, lengths) / lengths ** 2
    worst = int(np.argmax(np.abs(residual)))
    if abs(residual[worst]) > tolerance:
        raise ValueError(f'cable {worst + 1}: |r_p - r_i|^2 differs from l_i^2 by a fraction '
                         f'{residual[worst]:.3g}: not on the constraint manifold (Eq. 2.42)')
    offsets = payload - uavs                                       # d_i, (n, 3)
    weight = np.array([0.0, 0.0, params.payload_mass * params.gravity])
    # payload rows: (2 D^T) Lambda = -m_p g e_z, least-norm when indeterminate (n >= 4)
    multipliers, *_ = np.linalg.lstsq(2.0 * offsets.T, -weight, rcond=None)
    miss = float(np.linalg.norm(2.0 * offsets.T @ multipliers + weight))
    if miss > tolerance * weight[2]:
        raise ValueError(f'the payload cannot hang at rest at {payload.tolist()} m: its cables '
                         f'leave {miss:.3g} N of its weight unbalanced (Eq. 2.73)')
    for i, multiplier in enumerate(multipliers):
        if multiplier <= 0.0:
            raise ValueError(f'cable {i + 1}: the equilibrium multiplier is {multiplier:.3g} '
                             'N/m: the cable would be slack or in compression')
    euler = np.zeros((n, 3))
    rotor_speeds = []
    wrenches = np.zeros((n, 4))
    for i, uav in enumerate(params.uavs):
        # UAV rows: the rotors carry the UAV's weight and the cable's pull 2 lambda_i d_i
        force = uav.mass * params.gravity * np.array([0.0, 0.0, 1.0]) \
            - 2.0 * multipliers[i] * offsets[i]
        thrust = float(np.linalg.norm(force))
        # R e_z = force / thrust at yaw psi (seed Eq. 2.6, as cascade.attitude_from_force, which
        # multilift_sim must not import): rotate by -psi, then roll = asin(-b), pitch = atan2(a, c)
        s_psi, c_psi = math.sin(yaws[i]), math.cos(yaws[i])
        a = (c_psi * force[0] + s_psi * force[1]) / thrust
        b = (-s_psi * force[0] + c_psi * force[1]) / thrust
        euler[i] = math.asin(-b), math.atan2(a, force[2] / thrust), yaws[i]
        allocator = uav.allocator()
        speeds, saturated = allocator.rotor_speeds([thrust, 0.0, 0.0, 0.0],
                                                   uav.rotor_speed_min, uav.rotor_speed_max)
        if np.any(saturated):
            raise ValueError(f'uav{i + 1}: the equilibrium thrust {thrust:.2f} N needs rotor '
                             f'speeds outside [{uav.rotor_speed_min:g}, '
                             f'{uav.rotor_speed_max:g}] rad/s')
        rotor_speeds.append(speeds)
        wrenches[i] = allocator.wrench(speeds)
    state = StateLayout(n).pack(uavs, euler, payload)
    return Equilibrium(state=state, rotor_speeds=tuple(rotor_speeds), wrenches=wrenches,
                       multipliers=multipliers, tensions=cable_tension(multipliers, lengths))


def scenario_configuration(scenario: Scenario) -> tuple[np.ndarray, np.ndarray]:
    """(UAV positions (n, 3), payload position (3,)) [m] of the scenario's hanging rest.

    n = 1: the scenario's UAV position with the payload straight below (alpha = beta = 0; the
    release angles of payload.alpha_deg/beta_deg are an initial condition, not the
    equilibrium). n >= 2: simulation.formation_start (the payload under the UAVs' horizontal
    centroid, where equal multipliers balance it), without the payload.swing_deg release.
    """
    if scenario.n_uavs == 1:
        uav = np.array([scenario.uavs[0].position], dtype=float)
        return uav, uav[0] - np.array([0.0, 0.0, scenario.uavs[0].cable_length])
    return formation_start(scenario)


def scenario_equilibrium(scenario: Scenario) -> Equilibrium:
    """The static equilibrium (Eq. 2.73) of the scenario's formation at its hanging rest,
    UAVs at the scenario's yaw angles. ValueError for a rigid-body payload (its modes: not
    yet, docs/rigid_payload.md)."""
    if scenario.payload.type != 'point':
        raise ValueError(f'{scenario.name}: the modes of a {scenario.payload.type} payload are '
                         'not analysed yet (multilift modal: point payloads; '
                         'docs/rigid_payload.md)')
    uavs, payload = scenario_configuration(scenario)
    return static_equilibrium(scenario.formation_params(0.0, 0.0), uavs, payload,
                              [u.yaw for u in scenario.uavs])


def coordinate_names(n_uavs: int) -> tuple[str, ...]:
    """Names of the 6n + 3 coordinates q_f: x1 y1 z1 phi1 theta1 psi1 ... x_p y_p z_p."""
    names = [f'{c}{i + 1}' for i in range(n_uavs)
             for c in ('x', 'y', 'z', 'phi', 'theta', 'psi')]
    return tuple(names + ['x_p', 'y_p', 'z_p'])


def mass_matrix(params: FormationParams, uav_euler: ArrayLike) -> np.ndarray:
    """Formation inertia M_f (Eq. 2.47): blocks m_i I, M_eta,i = W^T J W (Eq. 2.24), m_p I."""
    n = params.n_uavs
    euler = np.asarray(uav_euler, dtype=float).reshape(n, 3)
    mass = np.zeros((6 * n + 3, 6 * n + 3))
    for i, uav in enumerate(params.uavs):
        mass[6 * i:6 * i + 3, 6 * i:6 * i + 3] = uav.mass * np.eye(3)
        mass[6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = euler_mass_matrix(uav.inertia, euler[i])
    mass[6 * n:, 6 * n:] = params.payload_mass * np.eye(3)
    return mass


def default_dependent_coordinates(jacobian: np.ndarray) -> tuple[int, ...]:
    """n dependent coordinates where G restricted to them has full rank.

    The UAV altitudes z_i (the seed's choice for the twin-lift, Sec. 2.8.2), whose block of G
    is diag(-2 (z_p - z_i)): fine unless a cable is (nearly) horizontal; then the first n
    pivots of a column-pivoted QR of G.
    """
    n = jacobian.shape[0]
    altitudes = tuple(6 * i + 2 for i in range(n))
    rows = np.linalg.norm(jacobian, axis=1)                     # 2 l_i on the manifold
    if np.min(np.abs(jacobian[np.arange(n), altitudes]) / rows) > 1e-3:
        return altitudes
    _, _, pivots = scipy.linalg.qr(jacobian, pivoting=True)
    return tuple(sorted(int(k) for k in pivots[:n]))


def elimination_basis(jacobian: np.ndarray,
                      dependent: tuple[int, ...]) -> tuple[np.ndarray, tuple[int, ...]]:
    """(T (6n+3, 5n+3), independent indices): ``dq = T dq_i`` solves ``G dq = 0`` to first
    order with ``dq_d = -G_d^-1 G_i dq_i``. Raises ValueError when G_d is singular."""
    n, size = jacobian.shape
    dependent = tuple(int(k) for k in dependent)
    if len(set(dependent)) != n or not all(0 <= k < size for k in dependent):
        raise ValueError(f'need {n} distinct dependent coordinates in 0..{size - 1}, got '
                         f'{dependent}')
    independent = tuple(k for k in range(size) if k not in dependent)
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
    mode k's shape in all 6n + 3 coordinates q_f ([m] and [rad], complex), scaled so that its
    largest component is 1.
    """

    params: FormationParams
    equilibrium: Equilibrium
    basis_kind: str                   # 'elimination' or 'nullspace'
    dependent: tuple[int, ...]        # indices into q_f ('elimination'); () for 'nullspace'
    basis: np.ndarray                 # T (or N_f), (6n+3, 5n+3)
    mass: np.ndarray                  # M_r = T^T M T
    stiffness: np.ndarray             # K_r = T^T M J_q T: M_r dq_i_ddot = K_r dq_i + D_r dq_i_dot
    damping: np.ndarray               # D_r = T^T M J_v T (zero: nothing damps at rest)
    state_matrix: np.ndarray          # A, (2(5n+3), 2(5n+3))
    eigenvalues: np.ndarray           # (2(5n+3),) complex [1/s]
    shapes: np.ndarray                # (2(5n+3), 6n+3) complex
    kinds: tuple[str, ...]            # one of MODE_KINDS per eigenvalue
    zero_tolerance: float             # |lambda| below this is a rigid-body mode [1/s]

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


def modal_analysis(params: FormationParams, equilibrium: Equilibrium,
                   dependent: tuple[int, ...] | None = None, basis: str = 'elimination',
                   zero_tolerance: float = 1e-4, imaginary_tolerance: float = 1e-6,
                   position_step: float = 1e-5, rate_step: float = 1e-3) -> ModalAnalysis:
    """Linearise the open-loop formation about `equilibrium` and find its modes.

    dependent: indices into q_f of the n eliminated coordinates (default: the UAV altitudes,
    see default_dependent_coordinates); basis: 'elimination' (T of the module docstring) or
    'nullspace' (orthonormal N_f, Eq. 2.71). zero_tolerance [1/s]: smaller |lambda| are
    rigid-body modes; a pair is purely imaginary when |Re| <= imaginary_tolerance |lambda|,
    and a pendulum mode when also 0.1 sqrt(g / l_max) <= |omega| <= 10 sqrt(g / l_min)
    (pendulum size; 'oscillatory' otherwise).
    position_step [m or rad] and rate_step [m/s or rad/s]: central-difference steps (the
    accelerations are even in the rates at rest, so rate_step only meets rounding).
    """
    if basis not in ('elimination', 'nullspace'):
        raise ValueError(f"basis must be 'elimination' or 'nullspace', got {basis!r}")
    # still air, exact index-reduced DAE: drag (zero slope at rest) and gusts out, no Baumgarte
    still = dataclasses.replace(params, gusts=(), payload_drag_coefficient=0.0,
                                baumgarte_alpha=0.0, baumgarte_beta=0.0)
    model = FormationModel(still)
    layout = model.layout
    x_e = np.asarray(equilibrium.state, dtype=float)
    size = layout.n_coordinates
    jacobian = constraint_jacobian(layout.uav_positions(x_e), layout.payload_position(x_e))
    if basis == 'elimination':
        dependent = (default_dependent_coordinates(jacobian) if dependent is None
                     else tuple(dependent))
        transform, _ = elimination_basis(jacobian, dependent)
    else:
        dependent = ()
        transform = scipy.linalg.null_space(jacobian)
    n_free = transform.shape[1]

    def acceleration(x: np.ndarray) -> np.ndarray:
        return model.accelerations_from_wrenches(x, equilibrium.wrenches)[0]

    j_q = np.empty((size, n_free))
    j_v = np.empty((size, n_free))
    for k in range(n_free):
        direction = transform[:, k]
        h = position_step / max(1.0, float(np.linalg.norm(direction)))
        step = np.zeros(2 * size)
        step[:size] = h * direction
        j_q[:, k] = (acceleration(x_e + step) - acceleration(x_e - step)) / (2.0 * h)
        h = rate_step / max(1.0, float(np.linalg.norm(direction)))
        step = np.zeros(2 * size)
        step[size:] = h * direction
        j_v[:, k] = (acceleration(x_e + step) - acceleration(x_e - step)) / (2.0 * h)
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
    kinds = [_kind(value, zero_tolerance, imaginary_tolerance, band) for value in eigenvalues]
    rank = {kind: r for r, kind in enumerate(MODE_KINDS)}
    order = sorted(range(eigenvalues.size), key=lambda k: (
        kinds[k] == 'rigid', -round(abs(eigenvalues[k].imag), 9),
        -round(abs(eigenvalues[k].real), 9), rank[kinds[k]], -eigenvalues[k].imag))
    eigenvalues, kinds = eigenvalues[order], [kinds[k] for k in order]
    shapes = (transform @ vectors[:n_free, order]).T
    for shape in shapes:
        shape /= shape[np.argmax(np.abs(shape))]
    if np.abs(damping).max() <= 1e-9 * max(1.0, np.abs(stiffness).max()):
        _real_shapes(eigenvalues, kinds, shapes, np.linalg.solve(mass, stiffness), transform)
    return ModalAnalysis(params=params, equilibrium=equilibrium, basis_kind=basis,
                         dependent=tuple(dependent), basis=transform, mass=mass,
                         stiffness=stiffness, damping=damping, state_matrix=state_matrix,
                         eigenvalues=eigenvalues, shapes=shapes, kinds=tuple(kinds),
                         zero_tolerance=zero_tolerance)


def _real_shapes(eigenvalues: np.ndarray, kinds: list[str], shapes: np.ndarray,
                 reduced_stiffness: np.ndarray, transform: np.ndarray) -> None:
    """Real mode shapes for the purely imaginary eigenvalues of an undamped system.

    Without damping a pair +/- j omega has the real shapes v of ``(M_r^-1 K_r + omega^2 I) v
    = 0``. eig returns an arbitrary complex basis when omega is repeated (the single-lift's x
    and y swings), so each group of equal omega gets its real null space, in the basis whose
    vectors are 1 at one coordinate of q_f and 0 at the others' (pivoted QR picks them).
    Overwrites `shapes` in place.
    """
    size = reduced_stiffness.shape[0]
    done: set[int] = set()
    for k, value in enumerate(eigenvalues):
        if k in done or kinds[k] not in ('pendulum', 'oscillatory') or value.imag <= 0:
            continue
        omega = value.imag
        group = [j for j, other in enumerate(eigenvalues)
                 if kinds[j] == kinds[k] and abs(abs(other.imag) - omega) <= 1e-6 * omega]
        upper = [j for j in group if eigenvalues[j].imag > 0]
        _, _, right = np.linalg.svd(reduced_stiffness + omega ** 2 * np.eye(size))
        basis = transform @ right[size - len(upper):].T                   # (6n+3, m), real
        _, _, pivots = scipy.linalg.qr(basis.T, pivoting=True)
        basis = basis @ np.linalg.inv(basis[pivots[:len(upper)]])
        basis /= basis[np.argmax(np.abs(basis), axis=0), np.arange(len(upper))]
        for column, j in enumerate(upper):
            conjugate = [c for c in group if c not in upper]
            shapes[j] = basis[:, column]
            if column < len(conjugate):
                shapes[conjugate[column]] = basis[:, column]
        done.update(group)


def _kind(value: complex, zero_tolerance: float, imaginary_tolerance: float,
          band: tuple[float, float]) -> str:
    if abs(value) < zero_tolerance:
        return 'rigid'
    if abs(value.real) <= imaginary_tolerance * abs(value):
        return 'pendulum' if band[0] <= abs(value.imag) <= band[1] else 'oscillatory'
    return 'unstable' if value.real > 0 else 'damped'


def scenario_modal_analysis(scenario: Scenario, **options: Any) -> ModalAnalysis:
    """modal_analysis of a scenario's formation at its static equilibrium (Eq. 2.73)."""
    return modal_analysis(scenario.formation_params(0.0, 0.0), scenario_equilibrium(scenario),
                          **options)


def mode_state(analysis: ModalAnalysis, mode: int, amplitude: float,
               iterations: int = 20) -> np.ndarray:
    """A state at rest displaced along mode `mode`'s (real) shape, back on the manifold.

    The coordinates move by ``amplitude * Re(shape)`` (largest component = amplitude [m or
    rad]); then least-norm Newton steps ``dq = -G^+ g`` put every cable at its length (a
    second-order correction). Velocities are zero. Returns the packed state.
    """
    layout = StateLayout(analysis.params.n_uavs)
    x = np.array(analysis.equilibrium.state, dtype=float)
    size = layout.n_coordinates
    x[:size] += amplitude * analysis.shapes[mode].real
    lengths = np.asarray(analysis.params.cable_lengths)
    for _ in range(iterations):
        residual = cable_residuals(layout.uav_positions(x), layout.payload_position(x), lengths)
        if np.max(np.abs(residual) / lengths ** 2) < 1e-15:
            break
        jacobian = constraint_jacobian(layout.uav_positions(x), layout.payload_position(x))
        x[:size] -= np.linalg.pinv(jacobian) @ residual
    return x
