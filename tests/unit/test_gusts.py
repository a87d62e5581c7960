"""wind/gusts.py: the 1-cosine gust of seed Eq. 2.55 and the air-relative drag of Eq. 2.53."""
import math

import numpy as np
import pytest

from multilift_sim.wind.gusts import Gust, gust_velocity, payload_drag

# seed Sec. 4.2: lateral gust at (-4, 6) m, H = 2 m, U_ref = 3 m/s, along +j of the seed
# (-y of the world)
LATERAL = Gust(center=(-4.0, 6.0), direction=(0.0, -1.0, 0.0), gradient_distance=2.0,
               reference_speed=3.0)


def test_one_minus_cosine_profile():
    assert np.allclose(gust_velocity([LATERAL], [-4.0, 6.0, 10.0]), [0.0, -3.0, 0.0])
    # r = H/2: U = U_ref/2 (1 + cos(pi/2)) = U_ref/2, in any horizontal direction
    for angle in np.linspace(0.0, 2 * np.pi, 7):
        point = [-4.0 + math.cos(angle), 6.0 + math.sin(angle), -3.0]
        assert LATERAL.speed(point) == pytest.approx(1.5, abs=1e-12)
    assert LATERAL.speed([-4.0 + 1.999999, 6.0, 0.0]) < 1e-10
    assert LATERAL.speed([-4.0, 8.5, 0.0]) == 0.0


def test_only_the_horizontal_distance_counts():
    speeds = [LATERAL.speed([-3.0, 6.5, z]) for z in (-50.0, 0.0, 3.0, 100.0)]
    assert speeds == [speeds[0]] * 4 and speeds[0] > 0


def test_gusts_add_up():
    longitudinal = Gust(center=(-4.5, 6.0), direction=(1.0, 0.0, 0.0), gradient_distance=2.0,
                        reference_speed=3.0)
    point = [-4.2, 6.1, 0.0]
    total = gust_velocity([LATERAL, longitudinal], point)
    assert np.allclose(total, [longitudinal.speed(point), -LATERAL.speed(point), 0.0])
    assert np.array_equal(gust_velocity([], point), np.zeros(3))


def test_gust_validation():
    with pytest.raises(ValueError, match='direction'):
        Gust(center=(0, 0), direction=(1.0, 1.0, 0.0), gradient_distance=2.0,
             reference_speed=3.0)
    with pytest.raises(ValueError, match='gradient_distance'):
        Gust(center=(0, 0), direction=(1.0, 0.0, 0.0), gradient_distance=0.0,
             reference_speed=3.0)


def test_drag_is_quadratic_and_opposes_the_air_relative_velocity():
    velocity = np.array([1.0, -2.0, 0.5])
    drag = payload_drag(velocity, np.zeros(3), 0.12)
    assert np.allclose(drag, -0.12 * np.linalg.norm(velocity) * velocity)
    assert np.allclose(payload_drag(2 * velocity, np.zeros(3), 0.12), 4 * drag)
    # moving with the wind: no drag; hovering in a wind: pushed along the wind
    assert np.array_equal(payload_drag(velocity, velocity, 0.12), np.zeros(3))
    assert np.allclose(payload_drag(np.zeros(3), [0.0, -3.0, 0.0], 0.12), [0.0, -1.08, 0.0])
