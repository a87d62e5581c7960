"""The IMU, the motion capture and the error-state EKF (issue 33 items 1 and 2;
docs/estimation.md) against independent solutions: an IMU on a known motion measures its
specific force and rate; the motion capture delivers its samples latency ticks late; a static
IMU's covariance grows as integrated random walks do (t, t^3 / 3); an update with equal
variances halves the variance and averages; a small Monte Carlo is consistent (its mean NEES
inside the chi-square interval for its count) and a mistuned filter is not; every compiled
function equals its source run by Python; the engine and the per-object path estimate the same
numbers; bad input is one line (its command line: tests/ros/test_estimation_cli.py)."""
from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest import realistic_scenario as _realistic
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.estimators import ekf, error_state, published
from multilift_sim.estimators.consistency import mean_bounds, share_inside
from multilift_sim.formation_params import StateLayout
from multilift_sim.estimators.error_state import (ERROR_ATTITUDE, ERROR_POSITION, ERROR_SIZE,
                                                  ERROR_VELOCITY, NOMINAL_QUATERNION,
                                                  NOMINAL_SIZE, fuse, inject, propagate)
from multilift_sim.physics import attitude
from multilift_sim.physics.layout import MEASURED_COLUMNS, MEASURED_EULER, MEASURED_VELOCITY
from multilift_sim.physics.measurement import quaternion_euler
from multilift_sim.sensors import gnss, imu, mocap
from multilift_sim.sensors.outputs import ARRIVED, OUTPUT, TAKEN
from multilift_tools.estimation_study import monte_carlo

ROOT = Path(__file__).resolve().parents[2]
G = 9.81


def _noise(accel=0.0, gyro=0.0, accel_walk=0.0, gyro_walk=0.0) -> np.ndarray:
    return np.array([accel, gyro, accel_walk, gyro_walk])


def _level() -> np.ndarray:
    x = np.zeros(NOMINAL_SIZE)
    x[NOMINAL_QUATERNION] = 1.0
    return x


def _static(noise: np.ndarray, seconds: float, dt: float = 0.01):
    """A level IMU at rest (f = (0, 0, g), w = 0) from P = 0: (x, P) after `seconds`."""
    x, p = _level(), np.zeros((ERROR_SIZE, ERROR_SIZE))
    for _ in range(int(round(seconds / dt))):
        propagate(x, p, np.array([0.0, 0.0, G]), np.zeros(3), dt, G, noise)
    return x, p


def test_a_static_imu_stays_put_and_its_covariance_grows_as_integrated_random_walks():
    t, n_a, n_g = 10.0, 0.02, 0.003
    x, p = _static(_noise(accel=n_a), t)
    assert np.array_equal(x, _level())  # the exact samples of rest: nothing moves
    for j in range(3):  # white acceleration of density N: var v = N^2 t, var p = N^2 t^3 / 3
        v, r = ERROR_VELOCITY + j, ERROR_POSITION + j
        assert p[v, v] == pytest.approx(n_a ** 2 * t, rel=1e-9)
        assert p[r, r] == pytest.approx(n_a ** 2 * t ** 3 / 3, rel=0.01)
        assert p[r, v] == pytest.approx(n_a ** 2 * t ** 2 / 2, rel=0.01)
    _, p = _static(_noise(gyro=n_g), t)
    for j in range(3):  # white rate: var theta = N^2 t; a tilt turns g into acceleration
        a = ERROR_ATTITUDE + j
        assert p[a, a] == pytest.approx(n_g ** 2 * t, rel=1e-9)
    for j in range(2):  # roll, pitch: var v = g^2 N^2 t^3 / 3 (yaw error moves no g)
        v = ERROR_VELOCITY + j
        assert p[v, v] == pytest.approx(G ** 2 * n_g ** 2 * t ** 3 / 3, rel=0.01)
    assert p[ERROR_VELOCITY + 2, ERROR_VELOCITY + 2] == pytest.approx(0.0, abs=1e-15)


def test_an_update_of_equal_variances_halves_the_variance_and_averages():
    sigma2, seen = 4e-6, np.array([0.002, -0.001, 0.0005])  # [m^2], innovation [m]
    p = np.eye(ERROR_SIZE) * sigma2
    correction = np.zeros(ERROR_SIZE)
    nis = sum(fuse(p, correction, ERROR_POSITION + j, seen[j], sigma2) for j in range(3))
    assert np.allclose(correction[:3], seen / 2, rtol=1e-12, atol=0)
    assert np.allclose(np.diag(p)[:3], sigma2 / 2, rtol=1e-12, atol=0)
    assert np.allclose(np.diag(p)[3:], sigma2, rtol=1e-12, atol=0)  # uncorrelated: untouched
    assert nis == pytest.approx(np.sum(seen ** 2) / (2 * sigma2), rel=1e-12)
    x = _level()
    inject(x, p, correction)
    assert np.allclose(x[:3], seen / 2, rtol=1e-12, atol=0)


