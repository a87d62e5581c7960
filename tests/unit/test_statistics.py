"""The payload-swing statistic's rest place (`statistics.equilibrium_payload_position`: the
lowest point within reach of every cable) against an analytic case and an independent
constrained minimiser (scipy's SLSQP), for two to eight UAVs."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize

from multilift_sim.statistics import equilibrium_payload_position, payload_swing_at


def test_three_uavs_in_an_equilateral_triangle_hang_it_below_the_centroid():
    radius, length, height = 1.5, 2.5, 4.0
    uavs = [(radius * math.cos(a), radius * math.sin(a), height)
            for a in (0.3, 0.3 + 2 * math.pi / 3, 0.3 + 4 * math.pi / 3)]
    rest = equilibrium_payload_position(uavs, [length] * 3)
    assert rest == pytest.approx([0.0, 0.0, height - math.sqrt(length ** 2 - radius ** 2)],
                                 abs=1e-12)
    assert payload_swing_at(uavs, [0.3, -0.4, 1.0], [length] * 3) == pytest.approx(0.5)


def test_cables_that_cannot_meet_give_none():
    assert equilibrium_payload_position([(0, 0, 5), (10, 0, 5), (5, 8, 5)], [2, 2, 2]) is None


@pytest.mark.parametrize('seed', range(16))
def test_random_formations_agree_with_a_constrained_minimiser(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 9))
    uavs = np.column_stack([rng.uniform(-2, 2, (n, 2)), rng.uniform(3, 5, n)])
    centroid = uavs.mean(axis=0)
    # every ball holds the centroid, some only just: several cables bind at the optimum
    lengths = np.linalg.norm(uavs - centroid, axis=1) + rng.uniform(0.05, 2.0, n)
    rest = equilibrium_payload_position(uavs, lengths)
    constraints = [{'type': 'ineq', 'fun': lambda q, u=u, r=r: r * r - np.sum((q - u) ** 2),
                    'jac': lambda q, u=u: -2.0 * (q - u)} for u, r in zip(uavs, lengths)]
    best = None
    for start in (centroid, centroid - [0.0, 0.0, 0.5], centroid + rng.normal(0, 0.1, 3)):
        found = minimize(lambda q: q[2], start, jac=lambda q: np.array([0.0, 0.0, 1.0]),
                         constraints=constraints, method='SLSQP',
                         options={'ftol': 1e-12, 'maxiter': 500})
        feasible = np.all(np.linalg.norm(uavs - found.x, axis=1) <= lengths + 1e-7)
        if found.success and feasible and (best is None or found.x[2] < best[2]):
            best = found.x
    assert rest is not None and best is not None
    assert np.all(np.linalg.norm(uavs - rest, axis=1) <= lengths * (1 + 1e-9) + 1e-12)
    assert rest[2] == pytest.approx(best[2], abs=1e-6)
    assert rest == pytest.approx(best, abs=1e-4)   # the lowest point is unique
