"""allocation.py: the rotor layout of docs/conventions.md, torque signs from physics, the seed's
Table 2.1 Q+ row and the Table 4.2 thrust limit."""
import math

import numpy as np
import pytest

from multilift_sim.allocation import (Allocator, allocation_matrix,
                                      rotor_positions, rotor_spin_directions)
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.vehicles import SHIPPED as FRAME_TYPES

# Table 4.2 vehicle
ARM, K_T, K_D, W_MAX = 0.2, 1.83e-6, 1.85e-7, 2100.0


def allocator(frame_type: str) -> Allocator:
    return Allocator(frame_type, ARM, K_T, K_D)


def signum(value: float, tolerance: float) -> int:
    return 0 if abs(value) < tolerance else (1 if value > 0 else -1)


def torque_of_one_rotor(frame_type: str, rotor: int) -> np.ndarray:
    """Body torque change (FLU) when rotor `rotor` (0-based) speeds up from a hover speed."""
    alloc = allocator(frame_type)
    base = np.full(alloc.n_rotors, 1500.0)
    faster = base.copy()
    faster[rotor] += 100.0
    return alloc.wrench(faster)[1:] - alloc.wrench(base)[1:]


@pytest.mark.parametrize('frame_type', FRAME_TYPES)
def test_round_trip_within_limits(frame_type):
    alloc = allocator(frame_type)
    hover = 0.6 * alloc.n_rotors * K_T * W_MAX ** 2
    for u in ([hover, 0.0, 0.0, 0.0], [hover, 0.4, -0.3, 0.05], [hover, -0.2, 0.5, -0.08]):
        omega, saturated = alloc.rotor_speeds(u, 0.0, W_MAX)
        assert not saturated.any()
        assert np.allclose(alloc.wrench(omega), u, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize('frame_type', FRAME_TYPES)
def test_every_rotor_torque_has_the_physical_sign(frame_type):
    positions = rotor_positions(frame_type, ARM)
    # rotor 1 is the front (+) or front-right (x) one, numbering clockwise seen from above
    bearing = np.arctan2(positions[:, 1], positions[:, 0])
    assert positions[0, 0] > 0 and positions[0, 1] <= 1e-12
    assert np.all(np.sin(np.diff(bearing)) < 0)  # each next rotor is clockwise (towards -y)
    for k in range(len(positions)):
        torque = torque_of_one_rotor(frame_type, k)
        x, y, _ = positions[k]
        # more lift on the left (y > 0) rolls right-side-down: +tau_x in FLU
        assert signum(torque[0], 1e-9) == signum(y, 1e-12)
        # more lift in front pitches the nose up: -tau_y in FLU
        assert signum(torque[1], 1e-9) == -signum(x, 1e-12)
        # odd rotors (k = 1, 3, ...) spin clockwise seen from above: reaction +tau_z
        assert signum(torque[2], 1e-9) == (1 if k % 2 == 0 else -1)


def test_quad_x_rotor_corners():
    # rotor 1 front-right, 2 back-right, 3 back-left, 4 front-left (clockwise from above)
    expected_signs = [(-1, -1, 1), (-1, 1, -1), (1, 1, 1), (1, -1, -1)]
    for k, signs in enumerate(expected_signs):
        assert tuple(np.sign(torque_of_one_rotor('quad_x', k))) == signs
    assert np.array_equal(rotor_spin_directions('quad_x'), [1.0, -1.0, 1.0, -1.0])


def test_quad_plus_matches_the_seed_table_2_1_q_plus_row():
    # Table 2.1, Q+ (FRD body, thrust row positive magnitudes):
    #   roll  [0, -l k_T, 0, l k_T], pitch [l k_T, 0, -l k_T, 0], yaw [-k_D, k_D, -k_D, k_D].
    # FRD -> FLU flips the sign of the pitch and yaw rows (frames.py).
    lk = ARM * K_T
    expected = np.array([[K_T, K_T, K_T, K_T],
                         [0.0, -lk, 0.0, lk],
                         [-lk, 0.0, lk, 0.0],
                         [K_D, -K_D, K_D, -K_D]])
    assert np.allclose(allocation_matrix('quad_plus', ARM, K_T, K_D), expected, atol=1e-20)


def test_saturation_clips_and_flags():
    alloc = allocator('quad_x')
    omega, saturated = alloc.rotor_speeds([40.0, 0.0, 0.0, 0.0], 0.0, W_MAX)   # > 32.28 N
    assert np.allclose(omega, W_MAX) and saturated.all()
    # a large negative roll torque (lift the right side) asks the left rotors 3 and 4 for
    # omega^2 < 0: clipped to the minimum and flagged
    omega, saturated = alloc.rotor_speeds([5.0, -3.0, 0.0, 0.0], 100.0, W_MAX)
    assert np.array_equal(saturated, [False, False, True, True])
    assert np.allclose(omega[2:], 100.0) and np.all(omega[:2] < W_MAX)


def test_table_4_2_vehicle_max_thrust():
    vehicle = MultirotorParams(mass=2.5, inertia=(0.957, 0.486, 0.355), frame_type='quad_x',
                               arm_length=ARM, thrust_coefficient=K_T, moment_coefficient=K_D,
                               rotor_speed_min=0.0, rotor_speed_max=W_MAX)
    assert math.isclose(vehicle.max_thrust, 32.28, abs_tol=0.005)
    assert math.isclose(allocator('quad_x').wrench(np.full(4, W_MAX))[0], 32.28, abs_tol=0.005)


def test_unknown_frame_type_names_it_and_the_valid_ones():
    with pytest.raises(ValueError, match="'tri_y'.*quad_plus, quad_x, hexa_plus"):
        allocation_matrix('tri_y', ARM, K_T, K_D)
