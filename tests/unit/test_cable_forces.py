"""Cable-force allocation for any number of cables (issue 35 item 3, `formation.reorganize:
cable_forces`, multilift_control.laws.cable_forces) with a point payload: the shares against
the least largest thrust utilisation worked out apart, the places it picks against the statics
of Eq. 2.73 solved apart (the payload's hang and its rows' tensions, the triangle of forces'
law of cosines, two cables' balance of slopes), for n = 2, 3, 4, 5 and unequal airframes; the
keys' parse for any n; and formations of two flown to their end."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.controllers import formation_rows
from multilift_control.controllers.followers import thrust_margin
from multilift_control.headless import fly
from multilift_control.laws import cable_forces as allocation
from multilift_control.laws import reorganize as laws
from multilift_control.laws.layout import REORGANIZE_ALLOCATE, REORGANIZE_DEPTH
from multilift_sim import scenario as scenario_io
from multilift_sim.analysis.loads import hover_loads

G = 9.81
DOWN = np.array([0.0, 0.0, -1.0])
# unequal airframes (rotor limits [rad/s], masses [kg]) mild enough that no share is clipped
AIRFRAMES = {2: ('twin_lift', [{}, {'rotor_speed_max': 2040.0, 'mass': 2.4}]),
             3: ('multi_lift', [{}, {'rotor_speed_max': 2040.0}, {'mass': 2.45}]),
             4: ('v5', [{}, {'rotor_speed_max': 2040.0}, {'mass': 2.45},
                        {'rotor_speed_max': 2070.0, 'mass': 2.55}]),
             5: ('v5', [{}, {'rotor_speed_max': 2040.0}, {'mass': 2.45},
                        {'rotor_speed_max': 2070.0, 'mass': 2.55}, {'rotor_speed_max': 2060.0}])}


def _allocating(name, n=None, uavs=None, **formation):
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['formation'].update(reorganize='cable_forces', **formation)
    if n is not None:
        data['formation']['n'] = n
    if uavs is not None:
        data['uavs'] = uavs
    return scenario_io.loads(yaml.safe_dump(data))


def _allocated(scenario):
    """(shares, places the allocation wants from the geometry's places, constants)."""
    n = scenario.n_uavs
    constants, _, _, _ = thrust_margin.mode_arrays(scenario, 1, REORGANIZE_ALLOCATE)
    _, constraints = formation_rows(scenario)
    places = laws.target_places(constraints.rows, constraints.targets,
                                np.zeros(len(constraints.targets)), n)
    effective = np.array([0.0, 0.0, G])
    wanted, found = allocation.allocated_places(constants, effective, places)
    assert found
    return allocation.load_shares(constants, effective, n), wanted, constants


def _hang(scenario, places):
    """The payload's hang below level or tilted UAVs at `places` [m] (the lowest point every
    cable reaches) and the unit vectors up the cables (n, 3), every cable taut there."""
    lengths = np.array([u.cable_length for u in scenario.uavs])
    payload, found = laws.hang_point(places, lengths, DOWN)
    spans = places - payload
    assert found
    np.testing.assert_allclose(np.linalg.norm(spans, axis=1), lengths, rtol=1e-9)
    return payload, spans / lengths[:, None]


@pytest.mark.parametrize('n', [2, 3, 4, 5])
def test_the_shares_even_the_utilisation_and_the_places_carry_them(n):
    """The shares give every UAV the same thrust utilisation (m_i g + s_i m_p g) / u_T,max,i
    (no bound binds with these airframes); at the places allocated the payload, hanging where
    every cable reaches, is balanced by cables whose vertical pulls are the shares (Eq. 2.73's
    payload rows): with n <= 3 the rows' only tensions, solved here by least squares; with
    n >= 4 (indeterminate) the allocation's T_i = s_i W l_i / H meet the rows, and are what
    `allocated_statics` gives the followers."""
    name, uavs = AIRFRAMES[n]
    s = _allocating(name, n=n, uavs=uavs)
    shares, places, constants = _allocated(s)
    weight = s.payload.mass * G
    largest = np.array([u.vehicle.max_thrust for u in s.uavs])
    utilisation = (np.array([u.vehicle.mass for u in s.uavs]) * G + shares * weight) / largest
    assert shares.sum() == pytest.approx(1.0, abs=1e-12) and np.ptp(shares) > 0.05
    np.testing.assert_allclose(utilisation, utilisation.mean(), rtol=1e-9)
    payload, units = _hang(s, places)
    if n <= 3:
        tensions = np.linalg.lstsq(units.T, [0.0, 0.0, weight], rcond=None)[0]
    else:
        depth = constants[REORGANIZE_DEPTH]
        tensions = shares * weight * np.array([u.cable_length for u in s.uavs]) / depth
        np.testing.assert_allclose(places[:, 2], 0.0, atol=1e-12)  # level
        np.testing.assert_allclose(places[0, 2] - payload[2], depth, rtol=1e-9)
        assert min(np.linalg.norm(places[i, :2] - places[j, :2]) for i in range(n)
                   for j in range(i)) >= s.formation.min_spacing
    np.testing.assert_allclose(units.T @ tensions, [0.0, 0.0, weight], atol=1e-9)
    np.testing.assert_allclose(tensions * units[:, 2] / weight, shares, atol=1e-9)
    flown, _, found = allocation.allocated_statics(constants, places)
    assert found
    np.testing.assert_allclose(flown, tensions, rtol=1e-9)


def test_three_cables_make_the_triangle_of_forces_and_the_equilibrium_agrees():
    """n = 3: level cables of one length pull s_i along u_i, so the angle between u_1 and u_2
    is the triangle of forces' (law of cosines, cos = (s_3^2 - s_1^2 - s_2^2) / (2 s_1 s_2));
    started at those places, the formation's static equilibrium (analysis.equilibrium, Eq.
    2.73 solved for the whole formation) has cables whose vertical pulls are the shares."""
    name, uavs = AIRFRAMES[3]
    s = _allocating(name, uavs=uavs)
    shares, places, _ = _allocated(s)
    payload, units = _hang(s, places)
    u1, u2 = units[0, :2] / np.linalg.norm(units[0, :2]), units[1, :2] / np.linalg.norm(
        units[1, :2])
    assert u1 @ u2 == pytest.approx((shares[2] ** 2 - shares[0] ** 2 - shares[1] ** 2)
                                    / (2.0 * shares[0] * shares[1]), abs=1e-9)
    started = dataclasses.replace(s, formation=dataclasses.replace(
        s.formation, start_places=tuple(tuple(p[:2]) for p in places[1:])))
    loads = hover_loads(started)
    np.testing.assert_allclose(loads.tensions * units[:, 2] / (s.payload.mass * G), shares,
                               atol=1e-6)


def test_two_cables_share_by_their_slopes():
    """n = 2: level UAVs on cables of one length carry half each wherever they stand, so the
    follower keeps its line and spacing and changes height: the more loaded cable steeper and
    its UAV higher, s_1 r_1 / h_1 = s_2 r_2 / h_2 (r, h measured from the payload's hang);
    even airframes stay level (twin_lift's places)."""
    even = _allocating('twin_lift')
    shares, places, _ = _allocated(even)
    np.testing.assert_allclose(shares, 0.5, atol=1e-12)
    np.testing.assert_allclose(places[1], [-3.46, -2.0, 0.0], atol=1e-9)
    name, uavs = AIRFRAMES[2]
    s = _allocating(name, uavs=uavs)
    shares, places, _ = _allocated(s)
    payload, _ = _hang(s, places)
    radii = np.linalg.norm(places[:, :2] - payload[:2], axis=1)
    heights = places[:, 2] - payload[2]
    assert shares[0] > shares[1] and places[1, 2] < -0.05  # the follower carries less: lower
    assert shares[0] * radii[0] / heights[0] == pytest.approx(
        shares[1] * radii[1] / heights[1], rel=1e-9)
    np.testing.assert_allclose(places[1, :2], [-3.46, -2.0], atol=1e-9)  # line and spacing


def test_a_weak_uav_s_cable_keeps_the_least_tension():
    """v3_mixed's UAV 3 cannot reach the others' utilisation (its share would be negative):
    its cable keeps the least tension the allocation keeps, ALLOCATED_TENSION_SHARE of the even
    share m_p g / 3 (the bound is on the tension, not its vertical part; to
    allocation.ROUNDING_GUARD above it; the payload's rows solved here by least squares), UAVs
    1 and 2 share the rest at one utilisation; UAV 3 then carries less than at the places the
    thrust margins' gradient reaches at hover (the file's start_places, the statics of
    `multilift loads` there), where its cable keeps reorganize's LEAST_TENSION_SHARE."""
    s = _allocating('v3_mixed')
    shares, places, _ = _allocated(s)
    tensions, _ = np.linalg.lstsq(_hang(s, places)[1].T, [0.0, 0.0, 0.8 * G], rcond=None)[:2]
    least = allocation.ALLOCATED_TENSION_SHARE * 0.8 * G / 3.0
    assert tensions[2] == pytest.approx(least, rel=2e-6)
    assert tensions[2] >= least  # not below by a rounding
    largest = np.array([u.vehicle.max_thrust for u in s.uavs])
    assert (2.5 * G + shares[0] * 0.8 * G) / largest[0] == pytest.approx(
        (2.5 * G + shares[1] * 0.8 * G) / largest[1], rel=1e-12)
    gradient = hover_loads(scenario_io.load('v3_mixed'))
    assert gradient.tensions[2] == pytest.approx(laws.LEAST_TENSION_SHARE * 0.8 * G / 3.0,
                                                 rel=2e-3)
    assert tensions[2] < gradient.tensions[2] - 0.05


@pytest.mark.parametrize('acceleration', [(0.5, 0.0, 0.0), (0.0, -0.4, 0.3)])
def test_under_an_acceleration_the_cables_carry_the_shares_of_the_reference_s_wrench(
        acceleration):
    """Under g e_z + a the payload needs m_p (g e_z + a): the allocation tilts the formation
    as one body, the UAVs in the plane normal to g e_z + a, and the cables' pulls along it
    are the shares of m_p |g e_z + a| (the payload's hang along it and its rows' tensions
    solved here by least squares, three cables)."""
    s = _allocating('v3_mixed')
    constants, _, _, _ = thrust_margin.mode_arrays(s, 1, REORGANIZE_ALLOCATE)
    effective = np.array([0.0, 0.0, G]) + acceleration
    up = effective / np.linalg.norm(effective)
    start = np.vstack([[0.0, 0.0], s.formation.start_places])
    places, found = allocation.allocated_places(constants, effective,
                                                np.hstack([start, np.zeros((3, 1))]))
    shares = allocation.load_shares(constants, effective, 3)
    lengths = np.full(3, s.uavs[0].cable_length)
    payload, hangs = laws.hang_point(places, lengths, -up)
    spans = places - payload
    units = spans / np.linalg.norm(spans, axis=1)[:, None]
    load = s.payload.mass * effective
    tensions = np.linalg.solve(units.T, load)
    assert found and hangs and abs(places[1, 2]) > 0.05  # tilted: the followers' heights moved
    np.testing.assert_allclose(places @ up, 0.0, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(spans, axis=1), lengths, rtol=1e-9)
    np.testing.assert_allclose(tensions * (units @ up) / np.linalg.norm(load), shares, atol=1e-9)


@pytest.mark.parametrize('name, n', [('twin_lift', 2), ('v5', 5), ('v5', 4)])
def test_any_formation_of_two_or_more_takes_the_allocation(name, n):
    s = _allocating(name, n=n)
    assert s.control.follower == 'cable_forces' and s.n_uavs == n


def _flown(scenario, duration=None):
    if duration is not None:
        scenario = dataclasses.replace(
            scenario, simulation=dataclasses.replace(scenario.simulation, duration=duration))
    return fly(scenario).summary()['sim']


@pytest.mark.parametrize('uavs', [None, AIRFRAMES[2][1]])
def test_allocated_formations_of_two_fly_their_mission(uavs):
    """twin_lift, even and with a heavier, weaker follower (whose cable the allocation makes
    shallower, the follower lower, and flown there): the mission flown to its end, every cable
    pulling, the
    rotors saturated no longer than with the thrust margins' gradient nor the fixed geometry
    (the even pair's 0.10 UAV s at the start are the gradient's too: docs/loads.md)."""
    s = _allocating('twin_lift', uavs=uavs)
    summary = fly(s).summary()
    whole = summary['sim']
    # the follower flies the height allocated (its altitude loop's offset follows it): its
    # rows' error, z included, within 1 cm on average (the allocated height is 6 to 10 cm)
    assert summary['follower2']['mean_formation_error_norm'] < 0.01
    assert whole.get('error') is None and math.isfinite(whole['max_tension'])
    assert whole['min_tension'] > 0.0
    for other in ('thrust_margin', 'none'):
        compared = dataclasses.replace(s, formation=dataclasses.replace(
            s.formation, reorganize=other), control=dataclasses.replace(
                s.control, follower=other if other != 'none' else 'virtual_constraints'))
        assert sum(whole['saturated_time']) <= sum(_flown(compared)['saturated_time'])
