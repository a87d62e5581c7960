"""Winches (`uavs[i].winch`, issue 32 item 3; physics.winch) against mechanics worked out here:
the reel's limits and stops, the energy balance of a falling single lift whose cable is paid
out (the winch's work, from angular momentum, equals the change of the system's energy), the
twin-lift lowering its payload 3 m (`winch_lower`), the bad input, and the compiled run against
its uncompiled source."""
from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import fly, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.physics.layout import REEL_LENGTH, REEL_RATE
from multilift_sim.simulation import FormationSimulator

WINCH = {'rate_limit': 0.5, 'acceleration_limit': 0.5, 'min_length': 1.0, 'max_length': 6.0}


def _single_lift(events, duration: float, winch=None, **changes) -> scenario_io.Scenario:
    """single_lift held in hover with a winch on its UAV and these `events`."""
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['uavs'][0]['winch'] = dict(winch or WINCH)
    data['events'] = events
    data['simulation']['duration'] = duration
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': duration}]
    for key, value in changes.items():
        data[key].update(value)
    return scenario_io.loads(yaml.safe_dump(data))


def _reels(scenario) -> tuple[np.ndarray, np.ndarray]:
    """The cable's (length, rate) at every tick of a run tick by tick."""
    rows = []
    run_headless(scenario, on_tick=lambda sim, *_: rows.append(sim.memory.reel[0, 0].copy()))
    rows = np.array(rows)
    return rows[:, REEL_LENGTH], rows[:, REEL_RATE]


def test_a_reel_keeps_its_rate_and_acceleration_limits_and_stops_at_its_stop():
    """A command of 2 m/s beyond the 0.5 m/s limit: the reel speeds up at 0.5 m/s^2, runs at
    0.5 m/s, brakes onto max_length 3.5 m and rests there; then hauls in to min_length."""
    s = _single_lift([{'time': 0.5, 'type': 'winch_rate', 'uav': 1, 'rate': 2.0},
                      {'time': 9.0, 'type': 'winch_rate', 'uav': 1, 'rate': -2.0}], 16.0,
                     winch=dict(WINCH, max_length=3.5, min_length=2.0))
    length, rate = _reels(s)
    dt = 0.01
    assert np.abs(rate).max() == pytest.approx(0.5, abs=1e-12)
    # |l_ddot| <= 0.5 m/s^2: a T a period, but for the arrival at the stop (the last 0.5 %)
    assert np.abs(np.diff(rate)).max() <= 1.01 * 0.5 * dt
    assert length.max() == pytest.approx(3.5, abs=1e-12) and length.max() <= 3.5
    assert length.min() >= 2.0 and length[-1] == pytest.approx(2.0, abs=1e-12)
    t = np.arange(1, len(length) + 1) * dt
    at_stop = t[np.argmax(length >= 3.5 - 1e-12)]
    # from t = 0.5 s: 1 s of ramp to 0.5 m/s (0.25 m), 1 s at it, 1 s of braking (0.25 m):
    # 1 m, at the stop at t = 3.5 s (a few periods later: braking decided once a period)
    assert 3.5 <= at_stop < 3.55
    assert rate[(t > at_stop) & (t < 9.0)].max() == 0.0


