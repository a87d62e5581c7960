"""reduced_model.py: the printed single-lift matrices (seed Eq. 2.35-2.39) against a Lagrangian
built from positions, and the pendulum mode of seed Sec. 2.8.1 by numerical linearisation."""
import math

import numpy as np

from multilift_sim.analysis.reduced_model import ReducedSingleLiftModel, rest_state
from multilift_sim.constraints import cable_residual_rates, cable_residuals
from multilift_sim.formation_params import StateLayout
from multilift_sim.kinematics import euler_rate_matrix
from multilift_sim.multirotor import MultirotorParams

UAV = MultirotorParams(mass=2.5, inertia=(0.957, 0.486, 0.355), frame_type='quad_x',
                       arm_length=0.2, thrust_coefficient=1.83e-6, moment_coefficient=1.85e-7,
                       rotor_speed_min=0.0, rotor_speed_max=2100.0)
MODEL = ReducedSingleLiftModel(UAV, payload_mass=0.4, cable_length=2.5, gravity=9.81)
HOVER = np.full(4, math.sqrt((2.5 + 0.4) * 9.81 / (4 * 1.83e-6)))
RNG = np.random.default_rng(3)
SAMPLES = [(RNG.uniform(-1.0, 1.0, 8), RNG.normal(size=8)) for _ in range(6)]


def kinetic_energy(q, q_dot):
    """T of UAV translation and rotation plus payload translation, with the payload velocity
    the time derivative of Eq. 2.33 worked by hand (independent of the printed matrices)."""
    s_a, c_a, s_b, c_b = math.sin(q[6]), math.cos(q[6]), math.sin(q[7]), math.cos(q[7])
    alpha_dot, beta_dot = q_dot[6], q_dot[7]
    payload_velocity = q_dot[:3] + 2.5 * np.array([
        -s_a * s_b * alpha_dot + c_a * c_b * beta_dot,
        -c_a * alpha_dot,
        -s_a * c_b * alpha_dot - c_a * s_b * beta_dot])
    omega = euler_rate_matrix(q[3:6]) @ q_dot[3:6]
    return 0.5 * (UAV.mass * q_dot[:3] @ q_dot[:3] + MODEL.payload_mass
                  * payload_velocity @ payload_velocity + omega @ (np.array(UAV.inertia) * omega))


def potential_energy(q):
    """U = -(m z + m_p z_p) g: the seed frame points z down (seed Eq. 2.44)."""
    return -9.81 * (UAV.mass * q[2] + MODEL.payload_mass * MODEL.payload_position(q)[2])


def test_mass_matrix_reproduces_the_kinetic_energy():
    for q, q_dot in SAMPLES:
        assert math.isclose(0.5 * q_dot @ MODEL.mass_matrix(q) @ q_dot, kinetic_energy(q, q_dot),
                            rel_tol=1e-8)


def test_velocity_and_gravity_terms_match_the_euler_lagrange_equation():
    h = 1e-6
    for q, q_dot in SAMPLES:
        m_dot = (MODEL.mass_matrix(q + h * q_dot) - MODEL.mass_matrix(q - h * q_dot)) / (2 * h)
        grad_t = np.array([(kinetic_energy(q + h * e, q_dot) - kinetic_energy(q - h * e, q_dot))
                           / (2 * h) for e in np.eye(8)])
        assert np.allclose(MODEL.velocity_term(q, q_dot), m_dot @ q_dot - grad_t, atol=1e-6)
        grad_u = np.array([(potential_energy(q + h * e) - potential_energy(q - h * e)) / (2 * h)
                           for e in np.eye(8)])
        assert np.allclose(MODEL.gravity_term(q), grad_u, atol=1e-6)


def test_world_state_of_a_reduced_state_satisfies_the_cable_constraint():
    for q, q_dot in SAMPLES:
        x = MODEL.to_formation_state(np.concatenate((q, q_dot)))
        layout = StateLayout(1)
        positions, payload = layout.uav_positions(x), layout.payload_position(x)
        assert abs(cable_residuals(positions, payload, [2.5])[0]) < 1e-12
        assert abs(cable_residual_rates(positions, layout.uav_velocities(x), payload,
                                        layout.payload_velocity(x))[0]) < 1e-12


def test_linearised_pendulum_mode_is_2_13_rad_s_and_2_94_s():
    # seed Sec. 2.8.1: two pairs +-2.13j (period 2.94 s); the other 12 eigenvalues are zero
    a = MODEL.linearise(rest_state([0.0, 0.0, -10.0], [0.0, 0.0, 0.3], 0.0, 0.0), HOVER)
    eigenvalues = np.linalg.eigvals(a)
    oscillatory = eigenvalues[np.abs(eigenvalues) > 1e-3]
    assert len(oscillatory) == 4
    assert np.abs(oscillatory.real).max() < 1e-6
    assert np.allclose(np.abs(oscillatory.imag), 2.13, atol=0.005)
    assert math.isclose(2 * math.pi / np.abs(oscillatory.imag).mean(), 2.94, abs_tol=0.006)
