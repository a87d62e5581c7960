"""frames.py: the seed (z-down, FRD) <-> world (z-up, FLU) maps are consistent with the
kinematics, so a rotation, a body rate or a position means the same thing in both frames."""
import numpy as np
import pytest

from multilift_sim.frames import (seed_to_world_body_vector, seed_to_world_euler,
                                  seed_to_world_vector, world_to_seed_body_vector,
                                  world_to_seed_euler, world_to_seed_vector)
from multilift_sim.kinematics import euler_rate_matrix, rotation_matrix

FLIP = np.diag([1.0, -1.0, -1.0])  # 180 deg about x


def test_vector_maps_flip_y_and_z_and_are_involutions():
    v = np.array([1.0, 2.0, 3.0])
    assert np.array_equal(seed_to_world_vector(v), [1.0, -2.0, -3.0])
    stack = np.random.default_rng(1).normal(size=(4, 5, 3))
    for there, back in ((seed_to_world_vector, world_to_seed_vector),
                        (seed_to_world_euler, world_to_seed_euler),
                        (seed_to_world_body_vector, world_to_seed_body_vector)):
        assert np.array_equal(back(there(stack)), stack)


def test_below_in_the_seed_is_below_in_the_world():
    # seed z points down: a payload 2 m "below" has z_seed = +2 and must get z_world = -2
    assert seed_to_world_vector([0.0, 0.0, 2.0])[2] == -2.0


def test_euler_map_reproduces_the_same_physical_rotation():
    rng = np.random.default_rng(2)
    eta_seed = rng.uniform(-1.2, 1.2, size=(20, 3))
    r_seed = rotation_matrix(eta_seed)
    r_world = rotation_matrix(seed_to_world_euler(eta_seed))
    # a body vector v_FRD = P v_FLU maps to the seed frame by R_seed; world = P seed
    assert np.allclose(r_world, FLIP @ r_seed @ FLIP, atol=1e-14)


def test_body_rates_map_like_body_vectors():
    rng = np.random.default_rng(3)
    eta_seed = rng.uniform(-1.2, 1.2, size=(20, 3))
    eta_dot_seed = rng.normal(size=(20, 3))
    omega_seed = (euler_rate_matrix(eta_seed) @ eta_dot_seed[..., None])[..., 0]
    omega_world = (euler_rate_matrix(seed_to_world_euler(eta_seed))
                   @ seed_to_world_euler(eta_dot_seed)[..., None])[..., 0]
    assert np.allclose(omega_world, seed_to_world_body_vector(omega_seed), atol=1e-14)


def test_wrong_shape_is_rejected():
    with pytest.raises(ValueError, match='shape'):
        seed_to_world_vector([1.0, 2.0])
