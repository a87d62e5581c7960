"""Faults and what the controllers do about them (multilift_control.faults, issue 21): the
reallocated mixer gives the wrench the UAV asks for over its other rotors; `hexa_rotor_failure`
flies its mission after its leader loses a rotor, where a leader unaware of the fault loses the
formation; after a release the formation's new offsets keep the payload's rest place and
`v3_uav_loss`'s twin-lift left delivers the payload (where the old offsets let it drift); the
engine and the per-object (ROS) path act at the same tick, to the bit."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from multilift_control.cascade import RotorMixer
from multilift_control.engine import Engine
from multilift_control.faults import RELEASE_TRANSITION, release_targets, target_schedule
from multilift_control.virtual_constraints import FormationGeometry, VirtualConstraints
from multilift_control.engine.arrays import FINISHED, NOT_FINITE
from multilift_control.headless import run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.allocation import allocation_matrix
from multilift_sim.formation_params import StateLayout
from multilift_sim.formation_geometry import hanging_payload


@pytest.mark.parametrize('frame_type', ['hexa_x', 'hexa_plus', 'octo_x', 'octo_plus'])
def test_the_reallocated_mixer_gives_the_wrench_over_the_other_rotors(frame_type):
    vehicle = dataclasses.replace(scenario_io.load('twin_lift').uavs[0].vehicle,
                                  frame_type=frame_type, rotor_speed_max=3000.0)
    effectiveness = np.ones(vehicle.n_rotors)
    effectiveness[0] = 0.0
    mixer = RotorMixer(vehicle, effectiveness)
    matrix = allocation_matrix(frame_type, vehicle.arm_length, vehicle.thrust_coefficient,
                               vehicle.moment_coefficient) * effectiveness
    # the rotor the reallocation pins at omega_min: live, no collective share
    pinned = (np.abs(mixer.pinv).sum(axis=1) > 0) & (mixer.collective <= 0)
    for wrench in ([30.0, 0.0, 0.0, 0.0], [30.0, 0.4, -0.3, 0.05], [25.0, -0.2, 0.5, -0.05]):
        speeds, saturated = mixer.rotor_speeds(wrench[0], np.array(wrench[1:]))
        assert speeds[0] == vehicle.rotor_speed_min and not saturated[0]  # left out
        assert not saturated[pinned].any()  # pinned, not saturated (issue 37)
        if not saturated.any() and np.all(speeds[pinned] > vehicle.rotor_speed_min):
            # nothing held at a limit: what the other rotors give is the wrench asked for
            assert matrix @ speeds ** 2 == pytest.approx(wrench, abs=1e-9)
    hover, _ = mixer.rotor_speeds(30.0, np.zeros(3))
    assert matrix @ hover ** 2 == pytest.approx([30.0, 0, 0, 0], abs=1e-9)
    intact = RotorMixer(vehicle)
    assert np.array_equal(RotorMixer(vehicle, np.ones(vehicle.n_rotors)).rows, intact.rows)


def test_hexa_rotor_failure_flies_its_mission_where_an_unaware_leader_does_not():
    scenario = scenario_io.load('hexa_rotor_failure')
    assert [(e.type, e.uav, e.rotor, e.effectiveness) for e in scenario.events] == [
        ('rotor_effectiveness', 1, 1, 0.0)]
    runs = {}
    for name, events, aware in (('aware', scenario.events, True), ('intact', (), True),
                                ('unaware', scenario.events, False)):
        engine = Engine(dataclasses.replace(scenario, events=events))
        if not aware:  # the leader's mixer never learns of the fault
            engine.arrays.fault_mixers[0, 0] = engine.memory.mixers[0, 0]
        engine.step(10 ** 6)
        runs[name] = (engine.memory.status[0], engine.summary(0))
    (status, aware), (_, intact) = runs['aware'], runs['intact']
    assert status == FINISHED
    sim = aware['sim']
    assert sim['max_abs_constraint'] < scenario.simulation.constraint_tolerance
    assert max(sim['max_rotor_speed']) < scenario.uavs[0].vehicle.rotor_speed_max
    # tracking within 30 % of the intact hexa's (measured: rms 0.087 against 0.068 m)
    assert aware['leader']['rms_tracking_error'] < 1.3 * intact['leader']['rms_tracking_error']
    assert aware['leader']['max_tracking_error'] < 1.3 * intact['leader']['max_tracking_error']
    assert sim['events'][0]['description'] == 'uav1 rotor 1 at 0 % of its thrust'
    status, unaware = runs['unaware']
    assert status == NOT_FINITE or unaware['leader']['rms_tracking_error'] > 10.0


def _both_paths(name: str, duration: float):
    """`name` flown `duration` [s] by the engine and by the per-object path (the ROS nodes'
    objects, `run_headless`): (engine, run), their states equal to the bit."""
    scenario = scenario_io.load(name).with_duration(duration)
    engine = Engine(scenario)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert np.array_equal(engine.state[0], run.simulator.state)
    return scenario, engine, run


def test_the_engine_and_the_ros_path_reallocate_alike():
    _, engine, run = _both_paths('hexa_rotor_failure', 30.2)
    assert np.array_equal(engine.memory.mixers[0, 0], run.runtimes[0].leader.cascade.mixer.rows)
    assert not np.array_equal(engine.memory.mixers[0, 0], engine._initial.mixers[0, 0])


def test_a_release_gives_the_formation_new_offsets():
    """v3_uav_loss: UAV 3 flies clear, 4 m farther out; UAV 2 moves so that the
    payload's rest place under the twin left is the one it had under the three
    (formation_geometry.hanging_payload of both nominal formations)."""
    scenario = scenario_io.load('v3_uav_loss')
    constraints = VirtualConstraints(FormationGeometry.from_config(scenario.formation, 3))
    before = np.array(constraints.targets).reshape(2, 3)      # r_1 - r_i, i = 2, 3
    after = release_targets(scenario)[0].reshape(2, 3)
    lengths = [u.cable_length for u in scenario.uavs]
    _, rest_three = hanging_payload(np.vstack([np.zeros(3), -before]), lengths)
    _, rest_two = hanging_payload(np.vstack([np.zeros(3), -after[0]]), lengths[:2])
    assert rest_two[:2] == pytest.approx(rest_three[:2], abs=1e-12)
    assert np.hypot(*after[1, :2]) == pytest.approx(np.hypot(*before[1, :2]) + 4.0)
    assert after[1, 2] == before[1, 2]
    # on their way there along a smoothstep of RELEASE_TRANSITION from the release's tick
    schedule = target_schedule(scenario)
    ramp = int(RELEASE_TRANSITION * scenario.simulation.control_rate)
    assert schedule[:, 0].tolist() == list(range(6000, 6000 + ramp))
    assert np.array_equal(schedule[-1, 1:], after.reshape(-1))
    middle = schedule[ramp // 2 - 1, 1:]
    assert middle == pytest.approx((before + after).reshape(-1) / 2.0)
    cross = after[1, 0] * before[1, 1] - after[1, 1] * before[1, 0]
    assert cross == pytest.approx(0.0, abs=1e-12)  # along the same bearing, outward


def _payload_path_distance(record, scenario, n):
    """Horizontal distance [m] of the payload from its path: the leader's reference plus the
    payload's place relative to the leader at the start (tick by tick)."""
    states = record.states[:, 0]
    payload = StateLayout(n).payload_position(states)[:, :2]
    reference = record.reference[:, 0, :2]
    start = payload[0] - states[0, :2]
    return np.hypot(*(payload - reference - start).T)


