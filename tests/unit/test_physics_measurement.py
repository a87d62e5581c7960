"""What the controllers measure (physics.measurement, seed Eq. 2.7), the odometry rows the
messages carry (R, R^T v, the quaternion) and the rotor wrenches (physics.allocation,
Eq. 2.14): compiled vs their uncompiled run to the bit, and against independent forms
(kinematics' W(eta), R and quaternion, msgvalues.quaternion, each allocator's matrix
product)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from multilift_sim import kernels
from multilift_sim.wire import msgvalues
from multilift_sim import scenario as scenario_io
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import StateLayout
from multilift_sim.kinematics import quaternion_from_euler, rotation_matrix
from multilift_sim.physics.allocation import rotor_wrenches
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_COLUMNS, MEASURED_EULER,
                                          MEASURED_POSITION, MEASURED_VELOCITY,
                                          ODOMETRY_BODY_VELOCITY, ODOMETRY_COLUMNS,
                                          ODOMETRY_QUATERNION, ODOMETRY_ROTATION)
from multilift_sim.physics.measurement import measured_states, odometry_states


def _angles(n: int, rng) -> np.ndarray:
    """ZYX angles (n, 3) [rad] in the output's ranges: roll and yaw in (-pi, pi], pitch in
    (-pi/2, pi/2)."""
    return np.column_stack((rng.uniform(-3.1, 3.1, n), rng.uniform(-1.5, 1.5, n),
                            rng.uniform(-3.1, 3.1, n)))


def _random_state(n: int, rng) -> np.ndarray:
    layout = StateLayout(n)
    x = rng.normal(size=layout.size)
    layout.set_uav_euler(x, _angles(n, rng))
    return x


@pytest.mark.parametrize('n', [1, 2, 5])
def test_measured_states_compiled_equal_uncompiled_and_w_eta_dot(n):
    rng = np.random.default_rng(n)
    x = _random_state(n, rng)
    compiled, python = np.empty((n, MEASURED_COLUMNS)), np.empty((n, MEASURED_COLUMNS))
    measured_states(x, n, compiled)
    kernels.uncompiled(measured_states)(x, n, python)
    assert np.array_equal(compiled, python)
    layout = StateLayout(n)
    for i in range(n):
        row = compiled[i]
        assert np.array_equal(row[MEASURED_POSITION:MEASURED_POSITION + 3],
                              layout.uav_positions(x)[i])
        assert np.array_equal(row[MEASURED_VELOCITY:MEASURED_VELOCITY + 3],
                              layout.uav_velocities(x)[i])
        assert np.array_equal(row[MEASURED_BODY_RATES:MEASURED_BODY_RATES + 3],
                              layout.uav_body_rates(x)[i])
        # the angles are the quaternion's: R of them is R of the quaternion (scipy's, an
        # independent form)
        eta = row[MEASURED_EULER:MEASURED_EULER + 3]
        w, qx, qy, qz = layout.uav_quaternions(x)[i]
        np.testing.assert_allclose(rotation_matrix(eta),
                                   Rotation.from_quat([qx, qy, qz, w]).as_matrix(),
                                   rtol=0, atol=1e-14)


def test_the_angles_of_a_quaternion_are_its_angles_up_to_and_at_90_degrees_pitch():
    rng = np.random.default_rng(3)
    angles = _angles(200, rng)
    angles[:5, 1] = (math.pi / 2, -math.pi / 2, math.pi / 2 - 1e-9, 1.0, -1.0)
    layout = StateLayout(200)
    x = np.zeros(layout.size)
    layout.set_uav_euler(x, angles)
    back = layout.uav_euler(x)
    assert np.abs(back[3:] - angles[3:]).max() < 1e-13
    for k in range(200):  # at 90 deg pitch only roll - yaw (or + yaw) is defined: compare R
        np.testing.assert_allclose(rotation_matrix(back[k]), rotation_matrix(angles[k]),
                                   rtol=0, atol=1e-8 if k < 3 else 1e-14)
    assert np.abs(np.abs(back[:2, 1]) - math.pi / 2).max() < 1e-8
    assert np.array_equal(back[:3, 2], np.zeros(3))  # at the lock: yaw 0, roll the rest


@pytest.mark.parametrize('n', [1, 2, 5])
def test_odometry_states_compiled_equal_uncompiled_and_the_oracles(n):
    rng = np.random.default_rng(10 + n)
    states = np.stack([_random_state(n, rng) for _ in range(4)])
    compiled, python = np.empty((4, n, ODOMETRY_COLUMNS)), np.empty((4, n, ODOMETRY_COLUMNS))
    odometry_states(states, n, compiled)
    kernels.uncompiled(odometry_states)(states, n, python)
    assert np.array_equal(compiled, python)
    for k, x in enumerate(states):
        measured = np.empty((n, MEASURED_COLUMNS))
        measured_states(x, n, measured)
        assert np.array_equal(compiled[k, :, :MEASURED_COLUMNS], measured)
        euler = measured[:, MEASURED_EULER:MEASURED_EULER + 3]
        velocity = measured[:, MEASURED_VELOCITY:MEASURED_VELOCITY + 3]
        rotation = compiled[k, :, ODOMETRY_ROTATION:ODOMETRY_ROTATION + 9].reshape(n, 3, 3)
        assert np.allclose(rotation, rotation_matrix(euler), rtol=0.0, atol=1e-15)
        assert np.allclose(rotation @ rotation.swapaxes(1, 2), np.eye(3), rtol=0, atol=1e-15)
        body = compiled[k, :, ODOMETRY_BODY_VELOCITY:ODOMETRY_BODY_VELOCITY + 3]
        assert np.allclose(body, np.einsum('nji,nj->ni', rotation, velocity), rtol=1e-15,
                           atol=1e-15)
        # each element the sum (R_0j v_x + R_1j v_y) + R_2j v_z, no fused multiply-add
        assert np.array_equal(body, (rotation[:, 0] * velocity[:, :1]
                                     + rotation[:, 1] * velocity[:, 1:2])
                              + rotation[:, 2] * velocity[:, 2:])
        quaternion = compiled[k, :, ODOMETRY_QUATERNION:ODOMETRY_QUATERNION + 4]
        assert quaternion.tolist() == [list(msgvalues.quaternion(e)) for e in euler]
        assert np.allclose(quaternion, quaternion_from_euler(euler), rtol=0.0, atol=1e-15)


def test_rotor_wrenches_are_each_allocation_times_the_squared_speeds():
    scenario = scenario_io.load('circle3')
    model = FormationModel(scenario.formation_params())
    rng = np.random.default_rng(4)
    speeds = rng.uniform(800.0, 2000.0, size=(scenario.n_uavs, model.allocation.shape[2]))
    compiled, python = np.empty((scenario.n_uavs, 4)), np.empty((scenario.n_uavs, 4))
    intact = np.ones_like(speeds)
    rotor_wrenches(model.allocation, speeds, intact, compiled)
    kernels.uncompiled(rotor_wrenches)(model.allocation, speeds, intact, python)
    assert np.array_equal(compiled, python)
    for i, uav in enumerate(scenario.uavs):
        expected = uav.vehicle.allocator().matrix @ speeds[i] ** 2
        assert np.allclose(compiled[i], expected, rtol=1e-13)
    assert np.array_equal(model.wrenches(list(speeds)), compiled)
    # a rotor at effectiveness e gives e times its thrust and moment: rotor 2 of UAV 1 at half
    # is the intact rotor at speed omega / sqrt(2); a failed rotor adds nothing
    effectiveness = intact.copy()
    effectiveness[0, 1], effectiveness[1, 0] = 0.5, 0.0
    rotor_wrenches(model.allocation, speeds, effectiveness, compiled)
    slower = speeds.copy()
    slower[0, 1] /= math.sqrt(2.0)
    slower[1, 0] = 0.0
    rotor_wrenches(model.allocation, slower, intact, python)
    assert np.allclose(compiled, python, rtol=1e-13)
