"""Formation DAE for n >= 1: the structured solve (multilift_sim.physics.formation_dae, every
cable or only the taut ones) against the dense Lagrange-multiplier system of seed Eq. 2.59
formed here with numpy (the oracle), RK4, parameter validation, and a three-UAV formation's
invariants."""
import math

import numpy as np
import pytest

from multilift_sim.constraints import (cable_residual_rates, cable_residuals,
                                       constraint_jacobian, constraint_jacobian_rate_term)
from multilift_sim.wind.gusts import Gust, gust_velocity, payload_drag
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams, StateLayout
from multilift_sim.analysis.coordinates import coordinate_accelerations
from multilift_sim.kinematics import euler_rate_matrix, quaternion_from_euler, rotation_matrix
from multilift_sim.multirotor import MultirotorParams, euler_mass_matrix, euler_velocity_term
from multilift_sim.slack import SlackCableModel

GRAVITY = 9.81


def vehicle(frame_type: str = 'quad_x', mass: float = 2.5) -> MultirotorParams:
    return MultirotorParams(mass=mass, inertia=(0.957, 0.486, 0.355), frame_type=frame_type,
                            arm_length=0.2, thrust_coefficient=1.83e-6,
                            moment_coefficient=1.85e-7, rotor_speed_min=0.0,
                            rotor_speed_max=2100.0)


def params(uav_list, lengths, **overrides) -> FormationParams:
    values = dict(uavs=tuple(uav_list), cable_lengths=tuple(lengths), payload_mass=0.8,
                  payload_drag_coefficient=0.0, baumgarte_alpha=20.0, baumgarte_beta=20.0,
                  gravity=GRAVITY)
    values.update(overrides)
    return FormationParams(**values)


def dense_reference(formation: FormationModel, x: np.ndarray, rotor_speeds, taut=None):
    """q_ddot and Lambda from the full (7n+3)-square system of seed Eq. 2.59, assembled from
    the seed's matrices (Eq. 2.47-2.52) with dense numpy algebra; with `taut` (n,) bool only
    those cables' rows (the others' Lambda 0)."""
    p = formation.params
    layout = formation.layout
    n = p.n_uavs
    q, q_dot = seed_coordinates(layout, x)
    size = q.size
    mass = np.zeros((size, size))
    force = np.zeros(size)            # f_f = B_f u_f + d_f - f_g - C_f q_dot
    for i, uav in enumerate(p.uavs):
        eta, eta_dot = q[6 * i + 3:6 * i + 6], q_dot[6 * i + 3:6 * i + 6]
        wrench = uav.allocator().wrench(rotor_speeds[i])
        mass[6 * i:6 * i + 3, 6 * i:6 * i + 3] = uav.mass * np.eye(3)
        mass[6 * i + 3:6 * i + 6, 6 * i + 3:6 * i + 6] = euler_mass_matrix(uav.inertia, eta)
        force[6 * i:6 * i + 3] = (rotation_matrix(eta)[:, 2] * wrench[0]
                                  - uav.mass * p.gravity * np.array([0, 0, 1.0]))
        force[6 * i + 3:6 * i + 6] = (euler_rate_matrix(eta).T @ wrench[1:]
                                      - euler_velocity_term(uav.inertia, eta, eta_dot))
    payload_position, payload_velocity = q[6 * n:], q_dot[6 * n:]
    mass[6 * n:, 6 * n:] = p.payload_mass * np.eye(3)
    air = gust_velocity(p.gusts, payload_position)
    force[6 * n:] = (payload_drag(payload_velocity, air, p.payload_drag_coefficient)
                     - p.payload_mass * p.gravity * np.array([0, 0, 1.0]))
    positions = layout.uav_positions(x)
    velocities = layout.uav_velocities(x)
    jacobian = constraint_jacobian(positions, payload_position)
    g = cable_residuals(positions, payload_position, p.cable_lengths)
    g_dot = cable_residual_rates(positions, velocities, payload_position, payload_velocity)
    taut = np.ones(n, bool) if taut is None else np.asarray(taut)
    rows, m = jacobian[taut], int(taut.sum())
    kkt = np.block([[mass, rows.T], [rows, np.zeros((m, m))]])
    rhs = np.concatenate((force, (-constraint_jacobian_rate_term(velocities, payload_velocity)
                                  - 2 * p.baumgarte_alpha * g_dot
                                  - p.baumgarte_beta ** 2 * g)[taut]))
    solution = np.linalg.solve(kkt, rhs)
    multipliers = np.zeros(n)
    multipliers[taut] = solution[size:]
    return solution[:size], multipliers