def _truth(position, velocity, q) -> np.ndarray:
    row = np.zeros(MEASURED_COLUMNS)
    row[:3], row[MEASURED_VELOCITY:MEASURED_VELOCITY + 3] = position, velocity
    row[MEASURED_EULER:MEASURED_EULER + 3] = quaternion_euler(*q)
    return row


def _rotation(q) -> np.ndarray:
    r = attitude.quaternion_rotation(np.asarray(q, dtype=float), 0)
    return r


def test_the_imu_measures_the_specific_force_and_rate_of_a_known_motion():
    """A body tilted and yawed, turning at a constant body rate w and accelerating at a:
    f = R(q_0)^T (a + g e_z), the rate w (no noise)."""
    dt, w, a = 0.01, np.array([0.2, -0.1, 0.5]), np.array([0.3, -0.2, 1.1])
    q0 = np.array(attitude.rotation_quaternion(0.1, -0.05, 0.4))
    q1 = np.array(attitude.quaternion_product(*q0, *attitude.rotation_quaternion(*(w * dt))))
    v0 = np.array([1.0, 0.5, -0.2])
    settings = imu.ImuSettings((0.0, 0.0), (0.0, 0.0), period=dt, gravity=G)
    memory = imu.memory(settings)
    draws = np.zeros((3, imu.OUTPUT_COLUMNS))
    constants = imu.constants(settings, 1)
    imu.measure(constants, draws, memory, 0, _truth(np.zeros(3), v0, q0), None)
    assert memory[ARRIVED] == -1  # tick 0 starts the interval
    imu.measure(constants, draws, memory, 1, _truth(np.zeros(3), v0 + a * dt, q1), None)
    assert memory[ARRIVED] == memory[TAKEN] == 1
    force = memory[OUTPUT + imu.OUTPUT_SPECIFIC_FORCE:OUTPUT + imu.OUTPUT_SPECIFIC_FORCE + 3]
    assert np.allclose(force, _rotation(q0).T @ (a + [0.0, 0.0, G]), atol=1e-9)
    assert np.allclose(memory[OUTPUT + imu.OUTPUT_RATE:OUTPUT + imu.OUTPUT_RATE + 3], w,
                       atol=1e-9)
    # and the filter's propagation of those samples lands on the true state
    x = _level()
    x[3:6], x[NOMINAL_QUATERNION:NOMINAL_QUATERNION + 4] = v0, q0
    propagate(x, np.zeros((ERROR_SIZE, ERROR_SIZE)), force,
              memory[OUTPUT + imu.OUTPUT_RATE:OUTPUT + imu.OUTPUT_RATE + 3], dt, G, _noise())
    assert np.allclose(x[3:6], v0 + a * dt, atol=1e-12)
    assert np.allclose(x[:3], v0 * dt + a * dt * dt / 2, atol=1e-12)
    assert np.allclose(x[NOMINAL_QUATERNION:NOMINAL_QUATERNION + 4], q1, atol=1e-9)


def test_motion_capture_delivers_samples_latency_ticks_late_and_the_first_at_once():
    settings = mocap.MocapSettings(position_noise=0.0, attitude_noise=0.0, latency=0.03,
                                   dropout=0.0, latency_ticks=3)
    every, ticks = 2, 14
    memory = mocap.memory(settings)
    draws = np.zeros((ticks, mocap.DRAW_COLUMNS))
    draws[:, mocap.DRAW_DELIVERED] = 1.0
    draws[4, mocap.DRAW_DELIVERED] = 0.0  # sample 4 (tick 8) is lost
    constants = mocap.constants(settings, every)
    arrivals = {}
    for tick in range(ticks):
        q = attitude.rotation_quaternion(0.0, 0.0, 0.01 * tick)
        mocap.measure(constants, draws, memory, tick,
                      _truth([tick, 0.0, 0.0], np.zeros(3), q), None)
        if memory[ARRIVED] == tick:
            arrivals[tick] = (memory[TAKEN], memory[OUTPUT])
    # taken at 0 (at once), 2, 4, 6, (8 lost), 10 arriving 3 ticks later, each its tick's x
    assert arrivals == {0: (0, 0.0), 5: (2, 2.0), 7: (4, 4.0), 9: (6, 6.0), 13: (10, 10.0)}


