"""Sensors (`sensors:`, issue 21 item 2; docs/sensors.md): the errors against their definition
over many samples (white noise's deviation, the bias random walk's growing variance and
independent steps, the dropout rate), the delivery (update rate, latency in ticks, dropouts held)
against an oracle written here, one seed one series, validation, and the same measurement in the
engine and the per-object (ROS) path, to the bit and byte for byte in bags."""
from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.engine import Engine
from multilift_control.headless import run_headless
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.physics.layout import MEASURED_COLUMNS
from multilift_sim.sensors import measured_state
from multilift_sim.sensors.arrays import sensor_samples
from multilift_sim.sensors.measured_state import BLOCKS, QUANTITIES
from multilift_sim.simulation import FormationSimulator
from multilift_sim.topics import scenario_topics
from multilift_tools.headless_bag import _record_per_object, record_headless


def _config(rate: float = 100.0, seed: int = 0, **keys) -> scenario_io.SensorConfig:
    defaults = dict(noise=(0.0,) * 4, bias=(0.0,) * 4, latency_ticks=0, dropout=0.0)
    settings = measured_state.MeasuredStateSettings(**{**defaults, **keys})
    return scenario_io.SensorConfig(model=measured_state.NAME, rate=rate, seed=seed,
                                    settings=settings)


def sensor_errors(config: scenario_io.SensorConfig, n_uavs: int, tick_count: int,
                  control_rate: float) -> tuple[np.ndarray, np.ndarray]:
    """(errors (S, n, MEASURED_COLUMNS), delivered (S, n)) of a run's samples, drawn as a run
    draws them (sensors.arrays: numpy.random.default_rng(seed))."""
    every = config.every(control_rate)
    return measured_state.sample_errors(config.settings, n_uavs,
                                        sensor_samples(tick_count, every),
                                        every / control_rate,
                                        np.random.default_rng(config.seed))


def _with_sensors(name: str, duration: float, sensors: dict) -> scenario_io.Scenario:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['simulation']['duration'] = duration
    data['sensors'] = sensors
    return scenario_io.loads(yaml.safe_dump(data))


def test_white_noise_has_the_configured_deviation_per_quantity():
    sigmas = (0.02, 0.05, 0.003, 0.01)
    errors, delivered = sensor_errors(_config(noise=sigmas, seed=4), 3, 20_000, 100.0)
    assert errors.shape == (20_001, 3, MEASURED_COLUMNS) and delivered.all()
    for block, sigma in zip(BLOCKS, sigmas):
        values = errors[:, :, block:block + 3].ravel()  # 180,003 draws
        # the sample deviation within 1 % (its own standard error is 0.17 %), the mean ~0
        assert abs(values.std() / sigma - 1.0) < 0.01
        assert abs(values.mean()) < 5 * sigma / math.sqrt(values.size)
        # white: neighbouring samples uncorrelated
        flat = errors[:, 0, block]
        assert abs(np.corrcoef(flat[1:], flat[:-1])[0, 1]) < 0.03


def test_the_bias_walks_as_a_wiener_process_of_its_intensity():
    """Var b(t) = sigma_b^2 t, over 4000 independent UAVs sampled at 20 Hz, and its steps
    independent of each other with variance sigma_b^2 dt."""
    sigma_b, rate = 0.1, 20.0
    errors, _ = sensor_errors(_config(bias=(sigma_b, 0.0, 0.0, 0.0), rate=rate, seed=9), 4000,
                              400, 100.0)  # 400 ticks at 100 Hz: samples every 5 ticks, 81
    assert errors.shape[0] == 81
    bias = errors[:, :, 0]
    assert np.array_equal(bias[0], np.zeros(4000))  # b_0 = 0
    for s in (10, 40, 80):
        t = s / rate
        assert abs(bias[s].var() / (sigma_b ** 2 * t) - 1.0) < 0.07  # 4000 walks: 2.2 % s.e.
    steps = np.diff(bias, axis=0)
    assert abs(steps.var() / (sigma_b ** 2 / rate) - 1.0) < 0.01
    assert abs(np.corrcoef(steps[1:].ravel(), steps[:-1].ravel())[0, 1]) < 0.01
    assert np.array_equal(errors[:, :, 3:], np.zeros_like(errors[:, :, 3:]))  # velocity quiet


