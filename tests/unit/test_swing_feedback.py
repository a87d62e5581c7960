"""The leader's swing feedback (`control.payload_feedback`, multilift_control.laws.swing; issue
20 item 5, beyond the seed): its keys and their checks, its equation written out, the payload's
state reaching it on every path (the engine, the per-object runtimes, the leader node's
snapshot), and what it is for: a released swing dies faster than under the seed's law."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from multilift_control import laws
from multilift_control.controllers import LeaderController, swing_period, swing_rest
from multilift_control.engine import Engine
from multilift_control.headless import run_headless
from multilift_control.laws.layout import (CASCADE_SWING_DAMPING, CASCADE_SWING_LIMIT,
                                           CASCADE_SWING_REST, CASCADE_SWING_STIFFNESS,
                                           UAV_STATE_SIZE)
from multilift_control.laws import cascade as cascade_law
from multilift_control.laws.swing import swing_feedback
from multilift_control.mission import MissionPath
from multilift_control.runtime import uav_states
from multilift_sim.formation_params import StateLayout
from multilift_sim import scenario as scenario_io
from multilift_sim.scenario import INPUT_SHAPERS
from multilift_sim.simulation import FormationSimulator
from multilift_sim.start import formation_start
from multilift_sim.statistics import payload_swing


def _with_feedback(name: str, stiffness: float, damping: float, limit: float = math.inf,
                   **simulation) -> scenario_io.Scenario:
    base = scenario_io.load(name)
    return dataclasses.replace(
        base, control=dataclasses.replace(base.control, swing_stiffness=stiffness,
                                          swing_damping=damping, swing_limit=limit),
        simulation=dataclasses.replace(base.simulation, **simulation))


def _yaml(feedback: str, mode: str = 'cascade') -> str:
    text = scenario_io.resolve('twin_lift').read_text()
    text = text.replace('  mode: cascade\n', f'  mode: {mode}\n')
    return text.replace('  max_tilt_deg: 25.0\n', f'  max_tilt_deg: 25.0\n{feedback}')


def test_the_keys_are_read_and_off_by_default():
    seed = scenario_io.load('twin_lift').control
    assert (seed.swing_stiffness, seed.swing_damping, seed.swing_limit) == (0.0, 0.0, math.inf)
    control = scenario_io.loads(_yaml('  payload_feedback: {swing_stiffness: 0.75, '
                                      'swing_damping: 0.25, acceleration_limit: 0.2}\n')).control
    assert (control.swing_stiffness, control.swing_damping, control.swing_limit) == (
        0.75, 0.25, 0.2)


@pytest.mark.parametrize('feedback,mode,words', [
    ('  payload_feedback: {swing_damping: 0.5}\n', 'constant_rotor_speed',
     'payload_feedback.swing_damping: 0.5 needs control.mode: cascade'),
    ('  payload_feedback: {swing_damping: 0.5, acceleration_limit: 0}\n', 'cascade',
     'acceleration_limit: 0.0 must be > 0'),
    ('  payload_feedback: {swing_gain: 0.5}\n', 'cascade', 'swing_gain'),
    ('  payload_feedback: {swing_stiffness: .nan}\n', 'cascade', 'must be finite')])
def test_bad_keys_are_refused_by_name(feedback, mode, words):
    with pytest.raises(scenario_io.ScenarioError, match=words.replace('.', r'\.')):
        scenario_io.loads(_yaml(feedback, mode), 'x.yaml')


def test_the_law_is_the_equation_written_out():
    """a_s = k_s ((r_p - mean r_i)_xy - s_0) + k_d (v_p - mean v_i)_xy, its size limited with
    its direction kept, nothing vertical."""
    constants = np.zeros(CASCADE_SWING_LIMIT + 1)
    constants[CASCADE_SWING_STIFFNESS], constants[CASCADE_SWING_DAMPING] = 0.8, 0.3
    constants[CASCADE_SWING_REST:CASCADE_SWING_REST + 2] = 0.2, -0.1
    constants[CASCADE_SWING_LIMIT] = math.inf
    states = np.zeros((2, UAV_STATE_SIZE))
    states[0, 0:3], states[1, 0:3] = (1.0, 2.0, 5.0), (3.0, 0.0, 5.5)
    states[0, 3:6], states[1, 3:6] = (0.5, 0.1, 0.2), (0.3, -0.3, 0.0)
    payload_position, payload_velocity = np.array([2.5, 0.7, -4.0]), np.array([0.1, 0.6, 0.3])
    law = laws.runnable(swing_feedback)
    swing = np.array([2.5 - 2.0 - 0.2, 0.7 - 1.0 + 0.1])
    rate = np.array([0.1 - 0.4, 0.6 + 0.1])
    expected = 0.8 * swing + 0.3 * rate
    out = law(constants, states, payload_position, payload_velocity)
    assert out == pytest.approx([*expected, 0.0], abs=1e-15)
    constants[CASCADE_SWING_LIMIT] = 0.1
    limited = law(constants, states, payload_position, payload_velocity)
    assert np.hypot(*limited[:2]) == pytest.approx(0.1, rel=1e-14)
    assert limited[:2] / 0.1 == pytest.approx(expected / np.hypot(*expected), rel=1e-13)
    assert limited[2] == 0.0


def test_the_rest_offset_is_the_hanging_formation_s():
    scenario = scenario_io.load('twin_lift')
    uavs, payload = formation_start(scenario)
    assert swing_rest(scenario) == pytest.approx((payload - uavs.mean(axis=0))[:2], abs=1e-12)
    assert swing_rest(scenario_io.load('single_lift')) == (0.0, 0.0)
    leader = LeaderController(_with_feedback('twin_lift', 0.75, 0.25), 0)
    assert leader.cascade.constants[CASCADE_SWING_REST:CASCADE_SWING_REST + 2] == \
        pytest.approx(swing_rest(scenario), abs=0)


def test_the_engine_flies_it_as_the_runtimes_do_to_the_bit():
    """The engine reads the payload's state from its own; the per-object runtimes from the
    snapshot (FormationStates.payload_position/_velocity): the same states to the bit."""
    scenario = _with_feedback('twin_lift', 0.75, 0.25, 0.2, duration=20.0)
    engine = Engine(scenario)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert engine.finished[0]
    assert np.array_equal(engine.state[0], run.simulator.state)
    seed = Engine(scenario_io.load('twin_lift'))
    seed.step(2000)
    assert np.abs(seed.state[0] - engine.state[0]).max() > 1e-3  # the feedback acted


def test_a_leader_without_the_payload_state_refuses_to_guess():
    scenario = _with_feedback('twin_lift', 0.75, 0.25)
    states = uav_states(FormationSimulator(scenario).snapshot())
    bare = type(states)(states)  # the UAVs only
    leader = LeaderController(scenario, 0)
    with pytest.raises(ValueError, match='payload_feedback needs the payload'):
        leader.update(0.0, bare)
    leader.update(0.0, states)
    seed = LeaderController(scenario_io.load('twin_lift'), 0)
    seed.update(0.0, bare)  # the seed's law does not read it


def test_a_leader_answers_its_own_state_alone_as_before_the_feedback():
    """A user's node that reads only /uav1/odom (examples/multilift_example_leader) hands the
    leader one UavState: answered as the formation of one, the same as the stacked call."""
    scenario = scenario_io.load('single_lift')
    states = uav_states(FormationSimulator(scenario).snapshot())
    alone, stacked = LeaderController(scenario, 0), LeaderController(scenario, 0)
    for t in (0.0, 0.01, 0.02):
        output, reference = alone.update(t, states[0])
        expected, expected_reference = stacked.update(t, type(states)(states[:1]))
        assert np.array_equal(output.rotor_speeds, expected.rotor_speeds)
        assert np.array_equal(reference.position, expected_reference.position)
    assert output.rotor_speeds.min() > 0


def test_the_leader_node_reads_the_payload_from_the_snapshot():
    pytest.importorskip('rclpy')
    from multilift_control.ros.common import SnapshotReader
    from multilift_sim.wire import cdr

    scenario = scenario_io.load('twin_lift')
    snapshot = FormationSimulator(scenario).snapshot()
    counts = [u.vehicle.n_rotors for u in scenario.uavs]
    data = cdr.FormationSnapshot(counts).pack(
        123, *(np.concatenate([getattr(u, field) for u in snapshot.uavs])
               for field in ('position', 'velocity', 'euler', 'body_rates')),
        snapshot.payload_position, snapshot.payload_velocity + 0.25, [])
    t_ns, states, _ = SnapshotReader(scenario)(data)
    assert t_ns == 123
    assert np.array_equal(states.payload_position, snapshot.payload_position)
    assert np.array_equal(states.payload_velocity, snapshot.payload_velocity + 0.25)


def test_a_released_swing_dies_faster_than_under_the_seed_s_law():
    """One UAV hovering, its payload released 8 deg out (no drag): from 5 to 10 s after the
    release the feedback (k_s = 1, k_d = 1) has left less than 0.7 of the seed's law's swing
    (0.57 measured)."""
    base = scenario_io.load('single_lift')
    swings = []
    for gains in ((0.0, 0.0), (1.0, 1.0)):
        scenario = dataclasses.replace(
            base, mission=dataclasses.replace(base.mission, segments=()),
            payload=dataclasses.replace(base.payload, alpha=math.radians(8.0),
                                        drag_coefficient=0.0),
            simulation=dataclasses.replace(base.simulation, duration=10.0),
            control=dataclasses.replace(base.control, swing_stiffness=gains[0],
                                        swing_damping=gains[1]))
        engine = Engine(scenario)
        record = engine.new_record(1000)
        engine.step(1000, record)
        x = record.states[500:, 0]
        layout = StateLayout(1)
        swing = payload_swing(layout.uav_positions(x), layout.payload_position(x),
                              [base.uavs[0].cable_length])
        swings.append(float(np.sqrt(np.mean(swing ** 2))))
    assert swings[0] > 5e-3  # the seed's law leaves a swing to damp
    assert swings[1] < 0.7 * swings[0], swings


def _one_leg(tau: float) -> scenario_io.MissionConfig:
    """0.5 m/s along x for 20 s, then 0.5 m/s along y for 20 s, then the stop."""
    return scenario_io.MissionConfig(
        start=(0.0, 0.0, 0.0), reference_filter_time=tau,
        segments=(scenario_io.MissionSegment(velocity=(0.5, 0.0, 0.0), end_time=20.0),
                  scenario_io.MissionSegment(velocity=(0.0, 0.5, 0.0), end_time=40.0)))


def _residual_swing(path: MissionPath, omega: float, t_end: float) -> float:
    """The amplitude [m] a pendulum of frequency omega [rad/s] hung from the reference's x keeps
    after t_end [s]: x_p_ddot = -omega^2 (x_p - x_ref(t)), from rest under the start,
    integrated independently of the shaper (scipy, 1 ms steps at most)."""
    from scipy.integrate import solve_ivp

    def rates(t, y):
        return [y[1], -omega ** 2 * (y[0] - path(t).position[0])]

    solution = solve_ivp(rates, (0.0, t_end), [0.0, 0.0], max_step=1e-3, rtol=1e-10,
                         atol=1e-12)
    x_p, v_p = solution.y[:, -1]
    reference = path(t_end)
    swing, rate = x_p - reference.position[0], v_p - reference.velocity[0]
    return float(math.hypot(swing, rate / omega))


@pytest.mark.parametrize('tau', [0.0, 0.5])
def test_a_shaped_corner_leaves_the_pendulum_it_is_shaped_for_at_rest(tau):
    """Each shaper of INPUT_SHAPERS at period T: a pendulum of that period hung from the
    reference keeps (almost) no swing after the corners, where the unshaped corners leave
    one; raw steps and the filtered path alike."""
    period = 3.0
    omega = 2.0 * math.pi / period
    mission = _one_leg(tau)
    unshaped = _residual_swing(MissionPath(mission), omega, 38.0)
    assert unshaped > 1e-3
    for name, shaper in INPUT_SHAPERS.items():
        if name == 'none':
            continue
        shaped = _residual_swing(MissionPath(mission, shaper, period), omega, 38.0)
        assert shaped < 1e-3 * unshaped, (name, shaped, unshaped)


def test_a_shaped_mission_ends_where_the_mission_ends():
    mission = _one_leg(2.0)
    for name, shaper in INPUT_SHAPERS.items():
        path = MissionPath(mission, shaper, 6.4)
        final = path(200.0)
        assert final.position == pytest.approx([10.0, 10.0, 0.0], abs=1e-9), name
        assert final.velocity == pytest.approx([0.0, 0.0, 0.0], abs=1e-9)
        assert path(19.0).velocity[:2] == pytest.approx([0.5, 0.0], abs=1e-2)  # settled
    # the shaper's impulses: the steps at 0, T/2, T, 3T/2 of the velocity, sorted in time
    steps = MissionPath(mission, INPUT_SHAPERS['zvdd'], 4.0).steps
    assert list(steps[:4, 0]) == [0.0, 2.0, 4.0, 6.0]
    assert list(steps[:4, 1]) == [0.0625, 0.1875, 0.1875, 0.0625]


def test_the_shaping_period_is_the_hanging_payload_s_pendulum():
    single = scenario_io.load('single_lift')
    assert swing_period(single) == pytest.approx(
        2 * math.pi * math.sqrt(single.uavs[0].cable_length / 9.81), rel=1e-12)
    twin = scenario_io.load('twin_lift')
    half = 0.5 * math.hypot(*twin.formation.offsets[0])  # the UAVs 4 m apart, level
    depth = math.sqrt(twin.uavs[0].cable_length ** 2 - half ** 2)
    assert swing_period(twin) == pytest.approx(2 * math.pi * math.sqrt(depth / 9.81), rel=1e-9)


def test_the_feedback_yields_to_the_rotor_limits():
    """A share 1, 1/2, 1/4 of m a_s that saturates no rotor is flown; where all three would,
    the leader flies the seed's command (its integral advanced once either way)."""
    scenario = _with_feedback('twin_lift', 0.75, 0.25)
    leader = LeaderController(scenario, 0)
    seed = LeaderController(scenario_io.load('twin_lift'), 0)
    states = uav_states(FormationSimulator(scenario).snapshot()).array.copy()
    rest = np.array(formation_start(scenario)[1])
    law = laws.runnable(cascade_law.leader_update)
    c, p = leader.cascade, leader.path

    def answer(constants, payload_offset):
        memory = c.memory.copy()
        out = law(constants, c.mixer.rows, memory, p.mission, p.segments, p.steps, 0.5, states,
                  rest + payload_offset, np.zeros(3))
        return out, memory

    (seed_speeds, seed_saturated, *_), seed_memory = answer(seed.cascade.constants,
                                                             np.zeros(3))
    (speeds, saturated, *_), memory = answer(c.constants, np.array([0.02, 0.0, 0.0]))
    assert not saturated.any() and not np.array_equal(speeds, seed_speeds)
    assert np.array_equal(memory, seed_memory)
    wild = c.constants.copy()
    wild[CASCADE_SWING_STIFFNESS] = 1e4  # every share tilts the UAV past its rotors
    (speeds, saturated, *_), memory = answer(wild, np.array([3.0, 0.0, 0.0]))
    assert np.array_equal(speeds, seed_speeds) and np.array_equal(saturated, seed_saturated)
    assert np.array_equal(memory, seed_memory)
