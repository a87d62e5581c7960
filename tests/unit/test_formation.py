"""Virtual-constraint formation control (seed §3.2, Eq. 3.1-3.13, Table 3.1), world frame."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from multilift_control.cascade import UavState
from multilift_control.formation import FormationFollower
from multilift_control.virtual_constraints import (FormationGeometry, VirtualConstraints,
                                                 virtual_forces)
from multilift_sim.frames import seed_to_world_vector
from multilift_sim.kinematics import rotation_matrix
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.scenario import ControlConfig

G = 9.81
ALPHA, BETA = 2.1, 1.3  # seed Table 4.2 alpha_vc, beta_vc


def _geometry(kind: str, n: int) -> FormationGeometry:
    if kind == 'linear':
        offsets = tuple((3.0 * k, 2.0 * (-1) ** k, 0.5 * k) for k in range(1, n))
        return FormationGeometry('linear', n, offsets=offsets)
    if kind == 'v':
        return FormationGeometry('v', n, distance=4.0, half_angle=math.radians(30))
    return FormationGeometry(kind, n, distance=4.0)


ALL = [('linear', 2), ('linear', 4), ('v', 3), ('v', 5), ('distance', 2), ('distance', 4),
       ('circle', 3), ('circle', 5)]


# --- geometry ---------------------------------------------------------------------------------

@pytest.mark.parametrize('kwargs, field', [
    (dict(kind='square', n=3, distance=1.0), 'kind'),
    (dict(kind='v', n=1, distance=1.0, half_angle=0.5), 'n'),
    (dict(kind='circle', n=2, distance=1.0), 'n'),
    (dict(kind='linear', n=3, offsets=((1.0, 0.0, 0.0),)), 'offsets'),
    (dict(kind='linear', n=2, offsets=((0.0, 0.0, 0.0),)), 'offsets'),
    (dict(kind='linear', n=2, offsets=((1.0, math.nan, 0.0),)), 'offsets'),
    (dict(kind='distance', n=2, distance=-1.0), 'distance'),
    (dict(kind='distance', n=2, distance=1.0, offsets=((1.0, 0.0, 0.0),)), 'offsets'),
    (dict(kind='v', n=3, distance=1.0, half_angle=math.pi / 2), 'half_angle'),
    (dict(kind='circle', n=3, distance=1.0, half_angle=0.2), 'half_angle'),
])
def test_geometry_rejects_bad_fields_by_name(kwargs, field):
    with pytest.raises(ValueError, match=f'FormationGeometry.{field}'):
        FormationGeometry(**kwargs)


def _seed_v(i: int, d: float, gamma: float) -> np.ndarray:
    """v_1i as printed in seed §3.2.1 (z-down frame)."""
    if i % 2 == 0:
        return i / 2 * np.array([-d * math.cos(gamma), -d * math.sin(gamma), 0.0])
    return (i - 1) / 2 * np.array([-d * math.cos(gamma), d * math.sin(gamma), 0.0])


@pytest.mark.parametrize('n', [2, 3, 4, 5, 6])
def test_v_rows_are_eq_3_6_and_3_7(n):
    d, gamma = 4.0, math.radians(30)
    c = VirtualConstraints(FormationGeometry('v', n, distance=d, half_angle=gamma))
    # Eq. 3.7: block row i-1 is [I, 0, .., -I (block i), .., 0]
    blocks = np.hstack([np.ones((n - 1, 1)), -np.eye(n - 1)])
    j = c.jacobian(np.random.default_rng(n).normal(size=(n, 3)))
    assert np.array_equal(j, np.kron(blocks, np.eye(3)))
    v_c = np.concatenate([seed_to_world_vector(_seed_v(i, d, gamma)) for i in range(2, n + 1)])
    assert np.allclose(c.v_c, v_c)
    r = np.random.default_rng(1).normal(size=(n, 3))
    assert np.allclose(c.residual(r), j @ r.reshape(-1) + c.v_c)  # g_vc = J_vc r_f + v_c
    leader = np.array([1.0, -2.0, 3.0])
    pos = c.nominal_positions(leader)
    assert np.allclose(c.residual(pos), 0)
    assert np.allclose(pos[:, 2], leader[2])
    for i in range(2, n + 1):
        rel = pos[i - 1] - leader
        arm = i // 2                                   # how far down its arm of the V
        assert np.linalg.norm(rel) == pytest.approx(arm * d)
        side = 1.0 if i % 2 == 0 else -1.0             # world: even on +y, odd on -y
        assert np.allclose(rel, arm * d * np.array([-math.cos(gamma), side * math.sin(gamma),
                                                    0.0]))
        if i + 2 <= n:                                 # consecutive UAVs on one arm: d apart
            assert np.linalg.norm(pos[i + 1] - pos[i - 1]) == pytest.approx(d)


def test_v_of_three_at_30_degrees_is_equilateral():
    c = VirtualConstraints(FormationGeometry('v', 3, distance=4.0, half_angle=math.radians(30)))
    pos = c.nominal_positions(np.zeros(3))
    assert np.linalg.norm(pos[1] - pos[0]) == pytest.approx(4.0)
    assert np.linalg.norm(pos[2] - pos[0]) == pytest.approx(4.0)
    assert np.linalg.norm(pos[2] - pos[1]) == pytest.approx(4.0)
    assert pos[1, 0] < 0 and pos[2, 0] < 0 and pos[1, 1] > 0 > pos[2, 1]


def test_circle_of_three_is_table_3_1():
    c = VirtualConstraints(FormationGeometry('circle', 3, distance=4.0))
    assert c.pairs.tolist() == [[0, 1], [0, 2], [1, 2]]
    r = np.random.default_rng(3).normal(size=(3, 3))
    expected = [np.sum((r[a] - r[b]) ** 2) - 16.0 for a, b in ((0, 1), (0, 2), (1, 2))]
    assert np.allclose(c.residual(r), expected)


@pytest.mark.parametrize('n', [3, 4, 5, 6])
def test_circle_nominal_is_a_regular_polygon_with_the_leader_a_vertex(n):
    d = 4.0
    c = VirtualConstraints(FormationGeometry('circle', n, distance=d))
    assert c.m == 2 * n - 3
    leader = np.array([2.0, 1.0, 5.0])
    pos = c.nominal_positions(leader)
    assert np.allclose(pos[0], leader)
    assert np.allclose(c.residual(pos), 0)
    sides = [np.linalg.norm(pos[k] - pos[(k + 1) % n]) for k in range(n)]
    assert np.allclose(sides, d)
    centre = pos.mean(axis=0)
    assert np.allclose(np.linalg.norm(pos - centre, axis=1), d / (2 * math.sin(math.pi / n)))
    assert np.allclose(pos[:, 2], leader[2])


@pytest.mark.parametrize('n', [2, 3, 5])
def test_distance_nominal_spreads_followers_behind(n):
    c = VirtualConstraints(FormationGeometry('distance', n, distance=4.0))
    pos = c.nominal_positions(np.array([0.0, 0.0, 2.0]))
    assert np.allclose(c.residual(pos), 0)
    assert np.all(pos[1:, 0] < 0) and np.allclose(pos[:, 2], 2.0)
    assert len({tuple(np.round(p, 9)) for p in pos}) == n


@pytest.mark.parametrize('kind, n', [('linear', 3), ('v', 4), ('distance', 3), ('circle', 4)])
def test_rows_of(kind, n):
    c = VirtualConstraints(_geometry(kind, n))
    j = c.jacobian(np.random.default_rng(0).normal(size=(n, 3)))
    for i in range(n):
        involved = [k for k in range(c.m) if np.any(j[k, 3 * i:3 * i + 3] != 0)]
        assert c.rows_of(i) == involved


# --- derivatives ------------------------------------------------------------------------------

@pytest.mark.parametrize('kind, n', ALL)
def test_jacobian_and_rate_product_match_finite_differences(kind, n):
    c = VirtualConstraints(_geometry(kind, n))
    rng = np.random.default_rng(7)
    r = c.nominal_positions(np.zeros(3)) + rng.normal(scale=0.5, size=(n, 3))
    v = rng.normal(size=(n, 3))
    h = 1e-6
    fd = np.empty((c.m, 3 * n))
    for k in range(3 * n):
        dr = np.zeros(3 * n)
        dr[k] = h
        fd[:, k] = (c.residual(r + dr.reshape(n, 3)) - c.residual(r - dr.reshape(n, 3))) / (2 * h)
    assert np.allclose(c.jacobian(r), fd, atol=1e-6)
    # d/dt (J(r + v t)) v at t = 0
    fd_dot = (c.jacobian(r + h * v) - c.jacobian(r - h * v)) @ v.reshape(-1) / (2 * h)
    assert np.allclose(c.jacobian_rate_product(r, v), fd_dot, atol=1e-6)
    # second time derivative of g along a constant-velocity path is J_dot r_dot
    g2 = (c.residual(r + h * 1e2 * v) - 2 * c.residual(r) + c.residual(r - h * 1e2 * v)) \
        / (h * 1e2) ** 2
    assert np.allclose(c.jacobian_rate_product(r, v), g2, atol=1e-4)


# --- virtual forces (Eq. 3.8-3.12) ------------------------------------------------------------

@pytest.mark.parametrize('kind, n', ALL)
def test_multipliers_solve_eq_3_11(kind, n):
    c = VirtualConstraints(_geometry(kind, n))
    rng = np.random.default_rng(11)
    r = c.nominal_positions(np.zeros(3)) + rng.normal(scale=0.3, size=(n, 3))
    v = rng.normal(scale=0.5, size=(n, 3))
    masses = rng.uniform(2.0, 4.0, size=n)
    u = masses[:, None] * G * np.array([0, 0, 1.0]) + rng.normal(size=(n, 3))
    u_vf, lam = virtual_forces(c, r, v, u, masses, G, ALPHA, BETA)
    assert lam.shape == (c.m,) and u_vf.shape == (n, 3)
    j = c.jacobian(r)
    assert np.allclose(u_vf.reshape(-1), -j.T @ lam)
    f = masses[:, None] * G * np.array([0, 0, 1.0])
    accel = ((u - f).reshape(-1) + u_vf.reshape(-1)) / np.repeat(masses, 3)   # Eq. 3.9
    closed = (j @ accel + c.jacobian_rate_product(r, v) + 2 * ALPHA * j @ v.reshape(-1)
              + BETA ** 2 * c.residual(r))
    assert np.allclose(closed, 0, atol=1e-9)
    assert np.linalg.norm(lam) > 1e-3  # the check above is not trivially met


def test_singular_rows_fall_back_to_least_squares():
    c = VirtualConstraints(FormationGeometry('distance', 3, distance=2.0))
    r = np.array([[0.0, 0, 0], [0.0, 0, 0], [-2.0, 0, 0]])  # follower 2 on the leader
    masses = np.full(3, 3.0)
    u = masses[:, None] * G * np.array([0, 0, 1.0])
    u_vf, lam = virtual_forces(c, r, np.zeros((3, 3)), u, masses, G, ALPHA, BETA)
    assert np.all(np.isfinite(u_vf)) and np.all(np.isfinite(lam))
    assert np.allclose(u_vf[1], 0)  # no gradient of row 1: it cannot push UAV 2


def _row_response(g0: np.ndarray, gdot0: np.ndarray, t: float, alpha: float,
                  beta: float) -> np.ndarray:
    """g(t) of g_ddot + 2 alpha g_dot + beta^2 g = 0 (Eq. 3.8), row by row."""
    phi = expm(np.array([[0.0, 1.0], [-beta ** 2, -2 * alpha]]) * t)
    return phi[0, 0] * g0 + phi[0, 1] * gdot0


@pytest.mark.parametrize('alpha, beta', [(ALPHA, BETA), (1.0, 2.0)])
@pytest.mark.parametrize('kind, n', ALL)
def test_point_masses_converge_at_the_rate_of_alpha_beta(kind, n, alpha, beta):
    c = VirtualConstraints(_geometry(kind, n))
    rng = np.random.default_rng(5)
    masses = rng.uniform(2.0, 4.0, size=n)
    accel = np.array([0.3, -0.2, 0.1])                       # the leader's nominal acceleration
    u = masses[:, None] * (accel + G * np.array([0, 0, 1.0]))  # thrust with no gravity mismatch
    r = c.nominal_positions(np.array([0.0, 0.0, 5.0])) + rng.normal(scale=0.3, size=(n, 3))
    v = np.array([0.5, 0.0, 0.0]) + rng.normal(scale=0.3, size=(n, 3))

    def deriv(x):
        pos, vel = x[:n], x[n:]
        u_vf, _ = virtual_forces(c, pos, vel, u, masses, G, alpha, beta)
        acc = (u + u_vf) / masses[:, None] - G * np.array([0, 0, 1.0])
        return np.vstack([vel, acc])

    g0, gdot0 = c.residual(r), c.rate(r, v)
    x, dt, steps = np.vstack([r, v]), 4e-3, 1000
    for k in range(1, steps + 1):                           # RK4
        k1 = deriv(x)
        k2 = deriv(x + dt / 2 * k1)
        k3 = deriv(x + dt / 2 * k2)
        k4 = deriv(x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if k % 250 == 0:
            expected = _row_response(g0, gdot0, k * dt, alpha, beta)
            assert np.allclose(c.residual(x[:n]), expected, atol=1e-7 * np.abs(g0).max())
    assert np.abs(c.residual(x[:n])).max() < 0.5 * np.abs(g0).max()


# --- the follower controller ------------------------------------------------------------------

VEHICLE = MultirotorParams(mass=2.5, inertia=(0.957, 0.486, 0.355), frame_type='quad_x',
                           arm_length=0.2, thrust_coefficient=1.83e-6,
                           moment_coefficient=1.85e-7, rotor_speed_min=0.0,
                           rotor_speed_max=3000.0)   # seed Table 4.2 but 2100 rad/s: margin to
# turn without saturating while the attitude sits far from its setpoint (states are frozen)
GAINS = ControlConfig(mode='cascade', constant_rotor_speed=None, position_kp=(1.0, 1.0, 2.0),
                      position_kd=(1.8, 1.8, 2.6), position_ki=(0.15, 0.15, 0.4),
                      attitude_kp=(16.0, 16.0, 9.0), attitude_kd=(7.0, 7.0, 5.0),
                      max_tilt=math.radians(25))
TWIN = FormationGeometry('linear', 2, offsets=((3.46, 2.0, 0.0),))  # seed §4.3, world
V3 = FormationGeometry('v', 3, distance=4.0, half_angle=math.radians(30))


def _followers(geometry, **options):
    c = VirtualConstraints(geometry)
    masses = np.full(geometry.n, VEHICLE.mass + 0.8 / geometry.n)
    return c, masses, [FormationFollower(VEHICLE, i, c, masses, GAINS, masses[i], G, ALPHA, BETA,
                                         **options) for i in range(1, geometry.n)]


def _state(position, velocity, yaw=0.0):
    return UavState(np.asarray(position, float), np.asarray(velocity, float),
                    np.array([0.0, 0.0, yaw]), np.zeros(3))


@pytest.mark.parametrize('own_thrust', ['commanded', 'measured'])
@pytest.mark.parametrize('geometry', [TWIN, V3], ids=['twin', 'v3'])
def test_follower_iteration_converges_to_the_follower_only_solution(geometry, own_thrust):
    c, masses, followers = _followers(geometry, own_thrust=own_thrust, free_mode_gain=1.0)
    n = geometry.n
    rng = np.random.default_rng(2)
    r = c.nominal_positions(np.array([1.0, 2.0, 3.0]))
    r[1:, :2] += rng.normal(scale=0.3, size=(n - 1, 2))          # off their places, same height
    v = np.tile([0.5, -0.1, 0.2], (n, 1))
    v[1:, :2] += rng.normal(scale=0.1, size=(n - 1, 2))
    states = [_state(r[k], v[k], yaw=0.4 * k) for k in range(n)]
    a_leader = np.array([0.3, -0.2, 0.0])
    u = masses[:, None] * G * np.array([0, 0, 1.0])
    u[0] = masses[0] * (a_leader + G * np.array([0, 0, 1.0]))    # the leader's thrust, unaltered
    for tick in range(200):
        forces = [f.desired_force(0.01 * tick, states, u)[0] for f in followers]
        outs = [f.update(0.01 * tick, states, u) for f in followers]   # all on the same u
        lifts = []
        for f, force, (out, errors, rates) in zip(followers, forces, outs):
            # Eq. 3.13: the setpoint and thrust point the lift along the requested force
            lift = rotation_matrix(out.attitude_setpoint) @ np.array([0, 0, out.thrust])
            assert np.allclose(lift, force, atol=1e-9)
            assert out.attitude_setpoint[2] == pytest.approx(0.4 * f.index)  # yaw held
            assert np.allclose(errors, c.residual(r)[c.rows_of(f.index)])
            assert np.allclose(rates, c.rate(r, v)[c.rows_of(f.index)])
            # the lift the rotors give after saturation, as the simulator would measure it
            thrust = VEHICLE.thrust_coefficient * np.sum(out.rotor_speeds ** 2)
            assert np.allclose(f.lift, lift / out.thrust * thrust)
            lifts.append(f.lift)
        for f, lift in zip(followers, lifts):                   # a follower's next u_i
            u[f.index] = lift
    g, gdot = c.residual(r).reshape(n - 1, 3), c.rate(r, v).reshape(n - 1, 3)
    assert not any(out.saturated.any() for out, _, _ in outs)
    for i in range(1, n):
        a_i = u[i] / masses[i] - G * np.array([0, 0, 1.0])
        expected = a_leader + 2 * ALPHA * gdot[i - 1] + BETA ** 2 * g[i - 1]
        assert np.allclose(a_i[:2], expected[:2], atol=1e-8)
        # same height: the altitude loop damps the follower's own climb rate (seed §4.3)
        assert a_i[2] == pytest.approx(-GAINS.position_kd[2] * v[i, 2], abs=1e-9)
        assert np.linalg.norm(expected[:2] - a_leader[:2]) > 0.1  # not a trivial fixed point
    _, lam = virtual_forces(c, r, v, u, masses, G, ALPHA, BETA)
    lam = lam.reshape(n - 1, 3)
    assert np.allclose(lam[:, :2], 0, atol=1e-7)                # Lambda_i = 0 (x, y rows)


def test_follower_altitude_loop_tracks_the_leader_height():
    c, masses, (follower,) = _followers(TWIN)
    r = c.nominal_positions(np.array([0.0, 0.0, 3.0]))
    r[1, 2] = 2.5                                                # 0.5 m below the leader
    # the leader climbs at 0.2 m/s, the follower at 0.1 m/s: z_1 is a reference the outer loop
    # updates, so the damping acts on the follower's own climb rate only (seed §4.3)
    states = [_state(r[0], [0, 0, 0.2]), _state(r[1], [0, 0, 0.1])]
    u = masses[:, None] * G * np.array([0, 0, 1.0])
    force, _, _ = follower.desired_force(0.0, states, u)
    expected = masses[1] * (G + GAINS.position_kp[2] * 0.5 - GAINS.position_kd[2] * 0.1)
    assert force[2] == pytest.approx(expected)
    force, _, _ = follower.desired_force(1.0, states, u)         # one second of integral
    assert force[2] == pytest.approx(expected + masses[1] * GAINS.position_ki[2] * 0.5)
    for tick in range(2, 400):                                   # the integral is clamped
        force, _, _ = follower.desired_force(float(tick), states, u)
    assert force[2] == pytest.approx(expected + masses[1] * 0.5 * G)


def test_follower_rejects_the_leader_index():
    c, masses, _ = _followers(TWIN)
    with pytest.raises(ValueError, match='follower index'):
        FormationFollower(VEHICLE, 0, c, masses, GAINS, masses[0], G, ALPHA, BETA)


def _scenario(formation, n, cable_length=10.26):
    from types import SimpleNamespace as NS
    uavs = tuple(NS(vehicle=VEHICLE, position=(1.0, 2.0, 3.0), cable_length=cable_length,
                    attach_point=(0.0, 0.0, 0.0), yaw=0.0)
                 for _ in range(n))
    return NS(n_uavs=n, uavs=uavs, payload=NS(mass=0.9, attach_points=None), control=GAINS,
              simulation=NS(gravity=G), formation=formation)


def test_follower_from_scenario_uses_the_formation_section():
    from types import SimpleNamespace as NS
    v = NS(geometry='v', offsets=(), distance=4.0, half_angle=math.radians(30), alpha_vc=ALPHA,
           beta_vc=BETA)
    follower = FormationFollower.from_scenario(_scenario(v, 3), 2)
    assert follower.constraints.geometry == V3
    assert np.allclose(follower.masses, VEHICLE.mass + 0.3)
    assert follower.hover_mass == pytest.approx(VEHICLE.mass + 0.3)
    assert follower.rows == [3, 4, 5] and (follower.alpha_vc, follower.beta_vc) == (ALPHA, BETA)
    assert follower.free_mode_gain == pytest.approx(2 * ALPHA)
    assert follower.altitude_offset == pytest.approx(0.0)   # equilateral: all at one height
    # a V of five on equal cables: the payload under the centroid puts UAVs 2, 3 higher and
    # 4, 5 lower than the leader; each follower holds its start height relative to z_1
    v5 = FormationGeometry('v', 5, distance=4.0, half_angle=math.radians(30))
    places = VirtualConstraints(v5).nominal_positions(np.zeros(3))
    centre = places[:, :2].mean(axis=0)
    drops = np.sqrt(10.26 ** 2 - np.sum((places[:, :2] - centre) ** 2, axis=1))
    for i in range(1, 5):
        f = FormationFollower.from_scenario(_scenario(v, 5), i)
        assert f.altitude_offset == pytest.approx(drops[i] - drops[0])
    assert drops[1] - drops[0] > 0.5 and drops[3] - drops[0] < -0.3
    f = FormationFollower.from_scenario(_scenario(v, 5), 1, altitude_offset=0.0,
                                        free_mode_gain=None)
    assert f.altitude_offset == 0.0 and f.free_mode_gain is None


@pytest.mark.parametrize('kind, n, count', [('linear', 3, 0), ('v', 5, 0), ('circle', 3, 1),
                                            ('circle', 5, 1), ('distance', 3, 2)])
def test_free_follower_motions(kind, n, count):
    c = VirtualConstraints(_geometry(kind, n))
    r = c.nominal_positions(np.array([1.0, -1.0, 2.0]))
    basis = c.free_follower_motions(r)
    assert basis.shape == (2 * (n - 1), count)
    assert np.allclose(basis.T @ basis, np.eye(count))
    motion = np.zeros((count, n, 3))
    motion[:, 1:, :2] = basis.T.reshape(count, n - 1, 2)
    assert np.allclose(motion.reshape(count, 3 * n) @ c.jacobian(r).T, 0, atol=1e-12)
    if kind == 'circle':  # the polygon's rotation about the leader
        rel = r[1:, :2] - r[0, :2]
        spin = np.column_stack([-rel[:, 1], rel[:, 0]]).reshape(-1)
        assert abs(basis[:, 0] @ spin) == pytest.approx(np.linalg.norm(spin))


def _turn(kind, n, free_mode_gain):
    """Point masses (ideal attitude) behind a leader that turns from +x to -y at t = 5..6 s;
    returns (max |g_vc| after the turn, largest follower velocity along the free motions)."""
    c, masses, followers = _followers(_geometry(kind, n), free_mode_gain=free_mode_gain)
    r = c.nominal_positions(np.array([0.0, 0.0, 3.0]))
    v = np.tile([0.5, 0.0, 0.0], (n, 1))
    ez = np.array([0.0, 0.0, 1.0])
    u = masses[:, None] * G * ez
    dt, worst, free = 0.01, 0.0, 0.0
    for k in range(1500):
        t = k * dt
        accel = np.array([-0.5, -0.5, 0.0]) if 5.0 <= t < 6.0 else np.zeros(3)
        u[0] = masses[0] * (accel + G * ez)
        states = [_state(r[j], v[j]) for j in range(n)]
        forces = [f.desired_force(t, states, u)[0] for f in followers]
        for f, force in zip(followers, forces):
            u[f.index] = force
        v = v + dt * (u / masses[:, None] - G * ez)
        r = r + dt * v
        if t > 7.0:
            worst = max(worst, np.abs(c.residual(r)).max())
            basis = c.free_follower_motions(r)
            along = basis.T @ (v[1:, :2] - v[0, :2]).reshape(-1)
            free = max(free, np.abs(along).max(initial=0.0))
    return worst, free


@pytest.mark.parametrize('kind, n', [('circle', 3), ('distance', 3)])
def test_free_motions_drift_without_the_damping_and_not_with_it(kind, n):
    worst, free = _turn(kind, n, None)
    assert free > 0.3                                   # the formation turns about the leader
    worst, free = _turn(kind, n, 2 * ALPHA)
    assert free < 1e-6 and worst < 0.05                 # it follows the leader round the turn


@pytest.mark.parametrize('kind, n', [('linear', 2), ('v', 3)])
def test_free_mode_damping_leaves_linear_rows_alone(kind, n):
    assert _turn(kind, n, None) == pytest.approx(_turn(kind, n, 2 * ALPHA), abs=1e-12)


@pytest.mark.parametrize('own_thrust', ['commanded', 'measured'])
def test_own_thrust_source(own_thrust):
    c, masses, (follower,) = _followers(TWIN, own_thrust=own_thrust)
    r = c.nominal_positions(np.array([0.0, 0.0, 3.0])) + [[0, 0, 0], [0.3, -0.2, 0]]
    states = [_state(r[0], np.zeros(3)), _state(r[1], np.zeros(3))]
    u = masses[:, None] * G * np.array([0, 0, 1.0])
    follower.update(0.0, states, u)
    other = u.copy()
    other[1, :2] += [1.0, -0.5]        # what a lagging attitude would report
    first, _, _ = follower.desired_force(0.01, states, u)
    second, _, _ = follower.desired_force(0.01, states, other)
    if own_thrust == 'commanded':       # its own last lift, whatever the caller measured
        assert np.allclose(first, second)
    else:
        assert not np.allclose(first, second)


def test_linear_dz_offset_sets_the_follower_height():
    geometry = FormationGeometry('linear', 2, offsets=((3.0, 2.0, 0.5),))
    _, _, (follower,) = _followers(geometry)
    assert follower.altitude_offset == pytest.approx(-0.5)   # r_2 = r_1 - offset