def seed_coordinates(layout: StateLayout, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The seed's q_f = (r_i, eta_i, ..., r_p) (6n + 3) and q_f_dot of a state: eta_i the ZYX
    angles of UAV i's quaternion, eta_dot_i = W(eta_i)^-1 omega_i (Eq. 2.7)."""
    n = layout.n_uavs
    euler = layout.uav_euler(x)
    rates = np.array([np.linalg.solve(euler_rate_matrix(euler[i]), layout.uav_body_rates(x)[i])
                      for i in range(n)])
    q = np.concatenate((np.hstack((layout.uav_positions(x), euler)).ravel(),
                        layout.payload_position(x)))
    q_dot = np.concatenate((np.hstack((layout.uav_velocities(x), rates)).ravel(),
                            layout.payload_velocity(x)))
    return q, q_dot


def random_state(layout: StateLayout, lengths, rng) -> np.ndarray:
    """A state near (not on) the constraint manifold, with random rates."""
    n = layout.n_uavs
    payload = rng.normal(size=3)
    directions = rng.normal(size=(n, 3)) + [0.0, 0.0, 3.0]
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    positions = payload + (np.asarray(lengths) * (1 + 0.01 * rng.normal(size=n)))[:, None] \
        * directions
    return layout.pack(positions, rng.uniform(-0.6, 0.6, (n, 3)), payload,
                       rng.normal(size=(n, 3)), rng.normal(size=(n, 3)), rng.normal(size=3))


@pytest.mark.parametrize('n, kernel', [(1, 'jit'), (2, 'jit'), (3, 'jit'), (25, 'jit'),
                                       (3, 'python')])
def test_structured_solve_matches_the_dense_seed_system(n, kernel, monkeypatch):
    monkeypatch.setenv('MULTILIFT_KERNEL', kernel)
    rng = np.random.default_rng(n)
    frames = ['quad_x', 'hexa_plus', 'octo_x', 'quad_plus']
    uavs = [vehicle(frames[i % 4] if n == 2 else 'quad_x', mass=2.0 + 0.2 * i) for i in range(n)]
    lengths = rng.uniform(1.5, 3.0, n)
    gusts = (Gust(center=(0.0, 0.0), direction=(0.0, 0.6, 0.8), gradient_distance=8.0,
                  reference_speed=3.0),)
    formation = FormationModel(params(uavs, lengths, payload_drag_coefficient=0.12,
                                      gusts=gusts, baumgarte_alpha=7.0, baumgarte_beta=5.0))
    x = random_state(formation.layout, lengths, rng)
    speeds = [rng.uniform(1200.0, 2000.0, uav.n_rotors) for uav in uavs]
    acc, multipliers = formation.accelerations(0.0, x, speeds)
    q_ddot = coordinate_accelerations(formation.layout, x, acc)
    expected_q_ddot, expected_multipliers = dense_reference(formation, x, speeds)
    assert np.allclose(q_ddot, expected_q_ddot, rtol=1e-9, atol=1e-9)
    assert np.allclose(multipliers, expected_multipliers, rtol=1e-9, atol=1e-9)
    assert np.allclose(formation.cable_tension(0.0, x, speeds), 2 * lengths * multipliers)
    assert np.any(np.abs(expected_multipliers) > 1.0)  # a solve with tensions to match


@pytest.mark.parametrize('n', [2, 3, 7])
def test_a_solve_over_the_taut_cables_matches_the_dense_seed_system_of_those(n):
    """The one solve with slack cables (SlackCableModel): multiplier 0 and no constraint row
    for a slack cable, the Woodbury sum over the taut ones only (none taut: free bodies)."""
    rng = np.random.default_rng(40 + n)
    uavs = [vehicle(mass=2.0 + 0.3 * i) for i in range(n)]
    lengths = rng.uniform(1.5, 3.0, n)
    model = SlackCableModel(params(uavs, lengths, payload_drag_coefficient=0.12,
                                   baumgarte_alpha=7.0, baumgarte_beta=5.0))
    x = random_state(model.layout, lengths, rng)
    speeds = [rng.uniform(1200.0, 2000.0, 4) for _ in range(n)]
    for taut in (rng.uniform(size=n) < 0.5, np.zeros(n, bool), np.ones(n, bool)):
        model.taut = taut
        acc, multipliers = model.accelerations(0.0, x, speeds)
        q_ddot = coordinate_accelerations(model.layout, x, acc)
        expected_q_ddot, expected_multipliers = dense_reference(model, x, speeds, taut)
        scale = max(1.0, np.abs(expected_q_ddot).max())
        assert np.allclose(q_ddot, expected_q_ddot, rtol=1e-9, atol=1e-9 * scale)
        assert np.allclose(multipliers, expected_multipliers, rtol=1e-9, atol=1e-9)
        assert np.all(multipliers[~taut] == 0.0)


@pytest.mark.parametrize('kernel', ['jit', 'python'])
def test_step_is_classic_rk4(kernel, monkeypatch):
    monkeypatch.setenv('MULTILIFT_KERNEL', kernel)
    n = 2
    rng = np.random.default_rng(10 + n)
    lengths = rng.uniform(1.5, 3.0, n)
    formation = FormationModel(params([vehicle()] * n, lengths))
    x = random_state(formation.layout, lengths, rng)
    speeds = [rng.uniform(1500.0, 2000.0, 4) for _ in range(n)]
    dt = 0.01

    def f(state):
        return formation.derivative(0.0, state, speeds)

    k1 = f(x)
    k2 = f(x + dt / 2 * k1)
    k3 = f(x + dt / 2 * k2)
    k4 = f(x + dt * k3)
    expected = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    quaternions = formation.layout.uav_quaternions(expected)   # each back to unit length
    quaternions /= np.linalg.norm(quaternions, axis=-1, keepdims=True)
    assert np.allclose(formation.step(0.0, x, speeds, dt), expected, rtol=1e-12, atol=1e-12)


def test_state_layout_views():
    layout = StateLayout(2)
    assert (layout.n_coordinates, layout.size) == (9, 18 + 14)
    x = layout.pack([[1, 2, 3], [4, 5, 6]], [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]], [7, 8, 9],
                    payload_velocity=[-1, -2, -3])
    assert np.array_equal(x[:9], [1, 2, 3, 4, 5, 6, 7, 8, 9])
    assert np.array_equal(layout.payload_velocity(x), [-1, -2, -3])
    assert np.array_equal(x[18:22], quaternion_from_euler([0.1, 0.2, 0.3])[[3, 0, 1, 2]])
    assert np.allclose(layout.uav_euler(x), [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]], atol=1e-15)
    layout.uav_body_rates(x)[1, 2] = 5.0             # views write through
    assert x[18 + 7 + 4 + 2] == 5.0
    assert layout.uav_positions(x).shape == (2, 3)


