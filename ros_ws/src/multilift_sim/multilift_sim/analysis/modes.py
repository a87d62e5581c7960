"""The modes of a modal analysis named (seed Sec. 2.8): each eigenvalue's kind (rigid-body,
pendulum, oscillatory, unstable, damped), real shapes for an undamped system's repeated
frequencies, and where a mode's kinetic energy sits (the payload's swing, heave, roll / pitch /
yaw; the UAVs). Step 3 of the package docstring (multilift_sim/analysis/__init__.py).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg

from multilift_sim.physics.layout import POSITION, SEED_EULER, seed_payload_slot, seed_uav_slot

if TYPE_CHECKING:
    from multilift_sim.analysis.modal import ModalAnalysis

MODE_KINDS = ('pendulum', 'oscillatory', 'unstable', 'damped', 'rigid')


def motion_groups(n_uavs: int, rigid_payload: bool) -> dict[str, list[int]]:
    """The coordinates (indices into q_f, a rigid payload's rotation after it) of each motion
    a mode is named by: the payload's swing x, swing y (world), heave (z); a rigid payload's
    roll, pitch, yaw (its rotation about its own x, y, z axes); the UAVs' translation and
    attitude (all UAVs together)."""
    p = seed_payload_slot(n_uavs)
    groups = {'swing x': [p], 'swing y': [p + 1], 'heave': [p + 2]}
    if rigid_payload:
        groups.update({'roll': [p + 3], 'pitch': [p + 4], 'yaw': [p + 5]})
    groups['UAVs'] = [seed_uav_slot(i) + POSITION + k for i in range(n_uavs) for k in range(3)]
    groups['UAV attitudes'] = [seed_uav_slot(i) + SEED_EULER + k for i in range(n_uavs)
                               for k in range(3)]
    return groups


def motion_shares(analysis: ModalAnalysis, mode: int) -> dict[str, float]:
    """Each motion's share (motion_groups) of mode `mode`'s kinetic energy, sum 1:
    Re(v_g^H M_gg v_g) / Re(v^H M v) with v the shape and M the formation's inertia at the
    equilibrium (block-diagonal over the groups, so the shares add up; unit-free, unlike the
    shape's components in m and rad)."""
    shape = analysis.shapes[mode]
    inertia = analysis.inertia
    groups = motion_groups(analysis.params.n_uavs, analysis.params.rigid_payload)
    energy = {name: float(np.real(np.conj(shape[k]) @ inertia[np.ix_(k, k)] @ shape[k]))
              for name, k in groups.items()}
    total = sum(energy.values())
    return {name: value / total for name, value in energy.items()}


def real_shapes(eigenvalues: np.ndarray, kinds: list[str], shapes: np.ndarray,
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


def mode_kind(value: complex, zero_tolerance: float, imaginary_tolerance: float,
              band: tuple[float, float]) -> str:
    """One of MODE_KINDS for eigenvalue `value` [1/s] (modal_analysis's tolerances; `band` the
    pendulum frequencies [rad/s])."""
    if abs(value) < zero_tolerance:
        return 'rigid'
    if abs(value.real) <= imaginary_tolerance * abs(value):
        return 'pendulum' if band[0] <= abs(value.imag) <= band[1] else 'oscillatory'
    return 'unstable' if value.real > 0 else 'damped'
