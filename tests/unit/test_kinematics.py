"""kinematics.py against scipy's rotations and finite differences (seed Eq. 2.6-2.8)."""
import numpy as np
from scipy.spatial.transform import Rotation

from multilift_sim.kinematics import (euler_from_quaternion, euler_rate_matrix,
                                      euler_rate_matrix_dot, euler_rate_matrix_inverse,
                                      quaternion_from_euler, rotation_matrix)

RNG = np.random.default_rng(7)
ETA = RNG.uniform([-1.5, -1.4, -3.1], [1.5, 1.4, 3.1], size=(12, 3))
ETA_DOT = RNG.normal(size=(12, 3))


def test_rotation_matrix_is_intrinsic_zyx_body_to_world():
    for eta in ETA:
        phi, theta, psi = eta
        expected = Rotation.from_euler('ZYX', [psi, theta, phi]).as_matrix()
        assert np.allclose(rotation_matrix(eta), expected, atol=1e-14)


def test_vectorised_over_uavs():
    stacked = rotation_matrix(ETA)
    assert stacked.shape == (12, 3, 3)
    assert np.allclose(stacked, [rotation_matrix(e) for e in ETA])
    assert euler_rate_matrix(ETA).shape == (12, 3, 3)
    assert euler_rate_matrix_dot(ETA, ETA_DOT).shape == (12, 3, 3)


def test_w_gives_body_rates_of_the_rotating_frame():
    # [omega]_x = R^T R_dot with R_dot by central differences along eta(t) = eta + t eta_dot
    h = 1e-6
    for eta, eta_dot in zip(ETA, ETA_DOT):
        r = rotation_matrix(eta)
        r_dot = (rotation_matrix(eta + h * eta_dot) - rotation_matrix(eta - h * eta_dot)) / (2 * h)
        skew = r.T @ r_dot
        omega = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
        assert np.allclose(euler_rate_matrix(eta) @ eta_dot, omega, atol=1e-8)


def test_w_inverse_and_w_dot():
    assert np.allclose(euler_rate_matrix_inverse(ETA) @ euler_rate_matrix(ETA), np.eye(3),
                       atol=1e-12)
    h = 1e-6
    numeric = (euler_rate_matrix(ETA + h * ETA_DOT)
               - euler_rate_matrix(ETA - h * ETA_DOT)) / (2 * h)
    assert np.allclose(euler_rate_matrix_dot(ETA, ETA_DOT), numeric, atol=1e-8)


def test_quaternion_from_euler_is_scipys_zyx_quaternion():
    q = quaternion_from_euler(ETA)
    expected = Rotation.from_euler('ZYX', ETA[:, ::-1]).as_quat()  # (x, y, z, w)
    assert q.shape == (12, 4)
    signs = np.sign(np.sum(q * expected, axis=1))[:, None]  # q and -q are one rotation
    assert np.allclose(q, signs * expected, atol=1e-14)
    assert np.allclose(quaternion_from_euler(ETA[3]), q[3], atol=0)  # one attitude, shape (3,)


def test_euler_from_quaternion_inverts_quaternion_from_euler():
    angles = RNG.uniform([-3.0, -1.5, -3.0], [3.0, 1.5, 3.0], size=(200, 3))
    np.testing.assert_allclose(euler_from_quaternion(quaternion_from_euler(angles)), angles,
                               atol=1e-9)
    # a stack of any shape, scipy's quaternions as input
    stack = Rotation.from_euler('ZYX', angles[:6, ::-1]).as_quat().reshape(2, 3, 4)
    np.testing.assert_allclose(euler_from_quaternion(stack), angles[:6].reshape(2, 3, 3),
                               atol=1e-9)


def test_message_quaternion_is_quaternion_from_euler():
    """msgvalues.quaternion (plain floats, one attitude per message) against the array form."""
    from multilift_sim.wire.msgvalues import quaternion
    rng = np.random.default_rng(11)
    for eta in rng.uniform(-np.pi, np.pi, (200, 3)):
        np.testing.assert_allclose(quaternion(eta), quaternion_from_euler(eta), rtol=0,
                                   atol=1e-15)