@pytest.mark.parametrize('field, value, message', [
    ('cable_lengths', (2.0,), 'cable_lengths has 1 entries for 2 UAVs'),
    ('cable_lengths', (2.0, -1.0), r'cable_lengths\[1\] \(cable 2\)'),
    ('payload_mass', 0.0, 'payload_mass'),
    ('payload_drag_coefficient', -0.1, 'payload_drag_coefficient'),
    ('baumgarte_alpha', -1.0, 'baumgarte_alpha'),
    ('baumgarte_beta', math.nan, 'baumgarte_beta'),
    ('uavs', (), 'at least one'),
])
def test_params_validation_names_the_field(field, value, message):
    with pytest.raises(ValueError, match=message):
        params([vehicle(), vehicle()], [2.0, 2.0], **{field: value})


def test_arrays_of_the_wrong_shape_are_refused_before_the_compiled_code_reads_them():
    formation = FormationModel(params([vehicle(), vehicle()], [2.0, 2.0]))
    x = formation.layout.pack([[0, 0, 2], [1, 0, 2]], np.zeros((2, 3)), [0.5, 0, 0.3])
    with pytest.raises(ValueError, match=r'wrenches must have shape \(2, 4\), got \(2, 3\)'):
        formation.accelerations_from_wrenches(x, np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r'state must have shape \(32,\), got \(18,\)'):
        formation.constraint_residuals(x[:18])


def test_rotor_speeds_must_fit_each_vehicle():
    formation = FormationModel(params([vehicle('quad_x'), vehicle('hexa_x')], [2.0, 2.0]))
    x = formation.layout.pack([[0, 0, 2], [1, 0, 2]], np.zeros((2, 3)), [0.5, 0, 0.3])
    with pytest.raises(ValueError, match='uav2'):
        formation.accelerations(0.0, x, [np.full(4, 1500.0), np.full(4, 1500.0)])
    with pytest.raises(ValueError, match='2 UAVs'):
        formation.accelerations(0.0, x, [np.full(4, 1500.0)])
    same_frames = FormationModel(params([vehicle(), vehicle()], [2.0, 2.0]))
    with pytest.raises(ValueError, match=r'rotor_speeds\[0\] \(uav1\)'):
        same_frames.accelerations(0.0, x, [np.full(3, 1500.0), np.full(4, 1500.0)])


def test_gust_reporting():
    gust = Gust(center=(0.0, 0.0), direction=(0.0, -1.0, 0.0), gradient_distance=2.0,
                reference_speed=3.0)
    formation = FormationModel(params([vehicle()], [2.0], gusts=(gust,),
                                      payload_drag_coefficient=0.12))
    x = formation.layout.pack([0, 0, 2.0], [0, 0, 0], [0, 0, 0], payload_velocity=[1.0, 0, 0])
    assert np.allclose(formation.gust_velocity_at_payload(0.0, x), [0, -3.0, 0])
    assert np.allclose(formation.payload_air_velocity(0.0, x), [1.0, 3.0, 0])


