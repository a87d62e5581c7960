"""What a run's summary counts (issue 37): saturation is a rotor held at a limit the allocator
wanted it beyond (not a failed rotor, not one the reallocation pins at its minimum, not one a
collective shift brought inside), a pushing cable is a warning and `compressed_time`, and the
payload swing is measured from SWING_FROM on (not the release every twin-lift starts with)."""
from __future__ import annotations

import io
from contextlib import redirect_stdout

import numpy as np

from multilift_control.cascade import RotorMixer
from multilift_control.headless import fly
from multilift_sim import scenario as scenario_io
from multilift_sim.statistics.layout import SWING_FROM
from multilift_tools.run_summary import print_summary


def _hexa():
    return scenario_io.load('hexa_rotor_failure').uavs[0].vehicle


def test_a_shift_that_fits_saturates_nothing_and_a_clipped_rotor_is_flagged():
    vehicle = _hexa()
    mixer = RotorMixer(vehicle)
    hover = vehicle.mass * 9.81
    # a roll torque that pushes one side above omega_max at this thrust, within the range's
    # width: the collective shift fits it, no rotor ends beyond a limit
    speeds, saturated = mixer.rotor_speeds(1.9 * hover, np.array([0.25, 0.0, 0.0]))
    assert speeds.max() <= vehicle.rotor_speed_max + 1e-9
    assert np.isclose(speeds.max(), vehicle.rotor_speed_max)  # the shift set one at the limit
    flagged = np.flatnonzero(saturated)
    assert set(flagged) <= set(np.flatnonzero(np.isclose(speeds, vehicle.rotor_speed_max)))
    # thrust beyond every rotor's limit: all held at omega_max, all wanted beyond it
    speeds, saturated = mixer.rotor_speeds(50.0 * hover, np.zeros(3))
    assert saturated.all() and np.allclose(speeds, vehicle.rotor_speed_max)
    # a request inside the range flags nothing
    assert not mixer.rotor_speeds(hover, np.zeros(3))[1].any()


def test_a_failed_and_a_pinned_rotor_are_not_saturation():
    vehicle = _hexa()
    effectiveness = np.ones(vehicle.n_rotors)
    effectiveness[2] = 0.0
    mixer = RotorMixer(vehicle, effectiveness)
    pinned = np.flatnonzero((np.abs(mixer.pinv).sum(axis=1) > 0) & (mixer.collective <= 0))
    assert len(pinned) == 1  # the failed rotor's opposite carries no thrust share
    speeds, saturated = mixer.rotor_speeds(vehicle.mass * 9.81, np.array([0.0, 0.0, 0.05]))
    assert np.isclose(speeds[pinned[0]], vehicle.rotor_speed_min)  # held at its minimum
    assert not saturated[2] and not saturated[pinned[0]]


def test_the_hexa_s_summary_names_the_failed_and_pinned_rotors_apart_from_saturation():
    scenario = scenario_io.load('hexa_rotor_failure')
    summary = fly(scenario).summary()
    sim = summary['sim']
    limit = scenario.uavs[0].vehicle.rotor_speed_max
    # its fastest rotor stays below omega_max: what saturation remains is a rotor at omega_min
    # wanted below it; the 88.85 s of the old count were the pinned rotor's
    assert sim['max_rotor_speed'][0] < limit
    assert sim['saturated_time'][0] < 5.0, sim['saturated_time']
    out = io.StringIO()
    with redirect_stdout(out):
        print_summary(scenario.name, summary, None, scenario)
    text = out.getvalue()
    assert 'pinned at its minimum speed by the reallocation' in text
    assert 'effectiveness 0 from' in text


def test_the_swing_is_measured_after_the_release_and_a_pushing_cable_is_a_warning():
    base = scenario_io.load('twin_lift')
    early = fly(base.with_duration(SWING_FROM - 1.0)).summary()['sim']
    assert early['max_payload_swing'] == 0.0  # nothing sampled before SWING_FROM
    late = fly(base.with_duration(SWING_FROM + 5.0)).summary()['sim']
    assert 0.0 < late['max_payload_swing'] < 1.0  # not the release's 2.6 m
    assert late['compressed_time'] == 0.0 and late['min_tension'] > 0.0
    # twin_lift_sensors' noisy follower makes a rigid cable push (issue 37: -1.87 N without
    # a word): a warning line and the time it pushed
    scenario = scenario_io.load('twin_lift_sensors')
    summary = fly(scenario).summary()
    sim = summary['sim']
    assert sim['min_tension'] < 0.0
    assert 0.0 < sim['compressed_time'] < sim['simulated_time']
    out = io.StringIO()
    with redirect_stdout(out):
        print_summary(scenario.name, summary, None, scenario)
    assert f'warning: a cable pushed for {sim["compressed_time"]:.2f} s' in out.getvalue()


def test_a_released_cable_leaves_the_swing_to_the_cables_that_hold_the_payload():
    """v3_uav_loss: UAV 3 lets go at 60 s and flies clear; the swing is the payload's distance
    from its rest place under the UAVs that still hold it (it was 3.29 m max, 1.76 m rms with
    the released UAV's place counted; measured 1.09 m max while the two left reorganise)."""
    sim = fly(scenario_io.load('v3_uav_loss')).summary()['sim']
    assert 0.0 < sim['max_payload_swing'] < 1.5, sim['max_payload_swing']
    assert sim['rms_payload_swing'] < 0.5, sim['rms_payload_swing']


def test_three_taut_cables_leave_no_swing_and_the_summary_says_why():
    """multi_lift's V of three: the three cables meet at one point under the UAVs, so the
    payload's rest place is where it is and the swing reads 0.000 m; the summary says why
    (a twin-lift's payload swings, and its summary has no such line)."""
    lines = {}
    for name in ('multi_lift', 'twin_lift'):
        scenario = scenario_io.load(name).with_duration(SWING_FROM + 5.0)
        out = io.StringIO()
        with redirect_stdout(out):
            print_summary(scenario.name, fly(scenario).summary(), None, scenario)
        lines[name] = out.getvalue()
    assert 'payload swing    max 0.000 m' in lines['multi_lift']
    assert 'three or more taut cables hold the payload' in lines['multi_lift']
    assert 'three or more taut cables' not in lines['twin_lift']
