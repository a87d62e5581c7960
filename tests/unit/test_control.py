"""Control laws on their own: mission path, thrust direction (seed Eq. 3.13), rotor mixing."""
from __future__ import annotations

import math

import numpy as np
import pytest

from multilift_control.cascade import (CascadeController, RotorMixer, UavState,
                                       attitude_from_force, balancing_rotor_speed)
from multilift_control.mission import MissionPath
from multilift_sim import scenario as scenario_io
from multilift_sim.allocation import allocation_matrix
from multilift_sim.kinematics import rotation_matrix


def test_mission_path_follows_the_seed_legs():
    path = MissionPath(scenario_io.load('single_lift').mission)
    assert np.allclose(path(5.0).position, [0, 0, 1.5])
    assert np.allclose(path(10.0).position, [0, 0, 3.0])
    assert np.allclose(path(25.0).position, [7.5, 0, 3.0])
    assert np.allclose(path(40.0).position, [7.5, -7.5, 3.0])
    assert np.allclose(path(100.0).position, [-22.5, -7.5, 3.0])
    assert np.allclose(path(110.0).position, [-22.5, -7.5, 3.0])
    assert np.allclose(path(30.0).velocity, [0, -0.5, 0])
    assert np.allclose(path(119.0).velocity, 0)


@pytest.mark.parametrize('yaw', [0.0, 0.7, -2.0])
@pytest.mark.parametrize('force', [[3.0, -2.0, 30.0], [-5.0, 1.0, 20.0], [0.0, 0.0, 25.0]])
def test_attitude_from_force_points_thrust_along_force(force, yaw):
    roll, pitch, thrust = attitude_from_force(np.array(force), yaw)
    thrust_vector = rotation_matrix(np.array([roll, pitch, yaw])) @ [0, 0, thrust]
    assert np.allclose(thrust_vector, force, atol=1e-9)


def test_attitude_from_force_limits_tilt():
    roll, pitch, thrust = attitude_from_force(np.array([100.0, 0.0, 10.0]), 0.0,
                                              math.radians(20))
    assert pitch == pytest.approx(math.radians(20))
    assert roll == pytest.approx(0.0)


def _vehicle():
    return scenario_io.load('single_lift').uavs[0].vehicle


def test_mixer_reproduces_the_wrench_inside_limits():
    v = _vehicle()
    mixer = RotorMixer(v)
    speeds, saturated = mixer.rotor_speeds(20.0, np.array([0.1, -0.2, 0.01]))
    assert not saturated.any()
    k = allocation_matrix(v.frame_type, v.arm_length, v.thrust_coefficient, v.moment_coefficient)
    assert np.allclose(k @ speeds ** 2, [20.0, 0.1, -0.2, 0.01])


def test_mixer_keeps_torque_and_stays_in_limits_when_thrust_is_too_high():
    v = _vehicle()
    mixer = RotorMixer(v)
    torque = np.array([0.3, 0.0, 0.0])
    speeds, saturated = mixer.rotor_speeds(40.0, torque)  # more than the 32.28 N available
    assert saturated.any()
    assert speeds.max() <= v.rotor_speed_max + 1e-9 and speeds.min() >= v.rotor_speed_min
    k = allocation_matrix(v.frame_type, v.arm_length, v.thrust_coefficient, v.moment_coefficient)
    assert np.allclose((k @ speeds ** 2)[1:], torque, atol=1e-9)  # attitude torque kept


def test_hover_speed_balances_weight():
    v = _vehicle()
    w = balancing_rotor_speed(v, 2.9, 9.81)
    assert v.n_rotors * v.thrust_coefficient * w ** 2 == pytest.approx(2.9 * 9.81)
    assert w == pytest.approx(1971.4, abs=0.5)


def test_cascade_holds_hover_with_no_error():
    s = scenario_io.load('single_lift')
    c = CascadeController(s.uavs[0].vehicle, s.control, 2.9, 9.81)
    state = UavState(np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3))
    out = c.update(0.0, state, np.zeros(3), np.zeros(3), np.zeros(3))
    assert np.allclose(out.attitude_setpoint, 0)
    assert out.thrust == pytest.approx(2.9 * 9.81)
    assert np.allclose(out.rotor_speeds, balancing_rotor_speed(s.uavs[0].vehicle, 2.9, 9.81))


def test_cascade_leans_towards_a_position_error():
    s = scenario_io.load('single_lift')
    c = CascadeController(s.uavs[0].vehicle, s.control, 2.9, 9.81)
    state = UavState(np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3))
    out = c.update(0.0, state, np.array([1.0, 0.0, 0.0]), np.zeros(3), np.zeros(3))
    # to go +x (forward) a FLU body pitches nose down: positive pitch
    assert out.attitude_setpoint[1] > 0
    out = c.update(0.0, state, np.array([0.0, 1.0, 0.0]), np.zeros(3), np.zeros(3))
    assert out.attitude_setpoint[0] < 0  # to go +y (left) it rolls left: negative roll