@pytest.mark.parametrize('sections,message', [
    ({'imu': {'rate': 30.0}}, r'imu\.rate: 30\.0 must divide simulation\.control_rate'),
    ({'imu': {'gyroscope_noise_density': -1e-4}},
     r'imu\.gyroscope_noise_density: -0\.0001 must be >= 0'),
    ({'mocap': {'preset': 'vicon_outdoor'}}, r"mocap\.preset: 'vicon_outdoor' must be one of"),
    ({'mocap': {'latency': -0.01}}, r'mocap\.latency: -0\.01 must be >= 0'),
    ({'mocap': None}, r"estimator: 'ekf' needs the sensors mocap or gnss"),
    ({'estimator': 'ukf'}, r"estimator: 'ukf' must be one of")])
def test_bad_estimation_input_names_the_key_and_rule(sections, message):
    with pytest.raises(scenario_io.ScenarioError, match=message) as error:
        _realistic(1.0, **sections)
    assert '\n' not in str(error.value)


def test_the_engine_and_the_per_object_path_estimate_the_same_and_the_controllers_read_it():
    from multilift_control.engine import Engine
    from multilift_control.headless import run_headless
    scenario = _realistic(2.0)
    engine = Engine(scenario)
    record = engine.new_record(200)
    engine.step(200, record)
    received = []
    run = run_headless(scenario, lambda sim, snap, answers: received.append(snap.measured))
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert np.array_equal(record.measured[:, 0], np.array(received[:200]))
    # what the controllers read is the estimate: off the state by about the filter's error
    error = (record.measured[50:, 0, :, :3]
             - StateLayout(scenario.n_uavs).uav_positions(record.states[50:, 0]))
    assert 1e-5 < np.sqrt(np.mean(error ** 2)) < 2e-3  # [m]; motion capture's 1 mm noise
    exact = Engine(_realistic(2.0, imu=None, mocap=None, estimator=None, cable_sensor=None,
                                payload_estimator=None))
    exact.step(200)
    assert not np.array_equal(exact.state, engine.state)


def test_a_small_monte_carlo_of_the_filter_is_consistent_and_a_mistuned_one_is_not():
    runs, seconds = 16, 4.0
    bounds = mean_bounds(3, runs)
    result = monte_carlo(str(ROOT / 'scenarios' / 'twin_lift_realistic.yaml'), runs, seconds)
    for key in ('position', 'attitude'):
        means = result[key][1:]
        assert 2.6 < np.mean(means) < 3.4, key
        assert share_inside(means.ravel(), bounds) > 0.85, key
    assert 5.4 < np.nanmean(result['nis']) < 6.6  # 6 dof

    def overconfident(engine):  # the filter believes the motion capture 4x better than it is
        engine.arrays.estimator_constants[:, 0, ekf.AID_VARIANCE:ekf.AID_VARIANCE + 3] /= 16.0

    bad = monte_carlo(str(ROOT / 'scenarios' / 'twin_lift_realistic.yaml'), runs, seconds,
                      tune=overconfident)
    assert np.mean(bad['position'][1:]) > 6.0
    assert share_inside(bad['position'][1:].ravel(), bounds) < 0.5


def _compiled_functions():
    modules = (error_state, ekf, imu, mocap, gnss)
    found = {f'{m.__name__}.{name}': value for m in modules for name, value in vars(m).items()
             if hasattr(value, 'py_func') and value.__module__ == m.__name__}
    for name in ('quaternion_product', 'rotation_quaternion', 'quaternion_rotation_vector',
                 'turn', 'attitude_difference'):
        found[f'{attitude.__name__}.{name}'] = getattr(attitude, name)
    return found