def test_paying_out_keeps_the_energy_balance_of_a_falling_single_lift():
    """Rotors all but off, no drag: the pair falls freely and the payload circles the UAV at
    1 m/s, the cable central, so the relative motion keeps its angular momentum L = mu |d x
    d_dot| (mu the reduced mass). Paying out 0.3 m/s for 3 s (0.6 s ramps at 0.5 m/s^2) moves
    the cable from l_a to l_b = l_a + 0.9 m; the winch does the work W = -int T l_dot dt with
    T = mu (L^2 / (mu^2 l^3) - l_ddot), which is L^2 / (2 mu) (1/l_b^2 - 1/l_a^2) between
    rests. The energy of the relative motion, mu |d_dot|^2 / 2 (gravity moves only the centre
    of mass), changes by W to 1e-6 relative."""
    s = _single_lift([{'time': 0.5, 'type': 'winch_rate', 'uav': 1, 'rate': 0.3},
                      {'time': 3.5, 'type': 'winch_rate', 'uav': 1, 'rate': 0.0}], 5.0,
                     control={'mode': 'constant_rotor_speed', 'constant_rotor_speed': 1e-3},
                     payload={'drag_coefficient': 0.0, 'initial_velocity': [1.0, 0.0, 0.0]})
    m, m_p = s.uavs[0].vehicle.mass, s.payload.mass
    mu = m * m_p / (m + m_p)
    layout = StateLayout(1)
    states = [FormationSimulator(s).state.copy()]
    run_headless(s, on_tick=lambda sim, *_: states.append(sim.state.copy()))
    d = np.array([layout.payload_position(x) - layout.uav_positions(x)[0] for x in states])
    d_dot = np.array([layout.payload_velocity(x) - layout.uav_velocities(x)[0]
                      for x in states])
    momentum = mu * np.linalg.norm(np.cross(d, d_dot), axis=1)
    energy = 0.5 * mu * np.sum(d_dot ** 2, axis=1)
    np.testing.assert_allclose(momentum, momentum[0], rtol=1e-7)   # a central force
    l_a, l_b = s.uavs[0].cable_length, s.uavs[0].cable_length + 0.9
    assert np.linalg.norm(d[-1]) == pytest.approx(l_b, abs=1e-6)
    work = momentum[0] ** 2 / (2.0 * mu) * (1.0 / l_b ** 2 - 1.0 / l_a ** 2)
    assert energy[-1] - energy[0] == pytest.approx(work, rel=1e-6)
    assert work < -0.05   # paying out slows the circling: the winch takes energy out


def test_winch_lower_pays_out_3_m_and_the_payload_follows_without_saturating():
    """The twin-lift's winches pay out 0.3 m/s from 100 s to 110 s: each cable 3 m longer (the
    ramps at either end cancel), the payload 3 m further below its UAVs less the geometry's
    (sqrt(l^2 - (d/2)^2) for cables l from UAVs d apart), max|g| within the tolerance, and the
    lowering saturates no rotor: the saturated time is twin_lift's (its corners) over the
    same 120 s."""
    s = scenario_io.load('winch_lower')
    lowered = fly(s)
    sim = lowered.summary()['sim']
    assert sim['longest_cable'] == pytest.approx([13.26, 13.26], abs=1e-9)
    assert sim['shortest_cable'] == pytest.approx([10.26, 10.26], abs=1e-12)
    assert sim['max_abs_constraint'] < s.simulation.constraint_tolerance
    twin = fly(scenario_io.load('twin_lift')).summary()['sim']
    assert sim['saturated_time'] == pytest.approx(twin['saturated_time'], abs=0.011)
    x = lowered.engine.state[0]
    layout = StateLayout(2)
    uavs, payload = layout.uav_positions(x), layout.payload_position(x)
    half = 0.5 * np.linalg.norm(uavs[0, :2] - uavs[1, :2])
    below = uavs[:, 2].mean() - payload[2]
    assert below == pytest.approx(math.sqrt(13.26 ** 2 - half ** 2), abs=0.02)


@pytest.mark.parametrize('change,message', [
    ({'winch': dict(WINCH, min_length=-1.0)}, 'min_length: -1.0 must be > 0'),
    ({'winch': dict(WINCH, min_length=3.0)}, "must hold the cable's length 2.5 m"),
    ({'winch': dict(WINCH, max_length=0.5)}, 'max_length: 0.5 must be >= min_length'),
    ({'winch': dict(WINCH, rate_limit=0.0)}, 'rate_limit: 0.0 must be > 0'),
    ({'winch': dict(WINCH, reel=1.0)}, 'uavs[0].winch.reel: unknown key'),
])
def test_a_bad_winch_is_one_line(change, message):
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data['uavs'][0].update(change)
    with pytest.raises(scenario_io.ScenarioError, match='^[^\n]*$') as error:
        scenario_io.loads(yaml.safe_dump(data))
    assert message in str(error.value)