def test_v3_uav_loss_the_twin_left_delivers_the_payload():
    scenario = scenario_io.load('v3_uav_loss')
    engine = Engine(scenario)
    record = engine.new_record(scenario.simulation.tick_count)
    engine.step(scenario.simulation.tick_count, record)
    assert engine.memory.status[0] == FINISHED
    sim = engine.summary(0)['sim']
    assert sim['max_abs_constraint'] < scenario.simulation.constraint_tolerance
    assert max(sim['saturated_time']) < 0.5  # no rotor saturated over 0.5 s
    t = np.arange(scenario.simulation.tick_count) / scenario.simulation.control_rate
    away = _payload_path_distance(record, scenario, 3)
    settled = (t >= 70.0) & (t < 100.0)  # 10 s after the release, to the last corner
    assert away[settled].max() < 1.0
    # the two cables left share the weight in the final hover; UAV 3 out of the way
    tension = record.tension[(t >= 115.0), 0]
    assert np.abs(tension[:, 0] - tension[:, 1]).max() < 0.1 * tension[:, :2].sum(axis=1).min()
    assert (tension[:, 2] == 0.0).all()
    uavs = StateLayout(3).uav_positions(engine.state[0])
    assert np.hypot(*(uavs[2, :2] - uavs[0, :2])) > 7.5  # 4 m farther out than the V's 4
    # the formation's new offsets are what did it: without them the payload drifts away
    kept = Engine(scenario)
    kept.arrays.target_schedule[0, :, 1:] = kept.memory.targets[0]
    kept_record = kept.new_record(scenario.simulation.tick_count)
    kept.step(scenario.simulation.tick_count, kept_record)
    assert _payload_path_distance(kept_record, scenario, 3)[settled].max() > 1.0


def test_the_engine_and_the_ros_path_take_the_new_offsets_alike():
    scenario, engine, run = _both_paths('v3_uav_loss', 60.3)
    schedule = target_schedule(scenario)  # the controllers answered the state at tick 6029
    for runtime in run.runtimes[1:]:
        assert np.array_equal(runtime.follower.constraints.targets, schedule[29, 1:])
    assert schedule[30, 0] == 6030 and np.array_equal(engine.memory.targets[0],
                                                        schedule[30, 1:])