def test_every_estimation_function_compiled_equals_its_source_bit_for_bit():
    """Each compiled function of the estimation run compiled and as its source in Python, on
    the arrays of a flight's tick (the filter's memory after 150 ticks), the same bits."""
    from multilift_control.engine import Engine
    engine = Engine(_realistic(2.0))
    engine.step(150)
    engine.measured()
    a, m = engine.arrays, engine.memory
    sensors = m.sensor_memory[0][:, 0]
    estimate_memory = m.estimator_memory[0, 0, 0]
    rng = np.random.default_rng(3)
    q = np.array(attitude.rotation_quaternion(*rng.normal(size=3)))
    x = estimate_memory[ekf.NOMINAL:ekf.NOMINAL + NOMINAL_SIZE].copy()
    p = estimate_memory[ekf.COVARIANCE:ekf.DELAYED].reshape(ERROR_SIZE, ERROR_SIZE).copy()
    truth = _truth(rng.normal(size=3), rng.normal(size=3), q)
    imu_row, mocap_row = int(a.estimator_constants[0, 0, ekf.IMU_ROW]), int(
        a.estimator_constants[0, 0, ekf.AID_ROW])
    calls = {
        'propagate': (x, p, rng.normal(size=3) + [0, 0, G], rng.normal(size=3) * 0.1, 0.01,
                      G, _noise(0.002, 0.0003, 0.003, 0.001)),
        'fuse': (p, rng.normal(size=ERROR_SIZE) * 1e-3, 7, 0.01, 2.5e-5),
        'inject': (x, p, rng.normal(size=ERROR_SIZE) * 1e-3),
        'measure': None,
        'estimate': (a.estimator_constants[0, 0], sensors, estimate_memory, 150,
                     np.zeros(MEASURED_COLUMNS)),
        'start': (a.estimator_constants[0, 0], sensors[mocap_row], x, p),
        'update': (a.estimator_constants[0, 0], sensors[mocap_row], x, p, estimate_memory, 150),
        'propagate_sample': (a.estimator_constants[0, 0], estimate_memory, 150, x, p),
        'publish': (a.estimator_constants[0, 0], x, p, estimate_memory),
        'quaternion_product': tuple(rng.normal(size=8)),
        'rotation_quaternion': tuple(rng.normal(size=3)),
        'quaternion_rotation_vector': tuple(q),
        'turn': (q.copy(), 0, 0.1, -0.2, 0.3),
        'attitude_difference': (q.copy(), 0, *attitude.rotation_quaternion(0.3, 0.1, -0.2))}
    sensor_calls = {
        imu.measure: (a.sensor_constants[0, imu_row], a.sensor_draws[0, imu_row, 0],
                      m.sensor_memory[0, imu_row, 0], 151, truth, np.zeros(MEASURED_COLUMNS)),
        mocap.measure: (a.sensor_constants[0, mocap_row], a.sensor_draws[0, mocap_row, 0],
                        m.sensor_memory[0, mocap_row, 0], 151, truth,
                        np.zeros(MEASURED_COLUMNS)),
        gnss.measure: (np.array([2.0, 3.0]), np.ones((100, gnss.DRAW_COLUMNS)),
                       gnss.memory(gnss.GnssSettings(
                           horizontal_position_noise=1.0, vertical_position_noise=2.0,
                           velocity_noise=0.1, latency=0.0, dropout=0.0, latency_ticks=3)),
                       151, truth, np.zeros(MEASURED_COLUMNS))}
    met = set()
    for name, function in _compiled_functions().items():
        short = name.rsplit('.', 1)[1]
        args = sensor_calls[function] if short == 'measure' else calls[short]
        compiled_args, python_args = copy.deepcopy(args), copy.deepcopy(args)
        compiled = function(*compiled_args)
        python = kernels.uncompiled(function)(*python_args)
        assert np.array_equal(np.asarray(compiled, dtype=float), np.asarray(python, dtype=float),
                              equal_nan=True), name
        for k, (c, u) in enumerate(zip(compiled_args, python_args)):
            assert np.array_equal(np.asarray(c, dtype=float), np.asarray(u, dtype=float),
                                  equal_nan=True), (name, k)
        met.add(name)
    assert len(met) == 16, sorted(met)
    assert math.isfinite(p[0, 0])