def test_a_reel_rate_for_a_uav_without_a_winch_and_unsupported_models_are_refused():
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    data['uavs'][0]['winch'] = dict(WINCH, max_length=12.0)
    data['events'] = [{'time': 1.0, 'type': 'winch_rate', 'uav': 2, 'rate': 0.1}]
    with pytest.raises(scenario_io.ScenarioError, match=r'uav: 2 has no winch \(uavs\[1\]'):
        scenario_io.loads(yaml.safe_dump(data))
    data['events'] = []
    for key, value, message in (
            ('cable_model', 'slack',
             'reels rigid, elastic or chain cables, not cable_model: slack'),
            ('simulation', dict(data['simulation'], integrator='nullspace'),
             'uavs[i].winch needs simulation.integrator: baumgarte')):
        with pytest.raises(scenario_io.ScenarioError, match='^[^\n]*$') as error:
            scenario_io.loads(yaml.safe_dump(dict(data, **{key: value})))
        assert message in str(error.value)


def test_a_reeled_run_compiled_equals_its_uncompiled_source(monkeypatch):
    """The winch's arithmetic compiled and run by Python (MULTILIFT_KERNEL=python): within
    1e-9 m over a second of paying out, the elastic rope's and a chain's too."""
    events = [{'time': 0.2, 'type': 'winch_rate', 'uav': 1, 'rate': 0.4}]
    for cable in ({}, {'cable_model': 'elastic', 'cable': {'axial_stiffness': 2e4}},
                  {'cable_model': 'chain', 'cable': {'links': 5, 'mass_per_length': 0.1}}):
        s = _single_lift(events, 1.2)
        if cable:
            data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
            data['uavs'][0]['winch'] = WINCH
            data.update(events=events, **cable)
            data['simulation'].update(duration=1.2, substeps=4)   # checked at min_length
            s = scenario_io.loads(yaml.safe_dump(data))
        monkeypatch.setenv('MULTILIFT_KERNEL', 'auto')
        compiled = run_headless(s).simulator.state
        monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
        python = run_headless(s).simulator.state
        assert np.abs(compiled - python).max() < 1e-9
        layout = StateLayout(1, chain_nodes=cable.get('cable', {}).get('links', 1) - 1)
        stretch = np.linalg.norm(layout.payload_position(compiled)
                                 - layout.uav_positions(compiled)[0])
        assert stretch > s.uavs[0].cable_length + 0.2    # paid out 0.24 m (a 0.8 s ramp)


def test_a_winched_bag_carries_the_lengths_and_plots_them(tmp_path):
    """The headless bag's /uav1/cable_length is the reel's length at every tick, which
    `multilift plot` draws (cable_lengths.png) and the rope figure is skipped for."""
    from multilift_tools.bagdata import load_run
    from multilift_tools.figures import plot_main
    from multilift_tools.headless_bag import record_headless
    s = _single_lift([{'time': 0.5, 'type': 'winch_rate', 'uav': 1, 'rate': 0.3}], 3.0)
    record_headless(s, tmp_path / 'bag')
    t, lengths = load_run(tmp_path / 'bag').cable_lengths(1)
    reel, _ = _reels(s)
    np.testing.assert_array_equal(lengths, reel)          # every tick's, t = 0 to t_max
    assert lengths[0] == 2.5 and lengths[-1] > 2.5 + 0.5 and t[-1] == pytest.approx(3.0)
    assert plot_main([str(tmp_path / 'bag'), '--out', str(tmp_path / 'plots')]) == 0
    assert (tmp_path / 'plots' / 'cable_lengths.png').stat().st_size > 0


