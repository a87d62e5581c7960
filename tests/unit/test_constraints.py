"""constraints.py against finite differences of g (seed Eq. 2.42, 2.56-2.57, 2.66-2.67)."""
import numpy as np

from multilift_sim.constraints import (cable_residual_rates, cable_residuals, cable_tension,
                                       constraint_jacobian, constraint_jacobian_rate_term)

RNG = np.random.default_rng(5)
N = 3
LENGTHS = np.array([2.0, 2.5, 3.0])


def split(q):
    """(UAV positions (n, 3), payload position) of a coordinate vector q_f (6n + 3)."""
    return q[:6 * N].reshape(N, 6)[:, :3], q[6 * N:]


def residuals(q):
    positions, payload = split(q)
    return cable_residuals(positions, payload, LENGTHS)


def test_residuals_of_a_known_geometry():
    positions = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 2.0], [0.0, 3.0, 0.0]])
    payload = np.array([0.0, 0.0, -2.0])
    assert np.allclose(cable_residuals(positions, payload, LENGTHS), [0.0, 17.0 - 6.25, 4.0])


def test_jacobian_rates_and_their_derivative_match_finite_differences():
    q = RNG.normal(size=6 * N + 3)
    q_dot = RNG.normal(size=6 * N + 3)
    h = 1e-6
    numeric = np.stack([(residuals(q + h * e) - residuals(q - h * e)) / (2 * h)
                        for e in np.eye(q.size)], axis=1)
    jacobian = constraint_jacobian(*split(q))
    assert np.allclose(jacobian, numeric, atol=1e-7)
    assert np.all(jacobian[:, [3, 4, 5, 9, 10, 11, 15, 16, 17]] == 0.0)   # attitude columns
    positions, payload = split(q)
    velocities, payload_velocity = split(q_dot)
    rates = cable_residual_rates(positions, velocities, payload, payload_velocity)
    assert np.allclose(rates, jacobian @ q_dot, atol=1e-12)
    # G_dot q_dot = d^2/dt^2 g(q + t q_dot) at t = 0
    second = (residuals(q + 1e-4 * q_dot) - 2 * residuals(q) + residuals(q - 1e-4 * q_dot)) / 1e-8
    assert np.allclose(constraint_jacobian_rate_term(velocities, payload_velocity), second,
                       rtol=1e-5)


def test_jacobian_has_full_row_rank_on_the_manifold():
    # seed Theorem 1
    payload = np.array([0.3, -0.2, 0.0])
    directions = RNG.normal(size=(N, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    positions = payload - LENGTHS[:, None] * directions
    assert np.allclose(cable_residuals(positions, payload, LENGTHS), 0.0, atol=1e-12)
    assert np.linalg.matrix_rank(constraint_jacobian(positions, payload)) == N


def test_tension_sign_convention():
    assert np.allclose(cable_tension([0.5, -0.1, 0.0], LENGTHS), [2.0, -0.5, 0.0])
