"""Links between the UAVs (`comms:`, issue 33 item 5): what a follower hears of the leader
(multilift_sim.links.radio.receive) against the packets sent, the engine and the nodes'
runtime hearing alike, and the V of three flying the §4.2 mission over a 50 ms, 10 % loss
link (the issue's bar)."""
import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import fly, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.links.radio import (LINK_LATENCY, LINK_RANGE, MEASURED_COLUMNS,
                                       MEASURED_POSITION, link_arrays, read_comms, receive)
from multilift_sim.scenario.reading import Section


def _multi_lift(comms=None, duration=None):
    data = yaml.safe_load((SCENARIOS / 'multi_lift.yaml').read_text())
    if comms is not None:
        data['comms'] = comms
    if duration is not None:
        data['simulation']['duration'] = duration
    return scenario_io.loads(yaml.safe_dump(data))


def _hear(comms, leader_positions, own_position=(0.0, 0.0, 0.0), delivered=None):
    """The leader's x [m] a follower flies on at each tick, the leader at x = leader_positions
    (ticks,) sending its tick's packet (thrust = its tick)."""
    config = read_comms(Section({'comms': comms}, '', 'test'), 100.0)
    ticks = len(leader_positions)
    link, drawn, memory = link_arrays(config, 2, ticks)
    delivered = drawn[1] if delivered is None else np.asarray(delivered, dtype=float)
    heard, xs, thrusts = np.empty(MEASURED_COLUMNS), [], []
    for tick, x in enumerate(leader_positions):
        leader = np.zeros(MEASURED_COLUMNS)
        leader[MEASURED_POSITION] = x
        thrusts.append(receive(link, delivered, memory[1], tick, leader, float(tick),
                               np.asarray(own_position), heard))
        xs.append(heard[MEASURED_POSITION])
    return np.array(xs), np.array(thrusts), link


def test_a_packet_arrives_latency_ticks_late_and_a_lost_one_leaves_the_last():
    xs, thrusts, link = _hear({'latency': 0.03}, np.arange(10.0))
    assert link[LINK_LATENCY] == 3
    # tick 0's at once (the formation at rest), then tick k hears tick k - 3's
    assert xs.tolist() == [0, 0, 0, 0, 1, 2, 3, 4, 5, 6]
    assert thrusts.tolist() == xs.tolist()
    delivered = np.ones(11)
    delivered[[2, 3, 6]] = 0.0   # the packets sent at ticks 2, 3 and 6 lost
    xs, _, _ = _hear({'latency': 0.01}, np.arange(10.0), delivered=delivered)
    assert xs.tolist() == [0, 0, 1, 1, 1, 4, 5, 5, 7, 8]


def test_losses_follow_their_probability_and_the_range_cuts_the_link():
    _, _, link = _hear({'loss': 0.3}, [0.0])
    config = read_comms(Section({'comms': {'loss': 0.3, 'seed': 4}}, '', 'test'), 100.0)
    _, delivered, _ = link_arrays(config, 3, 20000)
    assert abs(1.0 - delivered.mean() - 0.3) < 0.01
    assert link[LINK_RANGE] == math.inf
    # the leader walks away at 1 m a tick: beyond 4.5 m the follower keeps what it heard last
    xs, _, _ = _hear({'range': 4.5}, np.arange(10.0))
    assert xs.tolist() == [0, 1, 2, 3, 4, 4, 4, 4, 4, 4]


def test_the_engine_and_the_runtime_of_the_nodes_hear_alike():
    s = _multi_lift({'latency': 0.05, 'loss': 0.3, 'seed': 2}, duration=6.0)
    engine = fly(s).summary()
    headless = run_headless(s).summary()
    for name in ('leader', 'follower2', 'follower3'):
        for key, value in engine[name].items():
            assert headless[name][key] == pytest.approx(value, abs=1e-9), (name, key)
    exact = fly(_multi_lift(duration=6.0)).summary()   # and the link did change the flight
    assert exact['follower2']['mean_formation_error_norm'] != pytest.approx(
        engine['follower2']['mean_formation_error_norm'], abs=1e-6)


def test_the_v_of_three_flies_its_mission_over_a_50_ms_link_losing_10_percent():
    exact = fly(_multi_lift()).summary()
    linked = fly(_multi_lift({'latency': 0.05, 'loss': 0.1, 'seed': 1})).summary()
    assert linked['sim']['error'] is None
    assert max(linked['sim']['saturated_time']) <= 1.0
    assert linked['leader']['rms_tracking_error'] <= 2.0 * exact['leader']['rms_tracking_error']


@pytest.mark.parametrize('comms, message', [
    ({'loss': 1.0}, 'comms.loss: 1.0 must be within [0, 1)'),
    ({'latency': -0.01}, 'comms.latency: -0.01 must be >= 0'),
    ({'range': 0.0}, 'comms.range: 0.0 must be > 0'),
    ({'delay': 0.1}, 'delay'),
])
def test_bad_comms_are_one_line(comms, message):
    with pytest.raises(scenario_io.ScenarioError, match='^[^\n]*$') as error:
        _multi_lift(comms)
    assert message in str(error.value)


def test_a_link_needs_followers():
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['comms'] = {'latency': 0.05}
    with pytest.raises(scenario_io.ScenarioError, match='needs n >= 2'):
        scenario_io.loads(yaml.safe_dump(data))


def test_what_a_follower_hears_compiled_equals_its_uncompiled_source():
    """heard_formation (and receive inside it) compiled and run by Python, bit for bit, over
    200 ticks of a leader that moves, through 30 ms of latency, 20 % loss and a 3 m range."""
    from multilift_control.laws.links import heard_formation
    config = read_comms(Section({'comms': {'latency': 0.03, 'loss': 0.2, 'range': 3.0}}, '',
                                'test'), 100.0)
    results = []
    for law in (heard_formation, heard_formation.py_func):
        link, delivered, memory = link_arrays(config, 3, 200)
        walk = np.random.default_rng(3)
        heard, thrusts, out = np.empty((3, MEASURED_COLUMNS)), np.empty(3), []
        for tick in range(200):
            states = walk.normal(size=(3, MEASURED_COLUMNS))
            states[0, MEASURED_POSITION] = 0.05 * tick    # leaves the range at tick 60
            law(link, delivered[2], memory[2], tick, 2, states, walk.normal(size=3), heard,
                thrusts)
            out.append(np.concatenate([heard.ravel(), thrusts]))
        results.append(np.array(out))
    assert np.array_equal(results[0], results[1])
    assert len({row[0] for row in results[0]}) < 150  # packets lost or out of range: held


def test_the_comms_study_writes_its_table_and_figure(tmp_path):
    from multilift_tools.comms_study import comms_study
    result = comms_study(tmp_path, latencies=(0.0, 0.2), losses=(0.0, 0.5))
    assert [(r['latency'], r['loss']) for r in result['rows']] == [
        (0.0, 0.0), (0.0, 0.5), (0.2, 0.0), (0.2, 0.5)]
    exact = fly(_multi_lift()).summary()['leader']['rms_tracking_error']
    assert result['rows'][0]['tracking_rms'] == pytest.approx(exact, abs=1e-12)  # heard at once
    assert result['rows'][3]['tracking_rms'] > exact
    assert len(result['table'].splitlines()) == 6
    for path in result['files'].values():
        assert (tmp_path / path.split('/')[-1]).stat().st_size > 0
