"""The scenarios of issue 34 item 6 and contact (item 5), flown headless: `window` (two
Crazyflies turn edge on through a window 30 % or more narrower than their separation) and
`forest` (three through rows of trees) without contact, their least clearance at least
0.05 m as the summary gives it, through the window and past the trees; the per-object path
(FormationSimulator) and the engine measure the same clearances (one tick); a scenario built
to collide stops with one line naming what touched what and when (its exit 1 from `multilift
run`, ROS and headless: tests/ros/test_obstacles_ros.py), and with `world.on_contact: record`
flies on with the contact in its summary."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest import collide_scenario
from multilift_control.headless import fly, run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.physics.state_slots import payload_slot
from multilift_sim.simulation import SimulationStopped

pytest.importorskip('numba')
SCENARIOS = Path(__file__).resolve().parents[2] / 'scenarios'
KINDS = {'uav_world', 'cable_world', 'payload_world', 'uav_uav', 'uav_cable'}


@pytest.mark.parametrize('name', ['window', 'forest'])
def test_flies_through_without_contact(name):
    scenario = scenario_io.load(name)
    run = fly(scenario)
    sim = run.summary()['sim']
    assert run.error is None and sim['contact'] is None
    assert sim['simulated_time'] == pytest.approx(scenario.simulation.duration)
    assert set(sim['clearance']) == KINDS  # a point payload: no cable - cable pair
    assert sim['least_clearance'] == min(k['value'] for k in sim['clearance'].values())
    assert sim['least_clearance'] >= 0.05, sim['clearance']
    # past the obstacles: the payload beyond the last of them, the nearest one met on the way
    state = run.engine.memory.state[0]
    last = max(o.center[0] for o in scenario.world.obstacles)
    assert state[payload_slot(scenario.n_uavs)] > last + 0.5
    assert sim['clearance']['uav_world']['between'][1].startswith("obstacle '")


def test_the_window_is_30_percent_narrower_than_the_formation_side_by_side():
    scenario = scenario_io.load('window')
    walls = {o.name: o for o in scenario.world.obstacles}
    width = ((walls['wall_left'].center[1] - walls['wall_left'].half[1])
             - (walls['wall_right'].center[1] + walls['wall_right'].half[1]))
    # the separation side by side as flown: hovering at the start, before the turn
    run = run_headless(scenario_io.from_mapping(
        dict(yaml.safe_load((SCENARIOS / 'window.yaml').read_text()),
             simulation=dict(yaml.safe_load((SCENARIOS / 'window.yaml').read_text())[
                 'simulation'], duration=2.0)), str(SCENARIOS / 'window.yaml')))
    state = run.simulator.memory.state[0]
    separation = np.linalg.norm(state[0:3] - state[3:6])
    assert width == pytest.approx(0.30) and width <= 0.7 * separation, (width, separation)


def test_the_object_path_measures_what_the_engine_does():
    scenario = scenario_io.load('window')
    engine = fly(scenario).summary()['sim']
    flown = run_headless(scenario).summary()['sim']
    assert flown['clearance'] == engine['clearance']
    assert flown['least_clearance'] == engine['least_clearance']


def test_a_contact_stops_the_run_naming_what_touched_what_and_when(tmp_path):
    scenario = scenario_io.from_mapping(collide_scenario('stop'), str(tmp_path / 'collide.yaml'))
    with pytest.raises(SimulationStopped) as stopped:
        fly(scenario)
    message = str(stopped.value)
    assert message.startswith("contact: uav1 touched obstacle 'pillar' at t = ")
    # the UAV's sphere reaches the pillar when its centre is 0.16 m from the axis: x = 0.84 m
    # on a path along x, which the leader's reference passes at about 1.9 s
    t = float(message.split('t = ')[1].split(' s')[0])
    assert 1.5 < t < 2.3, message
    assert '\n' not in message  # `multilift run` prints it as one line, exit 1: tests/ros


def test_on_contact_record_flies_on_and_records_the_first_contact(tmp_path):
    stopping = scenario_io.from_mapping(collide_scenario('stop'), str(tmp_path / 'a.yaml'))
    recording = scenario_io.from_mapping(collide_scenario('record'), str(tmp_path / 'b.yaml'))
    with pytest.raises(SimulationStopped) as stopped:
        fly(stopping)
    run = fly(recording)
    sim = run.summary()['sim']
    assert run.error is None and sim['simulated_time'] == pytest.approx(6.0)
    contact = sim['contact']
    assert contact['between'] == ['uav1', "obstacle 'pillar'"] and contact['value'] <= 0.0
    assert f"t = {contact['time']:.3f} s" in str(stopped.value)
    # flown on through the pillar: the cables and the payload passed through it too
    assert sim['clearance']['cable_world']['value'] < 0.0
    assert sim['clearance']['payload_world']['value'] < 0.0
    assert sim['least_clearance'] < -0.1