def test_the_published_estimate_is_the_filter_s_state_and_covariance_in_ros_axes():
    """/uav{i}/estimate's numbers (estimators.published) against the filter's memory: the
    position and quaternion, the pose covariance's position block P_pp and its attitude block
    R P_theta R^T (the body-frame error turned to the world's axes), the velocity R^T v."""
    from multilift_control.engine import Engine
    engine = Engine(_realistic(1.0))
    engine.step(60)
    engine.measured()
    memory = engine.memory.estimator_memory[0, 0, 1]
    x = memory[ekf.NOMINAL:ekf.NOMINAL + NOMINAL_SIZE]
    p = memory[ekf.COVARIANCE:ekf.DELAYED].reshape(ERROR_SIZE, ERROR_SIZE)
    r = _rotation(x[NOMINAL_QUATERNION:NOMINAL_QUATERNION + 4])
    pose = memory[published.ESTIMATE_POSE_COVARIANCE:][:36].reshape(6, 6)
    assert np.array_equal(memory[published.ESTIMATE_POSITION:][:3], x[:3])
    assert np.array_equal(memory[published.ESTIMATE_ORIENTATION:][:4],
                          x[[NOMINAL_QUATERNION + k for k in (1, 2, 3, 0)]])
    assert np.allclose(pose[:3, :3], p[:3, :3], rtol=1e-12, atol=0)
    attitude_block = r @ p[ERROR_ATTITUDE:ERROR_ATTITUDE + 3, ERROR_ATTITUDE:ERROR_ATTITUDE + 3]
    assert np.allclose(pose[3:, 3:], attitude_block @ r.T, rtol=1e-9, atol=1e-18)
    assert np.allclose(pose, pose.T, rtol=1e-9, atol=1e-18)
    assert np.linalg.eigvalsh(pose).min() > 0
    assert np.allclose(memory[published.ESTIMATE_LINEAR:][:3], r.T @ x[3:6], atol=1e-15)
    twist = memory[published.ESTIMATE_TWIST_COVARIANCE:][:36].reshape(6, 6)
    assert np.linalg.eigvalsh(twist).min() > 0


def test_gnss_draws_its_datasheet_noise_and_delivers_latency_ticks_late():
    """`gnss_outdoor` (a u-blox M8: 2.5 m CEP, 0.05 m/s, 10 Hz, 110 ms): the drawn errors'
    deviations per axis (CEP / 1.1774 horizontally, twice that vertically), and on a UAV
    moving at 1 m/s along x each sample arrives 11 ticks late with the position of its tick."""
    scenario = _realistic(1.0, gnss={'preset': 'gnss_outdoor', 'seed': 2})
    config = next(c for c in scenario.sensor_suite if c.model == 'gnss')
    assert config.rate == 10.0 and config.settings.latency_ticks == 11
    rows = gnss.draws(config.settings, 2, 20000, 0.1, np.random.default_rng(5))
    sigma = rows[:, :, gnss.DRAW_ERROR:gnss.DRAW_ERROR + 6].reshape(-1, 6).std(axis=0)
    cep = 2.5 / math.sqrt(2.0 * math.log(2.0))
    assert np.allclose(sigma, [cep, cep, 2 * cep, 0.05, 0.05, 0.05], rtol=0.02)
    settings = gnss.GnssSettings(horizontal_position_noise=0.0, vertical_position_noise=0.0,
                                 velocity_noise=0.0, latency=0.03, dropout=0.0, latency_ticks=3)
    memory = gnss.memory(settings)
    draws = np.zeros((10, gnss.DRAW_COLUMNS))
    draws[:, gnss.DRAW_DELIVERED] = 1.0
    arrivals = {}
    for tick in range(12):
        gnss.measure(gnss.constants(settings, 4), draws, memory, tick,
                     _truth([0.01 * tick, 0.0, 0.0], [1.0, 0.0, 0.0], (1.0, 0, 0, 0)), None)
        if memory[ARRIVED] == tick:
            arrivals[tick] = (memory[TAKEN], round(memory[OUTPUT], 12), memory[OUTPUT + 3])
    assert arrivals == {0: (0, 0.0, 1.0), 7: (4, 0.04, 1.0), 11: (8, 0.08, 1.0)}
    with pytest.raises(scenario_io.ScenarioError, match=r"gnss\.preset: 'gps' must be one of"):
        _realistic(1.0, gnss={'preset': 'gps'})


def test_the_filter_on_gnss_estimates_within_the_receiver_s_noise():
    """`twin_lift_gnss`'s first 5 s: the EKF fusing the GNSS (2.12 m horizontal, 4.25 m
    vertical, 0.05 m/s per axis) estimates each UAV's position better than one fix and its
    velocity to about the fixes' 0.05 m/s; its published covariance covers the error."""
    from multilift_control.engine import Engine
    data = yaml.safe_load((ROOT / 'scenarios' / 'twin_lift_gnss.yaml').read_text())
    data['simulation']['duration'] = 5.0
    engine = Engine(scenario_io.loads(yaml.safe_dump(data)))
    record = engine.new_record(500)
    engine.step(500, record)
    layout = StateLayout(2)
    position = record.estimate[100:, 0, :, :3] - layout.uav_positions(record.states[100:, 0])
    assert np.sqrt(np.mean(position[..., :2] ** 2)) < 2.12  # below one fix's deviation
    sigma = np.sqrt(record.estimate[100:, 0, :, published.ESTIMATE_POSE_COVARIANCE + 0])
    assert np.mean(np.abs(position[..., 0]) < 3 * sigma) > 0.9