# ------------------------------------------------------------------ three UAVs, one payload
N3, LENGTH3, CONE = 3, 3.0, math.radians(30.0)
UAV3 = vehicle()
PAYLOAD3 = 0.8


def three_uav_equilibrium():
    """Symmetric hover: cables at 30 deg from the vertical, every UAV tilted so its thrust
    balances its weight plus its cable pull (seed Eq. 2.73). Returns (model, x, rotor speeds,
    the analytic tension m_p g / (3 cos 30 deg), thrust forces (3, 3) [N])."""
    formation = FormationModel(params([UAV3] * N3, [LENGTH3] * N3, payload_mass=PAYLOAD3))
    tension = PAYLOAD3 * GRAVITY / (N3 * math.cos(CONE))
    payload = np.array([0.5, -1.0, 10.0])
    positions, eulers, speeds, thrusts = [], [], [], []
    for i in range(N3):
        azimuth, yaw = 2 * math.pi * i / N3 + 0.2, 0.3 * i - 0.4
        up_cable = np.array([math.sin(CONE) * math.cos(azimuth),
                             math.sin(CONE) * math.sin(azimuth), math.cos(CONE)])
        positions.append(payload + LENGTH3 * up_cable)
        thrust = UAV3.mass * GRAVITY * np.array([0, 0, 1.0]) + tension * up_cable
        # thrust direction b = Rz(psi) (s_theta c_phi, -s_phi, c_theta c_phi)
        c, s = math.cos(yaw), math.sin(yaw)
        b = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]]) @ (thrust / np.linalg.norm(thrust))
        eulers.append([-math.asin(b[1]), math.atan2(b[0], b[2]), yaw])
        speeds.append(np.full(4, math.sqrt(np.linalg.norm(thrust) / (4 * UAV3.thrust_coefficient))))
        thrusts.append(thrust)
    x = formation.layout.pack(positions, eulers, payload)
    return formation, x, speeds, tension, np.array(thrusts)


def test_three_uav_hover_is_an_equilibrium_with_the_static_tensions():
    formation, x, speeds, tension, _ = three_uav_equilibrium()
    q_ddot, _ = formation.accelerations(0.0, x, speeds)
    assert np.abs(q_ddot).max() < 1e-10
    assert np.allclose(formation.cable_tension(0.0, x, speeds), tension, rtol=1e-10)
    state = x
    for k in range(200):                              # 2 s at 10 ms
        state = formation.step(k * 0.01, state, speeds, 0.01)
    assert np.abs(state - x).max() < 1e-8


def test_three_uav_swing_keeps_cables_and_balances_tensions():
    formation, x, speeds, _, thrusts = three_uav_equilibrium()
    layout = formation.layout
    # rotate the cable star 12 deg about x around the payload: every cable keeps its length
    # (a state on the manifold, at rest) but the thrusts no longer balance the cable pulls
    directions = (layout.payload_position(x) - layout.uav_positions(x)) / LENGTH3
    tilt = math.radians(12.0)
    rotation = np.array([[1, 0, 0], [0, math.cos(tilt), -math.sin(tilt)],
                         [0, math.sin(tilt), math.cos(tilt)]])
    payload = layout.payload_position(x).copy()
    start = x.copy()
    layout.uav_positions(start)[:] = payload - LENGTH3 * directions @ rotation.T
    dt = 2e-3
    states = [start]
    for _ in range(int(10.0 / dt)):
        states.append(formation.step(0.0, states[-1], speeds, dt))
    states = np.array(states)
    g = np.array([formation.constraint_residuals(s)[0] for s in states])
    assert np.abs(g).max() < 1e-6
    assert np.ptp(layout.payload_position(states)[:, 1]) > 0.1  # the payload does swing
    # Newton on the payload with the reported tensions, and every cable taut
    for state in states[::250]:
        q_ddot, _ = formation.accelerations(0.0, state, speeds)
        tensions = formation.cable_tension(0.0, state, speeds)
        assert np.all(tensions > 0)
        units = (layout.uav_positions(state) - layout.payload_position(state)) / LENGTH3
        net = tensions @ units - PAYLOAD3 * GRAVITY * np.array([0, 0, 1.0])
        assert np.allclose(PAYLOAD3 * layout.payload_position(q_ddot), net, atol=1e-9)
    # constant attitudes and thrusts: each thrust is a constant force with potential -F . r
    eulers = np.array([layout.uav_euler(s) for s in states])
    assert np.abs(eulers - eulers[0]).max() < 1e-12
    invariant = np.array([formation.mechanical_energy(s)
                          - np.sum(thrusts * layout.uav_positions(s)) for s in states])
    assert np.ptp(invariant) < 1e-8 * abs(invariant[0])
