"""multirotor.py: M_eta of seed Eq. 2.24, the velocity term derived from the Lagrangian (not the
printed C_eta), and torque-free rigid-body invariants."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from multilift_sim.kinematics import euler_rate_matrix, rotation_matrix
from multilift_sim.multirotor import (MultirotorParams, euler_acceleration, euler_mass_matrix,
                                      euler_velocity_term, rotational_kinetic_energy)

INERTIA = np.array([0.957, 0.486, 0.355])   # seed Table 4.1 [kg m^2]
RNG = np.random.default_rng(11)
SAMPLES = [(RNG.uniform(-1.3, 1.3, 3), RNG.normal(size=3)) for _ in range(10)]


def kinetic_energy(eta, eta_dot):
    """T = 1/2 eta_dot^T M_eta eta_dot (seed Eq. 2.22)."""
    return 0.5 * eta_dot @ euler_mass_matrix(INERTIA, eta) @ eta_dot


def lagrangian_velocity_term(eta, eta_dot, h=1e-6):
    """M_eta_dot eta_dot - dT/deta by central finite differences (seed Eq. 2.25-2.27)."""
    m_dot = (euler_mass_matrix(INERTIA, eta + h * eta_dot)
             - euler_mass_matrix(INERTIA, eta - h * eta_dot)) / (2 * h)
    grad = np.array([(kinetic_energy(eta + h * e, eta_dot) - kinetic_energy(eta - h * e, eta_dot))
                     / (2 * h) for e in np.eye(3)])
    return m_dot @ eta_dot - grad


def test_mass_matrix_matches_seed_eq_2_24():
    i_xx, i_yy, i_zz = INERTIA
    for eta, _ in SAMPLES:
        s_phi, c_phi, s_th, c_th = math.sin(eta[0]), math.cos(eta[0]), math.sin(eta[1]), \
            math.cos(eta[1])
        printed = np.array([
            [i_xx, 0.0, -i_xx * s_th],
            [0.0, i_yy * c_phi ** 2 + i_zz * s_phi ** 2, s_phi * c_phi * c_th * (i_yy - i_zz)],
            [-i_xx * s_th, s_phi * c_phi * c_th * (i_yy - i_zz),
             i_xx * s_th ** 2 + c_th ** 2 * (i_yy * s_phi ** 2 + i_zz * c_phi ** 2)]])
        assert np.allclose(euler_mass_matrix(INERTIA, eta), printed, atol=1e-14)


def test_velocity_term_equals_lagrangian_finite_differences():
    for eta, eta_dot in SAMPLES:
        assert np.allclose(euler_velocity_term(INERTIA, eta, eta_dot),
                           lagrangian_velocity_term(eta, eta_dot), rtol=1e-6, atol=1e-7)


def printed_coriolis_matrix(eta, eta_dot):
    """C_eta exactly as printed after seed Eq. 2.27 (transcribed element by element)."""
    i_xx, i_yy, i_zz = INERTIA
    phi, theta = eta[0], eta[1]
    phi_d, theta_d, psi_d = eta_dot
    sp, cp, st, ct = math.sin(phi), math.cos(phi), math.sin(theta), math.cos(theta)
    c12 = sp * cp * (i_yy - i_zz) * theta_d + sp ** 2 * ct * (i_yy - i_zz) * psi_d \
        - i_xx * psi_d * ct
    c13 = sp * cp * ct ** 2 * (i_zz - i_yy) * psi_d + cp ** 2 * ct * (i_zz - i_yy) * theta_d \
        - i_xx * ct * theta_d
    c21 = i_zz * psi_d * ct + (i_yy - i_xx) * (-theta_d * st * cp + psi_d * ct * cp ** 2
                                                - psi_d * ct * sp ** 2)
    c22 = -(i_yy - i_xx) * sp * cp * phi_d
    c23 = psi_d * st * ct * (-i_zz + i_yy * sp ** 2 + i_xx * cp ** 2)
    c31 = -(i_xx * theta_d * ct - (i_yy - i_xx) * (psi_d * ct ** 2 * sp * cp))
    c32 = i_zz * psi_d * st * ct - (i_yy - i_xx) * (theta_d * st * cp * sp + phi_d * ct * sp ** 2) \
        - (i_yy + i_xx) * (psi_d * st * ct * cp ** 2 - phi_d * ct * cp ** 2)
    c33 = i_zz * theta_d * st * ct - (i_yy + i_xx) * (theta_d * st * ct * sp ** 2) \
        + (i_yy - i_xx) * phi_d * ct ** 2 * sp * cp
    return np.array([[0.0, c12, c13], [c21, c22, c23], [c31, c32, c33]])


def test_printed_coriolis_matrix_is_not_the_lagrangian_one():
    # Why multirotor.py derives C_eta eta_dot instead of copying the print.
    errors = [np.abs(printed_coriolis_matrix(e, ed) @ ed - lagrangian_velocity_term(e, ed)).max()
              for e, ed in SAMPLES]
    assert min(errors) > 1e-2


def test_acceleration_solves_the_euler_lagrange_equation():
    for eta, eta_dot in SAMPLES:
        torque = RNG.normal(size=3)
        rhs = euler_rate_matrix(eta).T @ torque - euler_velocity_term(INERTIA, eta, eta_dot)
        expected = np.linalg.solve(euler_mass_matrix(INERTIA, eta), rhs)
        assert np.allclose(euler_acceleration(INERTIA, eta, eta_dot, torque), expected,
                           rtol=1e-10, atol=1e-12)


def test_torque_free_rotation_conserves_energy_and_world_angular_momentum():
    eta0 = np.array([0.1, -0.2, 0.3])
    omega0 = np.array([0.05, 1.5, 0.2])   # near the intermediate axis: it tumbles
    eta_dot0 = np.linalg.solve(euler_rate_matrix(eta0), omega0)

    def rhs(_t, state):
        return np.concatenate((state[3:], euler_acceleration(INERTIA, state[:3], state[3:],
                                                             np.zeros(3))))

    sol = solve_ivp(rhs, (0.0, 2.0), np.concatenate((eta0, eta_dot0)), method='DOP853',
                    rtol=1e-11, atol=1e-12, t_eval=np.linspace(0.0, 2.0, 201))
    eta, eta_dot = sol.y[:3].T, sol.y[3:].T
    assert np.abs(eta[:, 1]).max() < 1.3            # away from the Euler singularity
    omega = (euler_rate_matrix(eta) @ eta_dot[..., None])[..., 0]
    assert np.abs(omega - omega0).max() > 0.1       # the body rates really change
    energy = rotational_kinetic_energy(INERTIA, eta, eta_dot)
    momentum = (rotation_matrix(eta) @ (INERTIA * omega)[..., None])[..., 0]
    assert np.abs(energy - energy[0]).max() < 1e-9 * energy[0]
    assert np.abs(momentum - momentum[0]).max() < 1e-9 * np.linalg.norm(momentum[0])


def test_params_validate_and_describe_the_table_4_2_vehicle():
    vehicle = MultirotorParams(mass=2.5, inertia=(0.957, 0.486, 0.355), frame_type='quad_x',
                               arm_length=0.2, thrust_coefficient=1.83e-6,
                               moment_coefficient=1.85e-7, rotor_speed_min=0.0,
                               rotor_speed_max=2100.0)
    assert vehicle.n_rotors == 4
    assert math.isclose(vehicle.max_thrust, 32.28, abs_tol=0.005)
    with pytest.raises(ValueError, match='mass'):
        MultirotorParams(mass=-1.0, inertia=(1, 1, 1), frame_type='quad_x', arm_length=0.2,
                         thrust_coefficient=1e-6, moment_coefficient=1e-7, rotor_speed_min=0.0,
                         rotor_speed_max=2000.0)
    with pytest.raises(ValueError, match='rotor_speed_min'):
        MultirotorParams(mass=1.0, inertia=(1, 1, 1), frame_type='hexa_x', arm_length=0.2,
                         thrust_coefficient=1e-6, moment_coefficient=1e-7,
                         rotor_speed_min=2000.0, rotor_speed_max=2000.0)
    with pytest.raises(ValueError, match='octo_x'):
        MultirotorParams(mass=1.0, inertia=(1, 1, 1), frame_type='y6', arm_length=0.2,
                         thrust_coefficient=1e-6, moment_coefficient=1e-7, rotor_speed_min=0.0,
                         rotor_speed_max=2000.0)