def test_samples_drop_at_the_configured_rate_and_a_seed_is_one_series():
    config = _config(noise=(0.01,) * 4, bias=(0.01,) * 4, dropout=0.2, seed=5)
    errors, delivered = sensor_errors(config, 4, 50_000, 100.0)
    lost = 1.0 - delivered.mean()
    assert abs(lost - 0.2) < 4 * math.sqrt(0.2 * 0.8 / delivered.size)
    again = sensor_errors(config, 4, 50_000, 100.0)
    assert np.array_equal(errors, again[0]) and np.array_equal(delivered, again[1])
    other = sensor_errors(_config(noise=(0.01,) * 4, bias=(0.01,) * 4, dropout=0.2, seed=6),
                          4, 50_000, 100.0)
    assert not np.array_equal(errors, other[0])


def _oracle(exact: np.ndarray, errors: np.ndarray, delivered: np.ndarray, every: int,
            latency: int) -> np.ndarray:
    """What the controllers hold at each tick, from the definition: the last sample that has
    arrived (taken at a tick j = s * every with j + latency <= k, and delivered; sample 0 at
    once), with its error."""
    ticks, n, _ = exact.shape
    out = np.empty_like(exact)
    for k in range(ticks):
        for i in range(n):
            arrived = [j for j in range(0, k - latency + 1, every)
                       if delivered[j // every, i]]
            j = max(arrived) if arrived else 0
            out[k, i] = exact[j, i] + errors[j // every, i]
    return out


@pytest.mark.parametrize('every,latency', [(1, 0), (1, 3), (4, 0), (3, 5)])
def test_delivery_follows_rate_latency_and_dropouts(every, latency):
    """Both runs of the model's `measure` (compiled and its source), UAV by UAV, against the
    oracle above, tick by tick, on exact states that change every tick; calling twice a tick
    changes nothing."""
    rng = np.random.default_rng(1)
    ticks, n = 60, 2
    exact = rng.standard_normal((ticks, n, MEASURED_COLUMNS))
    samples = (ticks - 1) // every + 1
    errors = rng.standard_normal((samples, n, MEASURED_COLUMNS)) * 0.01
    delivered = rng.random((samples, n)) > 0.3
    delivered[0] = False  # the first sample arrives anyway
    expected = _oracle(exact, errors, delivered, every, latency)
    settings = _config(latency_ticks=latency).settings
    constants = measured_state.constants(settings, every)
    draws = np.empty((n, samples, measured_state.DRAW_COLUMNS))
    draws[:, :, measured_state.DRAW_ERROR:MEASURED_COLUMNS] = errors.transpose(1, 0, 2)
    draws[:, :, measured_state.DRAW_DELIVERED] = delivered.T
    for function in (measured_state.measure, kernels.uncompiled(measured_state.measure)):
        memory = np.repeat(measured_state.memory(settings)[np.newaxis], n, axis=0)
        for k in range(ticks):
            for _ in range(2):
                for i in range(n):
                    received = np.full(MEASURED_COLUMNS, -1.0)
                    function(constants, draws[i], memory[i], k, exact[k, i].copy(), received)
                    assert np.array_equal(received, expected[k, i]), (k, i, function)


def test_the_controllers_see_the_state_latency_ticks_late():
    """A step response through the simulator: with latency L and no noise, what the
    controllers receive at tick k is the state at tick k - L exactly (the state at 0 before)."""
    scenario = _with_sensors('twin_lift', 0.3, {'latency_ticks': 4})
    simulator = FormationSimulator(scenario)
    exact, received = [], []
    speeds = [np.full(4, 1900.0), np.full(4, 1950.0)]
    while not simulator.finished:
        snap = simulator.snapshot()
        exact.append(snap.odometry[:, :MEASURED_COLUMNS].copy())
        received.append(snap.measured.copy())
        simulator.advance(speeds, [np.zeros(4, bool)] * 2)
    exact, received = np.array(exact), np.array(received)
    assert np.array_equal(received[4:], exact[:-4])
    assert np.array_equal(received[:4], np.repeat(exact[:1], 4, axis=0))
    assert not np.array_equal(exact[4], exact[0])


@pytest.mark.parametrize('sensors,message', [
    ({'rate': 30.0}, r'sensors\.rate: 30\.0 must divide simulation\.control_rate \(100\)'),
    ({'rate': 200.0}, r'sensors\.rate: 200\.0 must be > 0 and <= simulation\.control_rate'),
    ({'dropout': 1.0}, r'sensors\.dropout: 1\.0 must be within \[0, 1\)'),
    ({'latency_ticks': 1.5}, r'sensors\.latency_ticks: 1\.5 must be an integer >= 0'),
    ({'seed': -1}, r'sensors\.seed: -1 must be an integer >= 0'),
    ({'position_noise': -0.1}, r'sensors\.position_noise: -0\.1 must be >= 0'),
    ({'gps_noise': 0.1}, r'sensors\.gps_noise: unknown key')])
def test_bad_sensors_name_key_and_rule(sensors, message):
    with pytest.raises(scenario_io.ScenarioError, match=message):
        _with_sensors('twin_lift', 1.0, sensors)


def test_every_quantity_has_its_keys_and_silent_sensors_change_nothing():
    keys = {f'{q}_{kind}': 0.0 for q in QUANTITIES for kind in ('noise', 'bias')}
    quiet = _with_sensors('twin_lift', 1.0, dict(keys, seed=3))
    assert quiet.sensors.settings.noise == (0.0,) * 4 and quiet.sensors.every(100.0) == 1
    assert quiet.sensors.model == 'measured_state'  # the default model
    plain = scenario_io.load('twin_lift').with_duration(1.0)
    assert plain.sensors is None
    a, b = Engine(quiet), Engine(plain)
    a.step(100)
    b.step(100)
    assert np.array_equal(a.state, b.state)


def test_the_engine_and_the_ros_path_receive_the_same_measurements():
    scenario = _with_sensors('circle3', 2.0, {
        'position_noise': 0.005, 'velocity_noise': 0.01, 'attitude_noise': 0.001,
        'body_rate_noise': 0.003, 'position_bias': 0.01, 'rate': 50.0, 'latency_ticks': 3,
        'dropout': 0.1, 'seed': 11})
    engine = Engine(scenario)
    record = engine.new_record(200)
    engine.step(200, record)
    received = []
    run = run_headless(scenario, lambda sim, snap, answers: received.append(snap.measured))
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert np.array_equal(record.measured[:, 0], np.array(received[:200]))
    # what they received is not the state: the error is there, and about its size
    exact = record.states[:, 0, :3]
    error = record.measured[100:, 0, 0, :3] - exact[100:]
    assert 0.002 < np.abs(error).mean() < 0.05
    summary = run.summary()
    del summary['sim']['wall_time']
    assert engine.summary(0) == summary
    assert summary['sim']['seeds'] == {'sensors': 11}  # the run's seed, recorded


def test_bags_carry_the_state_and_what_the_controllers_received(tmp_path):
    """The engine's headless bag is the per-object path's byte for byte; it has a
    /uav{i}/measured_odom per UAV beside /uav{i}/odom, and the two differ."""
    from rosbags.highlevel import AnyReader

    scenario = _with_sensors('twin_lift', 1.0, {'position_noise': 0.01, 'seed': 2,
                                                'latency_ticks': 1})
    record_headless(scenario, tmp_path / 'engine' / 'bag')
    _record_per_object(scenario, tmp_path / 'objects' / 'bag')
    for path in (tmp_path / 'engine' / 'bag').iterdir():
        assert path.read_bytes() == (tmp_path / 'objects' / 'bag' / path.name).read_bytes()
    assert ('/uav2/measured_odom', 'nav_msgs/msg/Odometry') in scenario_topics(scenario)
    with AnyReader([tmp_path / 'engine' / 'bag']) as reader:
        topics = {c.topic: c.msgcount for c in reader.connections}
        assert topics['/uav1/measured_odom'] == topics['/uav1/odom'] == 101
        wanted = [c for c in reader.connections if c.topic in ('/uav1/odom',
                                                               '/uav1/measured_odom')]
        x = {'/uav1/odom': [], '/uav1/measured_odom': []}
        for connection, _, raw in reader.messages(wanted):
            x[connection.topic].append(
                reader.deserialize(raw, connection.msgtype).pose.pose.position.x)
    difference = np.array(x['/uav1/measured_odom'])[1:] - np.array(x['/uav1/odom'])[:-1]
    assert 0.004 < difference.std() < 0.02  # one tick late, 0.01 m of noise


def test_a_sweep_can_sample_a_sensor_key_the_scenario_does_not_have():
    """`sweep --sample sensors.position_noise=...` on a scenario without `sensors:` (issue 21
    item 6): the section is made, and the noise changes the run."""
    from multilift_tools import campaign
    source, base = campaign.load_base('twin_lift')
    path = campaign.parse_key('sensors.position_noise', '--sample')
    rows = [campaign.run_one(source, base, [('sensors.position_noise', path, noise)],
                             duration=3.0) for noise in (0.0, 0.02)]
    assert [row['status'] for row in rows] == ['ok', 'ok']
    exact = campaign.run_one(source, base, [], duration=3.0)
    assert rows[0]['tracking_error_rms'] == exact['tracking_error_rms']
    assert rows[1]['tracking_error_rms'] != exact['tracking_error_rms']


def test_the_shipped_model_is_named_in_its_own_module_only():
    """`nothing else names a model` (issue 31): the shipped model's name as a string in one
    source file, its module of multilift_sim/sensors/."""
    import re
    from pathlib import Path

    from multilift_sim.sensors import SENSOR_MODELS
    sources = sorted((Path(__file__).resolve().parents[2] / 'ros_ws' / 'src').rglob('*.py'))
    for model in SENSOR_MODELS.shipped:
        pattern = re.compile(rf"""['"]{model.NAME}['"]""")
        naming = [p.name for p in sources if pattern.search(p.read_text())]
        assert naming == [f'{model.NAME}.py'], naming
        assert SENSOR_MODELS[model.NAME] is model


def test_sensors_of_a_formation_run_in_order_each_from_the_truth():
    """sensed_states with two sensors (K = 2, both measured_state, rows padded to the wider):
    each reads the true state, not the one before it's output, and the last one's output is
    what the controllers receive; compiled and uncompiled alike."""
    from multilift_sim.sensors.arrays import _padded
    from multilift_sim.sensors.sensing import sensed_states

    rng = np.random.default_rng(3)
    n, ticks = 2, 12
    exact = rng.standard_normal((ticks, n, MEASURED_COLUMNS))
    late, noisy = _config(latency_ticks=2).settings, _config(noise=(0.1,) * 4).settings
    draws = [measured_state.draws(s, n, ticks, 0.01, np.random.default_rng(k))
             for k, s in enumerate((late, noisy))]
    constants = _padded([measured_state.constants(s, 1) for s in (late, noisy)], (0,))
    memory0 = _padded([np.repeat(measured_state.memory(s)[np.newaxis], n, axis=0)
                       for s in (late, noisy)], (n, 0))
    assert memory0.shape == (2, n, measured_state.DELAY_LINE + 3 * MEASURED_COLUMNS)
    models = np.zeros(2, dtype=np.int64)
    for function in (sensed_states, kernels.uncompiled(sensed_states)):
        memory = memory0.copy()
        for k in range(ticks):
            states = exact[k].copy()
            function(models, constants, _padded(draws, (n, 0, 0)), memory, k, exact[k].copy(),
                     states)
            # the second sensor's: the true state now with its noise (not 2 ticks late)
            np.testing.assert_array_equal(states, exact[k] + draws[1][:, k, :MEASURED_COLUMNS])
            # the first one's, held in its memory: the state 2 ticks ago (tick 0's before)
            held = memory[0, :, measured_state.HELD:measured_state.HELD + MEASURED_COLUMNS]
            np.testing.assert_array_equal(held, exact[max(k - 2, 0)])