def test_an_elastic_rope_s_stepping_is_checked_at_the_winch_s_shortest_length():
    """EA / l grows as the winch hauls in: a rope stepped well enough at its length is refused
    when its winch may reel it to a fifth of it (omega h times sqrt 5), naming the sub-steps."""
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data.update(cable_model='elastic', cable={'axial_stiffness': 2e4})
    data['simulation']['substeps'] = 4                            # omega h = 0.25
    scenario_io.loads(yaml.safe_dump(data))                       # flies without a winch
    data['uavs'][0]['winch'] = dict(WINCH, min_length=0.5)        # 5x stiffer: omega h 0.56
    with pytest.raises(scenario_io.ScenarioError, match='set simulation.substeps >= '):
        scenario_io.loads(yaml.safe_dump(data))


def test_the_foxglove_layout_plots_each_winch_s_length_only_where_there_are_winches():
    from multilift_tools.foxglove.layout import layout
    plot = layout(scenario_io.load('winch_lower'))['configById']['Plot!winches']
    assert [p['value'] for p in plot['paths']] == ['/uav1/cable_length.data',
                                                   '/uav2/cable_length.data']
    assert {p['timestampMethod'] for p in plot['paths']} == {'receiveTime'}   # no header
    assert 'Plot!winches' not in layout(scenario_io.load('twin_lift'))['configById']


def test_a_rigid_beam_is_lowered_on_its_reeled_cables():
    """beam_lift's two winches pay out 0.2 m/s for 10 s in a hover: each cable 2 m longer
    (the ramps cancel), the beam (a rigid body, its cables at its ends) lowered with them, the
    reeled constraint |d_i|^2 = l_i(t)^2 held within 1e-3 m^2."""
    data = yaml.safe_load((SCENARIOS / 'beam_lift.yaml').read_text())
    for uav in data['uavs']:
        uav['winch'] = dict(WINCH, min_length=2.0, max_length=15.0)
    data['simulation']['duration'] = 30.0
    data['mission']['segments'] = [{'velocity': [0.0, 0.0, 0.0], 'until': 30.0}]
    data['events'] = [{'time': t, 'type': 'winch_rate', 'uav': i, 'rate': rate}
                      for t, rate in ((5.0, 0.2), (15.0, 0.0)) for i in (1, 2)]
    s = scenario_io.loads(yaml.safe_dump(data))
    start = FormationSimulator(s).state.copy()
    run = fly(s)
    sim = run.summary()['sim']
    length = s.uavs[0].cable_length
    assert sim['longest_cable'] == pytest.approx([length + 2.0] * 2, abs=1e-9)
    assert sim['max_abs_constraint'] < 1e-3
    layout = StateLayout(2)

    def below(x):
        return layout.uav_positions(x)[:, 2].mean() - layout.payload_position(x)[2]
    # 2 m for vertical cables; a cable leaning h off its end drops sqrt(l_1^2 - h^2) -
    # sqrt(l_0^2 - h^2), more (beam_lift's UAVs stand outside its ends: 2.07 m)
    assert 2.0 <= below(run.engine.state[0]) - below(start) < 2.2


def test_a_stamped_reel_rate_takes_effect_at_the_first_tick_of_its_stamp():
    """`command_winch(..., at_ns)` (a live /uav{i}/winch_cmd_stamped): a stamp of 0.505 s
    sent at t = 0.1 s reels from tick 51 (the first at or after it), none before; a stamp
    already past acts at once; a UAV without a winch is a ValueError."""
    s = _single_lift([], 1.0)
    taken, lengths = [], []

    def each(sim, *_):
        if sim.tick == 10:
            taken.append(sim.command_winch(0, 0.4, at_ns=505_000_000))
            taken.append(sim.command_winch(0, 0.0, at_ns=50_000_000))
            with pytest.raises(ValueError, match='uav2 has no winch'):
                sim.command_winch(1, 0.4)
        lengths.append(sim.memory.reel[0, 0, REEL_LENGTH])
    run_headless(s, on_tick=each)
    assert taken == [51, 10]
    lengths = np.array(lengths)   # lengths[k]: at tick k, the period from tick 51 reels
    assert np.all(lengths[:52] == 2.5)
    assert lengths[52] - 2.5 == pytest.approx(0.5 * 0.5 * 0.01 ** 2, rel=1e-9)
