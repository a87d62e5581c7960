"""A leader and a follower controller are registered parts (issue 31): a toy leader (holds a
fixed position, a PD on thrust) and a toy follower (holds its start offset to the leader, a
PD) defined in this file only. A scenario names this file under `parts:`; the processes that
read it import the file and register the two (pytest's own import leaves its worker's
registries alone): they compile into the one tick (multilift_control.controllers.compiled)
and fly headless (the engine's `fly`, the per-object `run_headless`: to the bit) and through
ROS (`multilift run`: the simulator node, our leader and follower nodes), to the headless
bag's trajectories to 1e-9 m. Held to what statics says, not read from the code: the
formation climbs to the held place, each UAV pulled inward by its cable as a PD leaves it, and
the payload settles where its two taut cables hang it below the UAVs.

The run's processes import this module: it imports no test helper at module level."""
from __future__ import annotations

import math
import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
import yaml

from multilift_control import controllers
from multilift_control.laws.cascade import command
from multilift_control.laws.layout import (CASCADE_THRUST_COEFFICIENT, REFERENCE_SIZE,
                                           UAV_POSITION, UAV_STATE_SIZE, UAV_VELOCITY)
from multilift_control.laws.mixer import collective_thrust
from multilift_sim.formation_params import StateLayout
from multilift_sim import scenario as scenario_io
from multilift_sim.kernels import jit
from multilift_sim.start import formation_start

ROOT = Path(__file__).resolve().parents[2]

# -- the toy leader: hold `hold_position` [m] with a PD on the thrust ----------------------
HOLD = 0        # (3) the place held, world [m]
KP = 3          # [1/s^2]
KD = 4          # [1/s]
MASS = 5        # the UAV and its payload share [kg]
GRAVITY = 6     # [m/s^2]
SIZE = 7


def _parse_hold(c):
    gains = c.vector('hold_gains', length=2, check=lambda v: v > 0, rule='must be > 0')
    return {'values': (('hold_position', c.vector('hold_position')), ('hold_gains', gains))}


def _hold_arrays(scenario, index):
    constants = np.empty(SIZE)
    constants[HOLD:HOLD + 3] = scenario.control.value('hold_position')
    constants[KP], constants[KD] = scenario.control.value('hold_gains')
    constants[MASS] = (scenario.uavs[index].vehicle.mass
                       + scenario.payload.mass / scenario.n_uavs)
    constants[GRAVITY] = scenario.simulation.gravity
    return constants, np.zeros(0)


@jit
def hold_answer(constants, memory, cascade, mixer, mission, segments, steps, t, states,
                payload_position, payload_velocity, speeds, saturated, setpoint, reference):
    force = np.empty(3)  # a PD on the thrust, gravity fed forward
    for k in range(3):
        force[k] = constants[MASS] * (
            constants[KP] * (constants[HOLD + k] - states[0, UAV_POSITION + k])
            - constants[KD] * states[0, UAV_VELOCITY + k]
            + (constants[GRAVITY] if k == 2 else 0.0))
    s, sat, attitude, thrust = command(cascade, mixer, states[0], force, 0.0)
    speeds[:] = s
    saturated[:] = sat
    setpoint[:] = attitude
    reference[:] = math.nan
    return collective_thrust(cascade[CASCADE_THRUST_COEFFICIENT], speeds)


HOLD_LEADER = types.SimpleNamespace(
    NAME='toy_hold', KEYS=('hold_position', 'hold_gains'), parse=_parse_hold,
    TRACKS_MISSION=False, arrays=_hold_arrays, answer=hold_answer)

# -- the toy follower: hold the start offset to the leader with a PD -----------------------
OFFSET = 0      # (3) r_i - r_1 at the start, world [m]
# KP, KD, MASS, GRAVITY as the leader's


def _parse_offset(c):
    gains = c.vector('offset_gains', length=2, check=lambda v: v > 0, rule='must be > 0')
    return {'values': (('offset_gains', gains),)}


def _offset_arrays(scenario, index):
    uavs, _ = formation_start(scenario)
    constants = np.empty(SIZE)
    constants[OFFSET:OFFSET + 3] = uavs[index] - uavs[0]
    constants[KP], constants[KD] = scenario.control.value('offset_gains')
    constants[MASS] = (scenario.uavs[index].vehicle.mass
                       + scenario.payload.mass / scenario.n_uavs)
    constants[GRAVITY] = scenario.simulation.gravity
    return constants, np.zeros(0), None, None  # no matrices


@jit
def offset_shared(constants, masses, rows, targets, states, vectors):
    return 0.0  # nothing shared


@jit
def offset_answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
                  targets, law_p, law_q, terms, speeds, saturated, setpoint, errors, rates):
    force = np.empty(3)
    for k in range(3):
        error = (states[0, UAV_POSITION + k] + constants[OFFSET + k]
                 - states[index, UAV_POSITION + k])
        rate = states[0, UAV_VELOCITY + k] - states[index, UAV_VELOCITY + k]
        force[k] = constants[MASS] * (constants[KP] * error + constants[KD] * rate
                                      + (constants[GRAVITY] if k == 2 else 0.0))
        if k < errors.shape[0]:
            errors[k] = error
            rates[k] = rate
    s, sat, attitude, thrust = command(cascade, mixer, states[index], force, 0.0)
    speeds[:] = s
    saturated[:] = sat
    setpoint[:] = attitude
    return collective_thrust(cascade[CASCADE_THRUST_COEFFICIENT], speeds)


OFFSET_FOLLOWER = types.SimpleNamespace(
    NAME='toy_offset', KEYS=('offset_gains',), parse=_parse_offset, arrays=_offset_arrays,
    shared=offset_shared, answer=offset_answer)


def register_parts() -> None:
    """Called by a scenario's `parts:` naming this file (the runs' processes), not by pytest's
    import."""
    controllers.register_leader(HOLD_LEADER)
    controllers.register_follower(OFFSET_FOLLOWER)


# -- the scenario: the twin lift holding a place 0.5 m above its start -----------------------
CLIMB = 0.5        # [m]
DURATION = 10.0    # [s]
GAIN = 4.0         # kp [1/s^2] and kd [1/s] of both toys
G = 9.81           # the scenario's gravity [m/s^2]


def _toy_yaml(path: Path, gains=(GAIN, GAIN), parts: bool = True) -> Path:
    data = yaml.safe_load((ROOT / 'scenarios' / 'twin_lift.yaml').read_text())
    if parts:
        data['parts'] = [os.path.relpath(__file__, path.parent)]
    data['simulation']['duration'] = DURATION
    data['payload']['swing_deg'] = 0.0
    data.pop('gusts')
    data['control'].update(mode='toy_hold', follower='toy_offset',
                           hold_position=[0.0, 0.0, CLIMB], hold_gains=list(gains),
                           offset_gains=list(gains))
    path.write_text(yaml.safe_dump(data))
    return path


def _equilibrium_error(scenario, state: np.ndarray) -> np.ndarray:
    """The payload's place minus where statics hangs it from the UAVs' places (two equal
    taut cables: below their midpoint by sqrt(l^2 - (d/2)^2)) [m]."""
    first, second = StateLayout(2).uav_positions(state)
    payload = StateLayout(2).payload_position(state)
    half = np.linalg.norm(second - first) / 2
    length = scenario.uavs[0].cable_length
    hanging = (first + second) / 2 - np.array([0.0, 0.0, math.sqrt(length ** 2 - half ** 2)])
    return payload - hanging


# fly and run_headless in a process that imports this file through the scenario's parts:
HEADLESS = """
import json, sys
from multilift_control.headless import fly, run_headless
from multilift_sim import scenario
toy = scenario.load(sys.argv[1])
flown, objects = fly(toy), run_headless(toy)
print(json.dumps([flown.engine.state[0].tolist(), objects.simulator.state.tolist(),
                  flown.summary()['follower2'], objects.summary()['follower2']]))
"""


def test_a_leader_and_a_follower_defined_here_fly_headless(tmp_path):
    import json
    bare = _toy_yaml(tmp_path / 'bare.yaml', parts=False)
    with pytest.raises(scenario_io.ScenarioError, match='control.mode.*must be one of'):
        scenario_io.load(str(bare))  # not a controller before it registers
    with controllers.registered(HOLD_LEADER, OFFSET_FOLLOWER):
        with pytest.raises(scenario_io.ScenarioError, match=r'hold_gains.*must be > 0'):
            scenario_io.load(str(_toy_yaml(tmp_path / 'bad.yaml', gains=(GAIN, -1.0),
                                           parts=False)))
        scenario = scenario_io.load(str(bare))
    with pytest.raises(scenario_io.ScenarioError, match='control.mode.*must be one of'):
        scenario_io.load(str(bare))  # gone again
    assert 'toy_hold' not in controllers.LEADER_CONTROLLERS  # pytest's import registered none
    out = subprocess.run([sys.executable, '-c', HEADLESS, str(_toy_yaml(tmp_path / 'toy.yaml'))],
                         capture_output=True, text=True, timeout=1200)
    assert out.returncode == 0, out.stderr[-3000:]
    state, object_state, *summaries = json.loads(out.stdout.splitlines()[-1])
    state = np.array(state)
    np.testing.assert_array_equal(state, object_state)  # both paths, to the bit
    assert summaries[0] == summaries[1]
    start, payload_start = formation_start(scenario)
    # at rest each cable pulls its UAV inward by T_h = (m_p g / 2) (d / 2) / h (d the UAVs'
    # distance, h the payload's depth below them), which a PD without an integral leaves as a
    # horizontal offset T_h / (m kp); the vertical share of the weight is fed forward
    (leader, follower), payload = (StateLayout(2).uav_positions(state),
                                   StateLayout(2).payload_position(state))
    inward = (follower - leader)[:2] / np.linalg.norm((follower - leader)[:2])
    depth = (leader[2] + follower[2]) / 2 - payload[2]
    pull = (scenario.payload.mass * G / 2) * (np.linalg.norm((follower - leader)[:2]) / 2) / depth
    offset = pull / ((scenario.uavs[0].vehicle.mass + scenario.payload.mass / 2) * GAIN)
    assert 0.05 < offset < 0.1  # what is checked is not nothing
    assert abs(leader[2] - CLIMB) < 0.005, leader  # the leader climbed to the place held
    np.testing.assert_allclose(leader[:2] - start[0, :2], offset * inward, atol=0.005)
    # the follower kept its offset to the leader, but for its own pull toward the leader
    np.testing.assert_allclose((follower - leader)[:2] - (start[1] - start[0])[:2],
                               -offset * inward, atol=0.005)
    # and the payload hangs where statics puts it, 0.5 m higher than it started
    assert np.linalg.norm(_equilibrium_error(scenario, state)) < 0.005
    assert payload[2] - payload_start[2] > 0.9 * CLIMB


def test_the_toys_fly_through_ros_as_headless(multilift_run, tmp_path):
    from conftest import flown_alike  # (here: a scenario's `parts:` imports this file too)
    ros, _ = flown_alike(multilift_run, _toy_yaml(tmp_path / 'toy.yaml'), tmp_path)
    # the toys flew it: the leader climbed to the place held
    assert abs(ros.uav_positions()[0][-1, 2] - CLIMB) < 0.01


def test_the_registries_are_the_scenario_s_and_an_unknown_law_is_an_error():
    """One registry per kind, the one validation reads (no hand-kept copy), and a law index
    the compiled dispatcher has no branch for stops with an error, never flies as another."""
    from multilift_control.controllers import compiled
    assert controllers.LEADER_CONTROLLERS is scenario_io.LEADER_CONTROLLERS
    assert controllers.FOLLOWER_CONTROLLERS is scenario_io.FOLLOWER_CONTROLLERS
    assert list(scenario_io.leader_controllers()) == ['cascade', 'constant_rotor_speed']
    assert list(scenario_io.follower_controllers()) == ['virtual_constraints', 'thrust_margin',
                                                       'cable_forces', 'heading']
    leader = controllers.LeaderController(scenario_io.load('single_lift'))
    c = leader.cascade
    arguments = (leader.constants, leader.memory, c.constants, c.mixer.rows, leader.path.mission,
                 leader.path.segments, leader.path.steps, 0.0, np.zeros((1, UAV_STATE_SIZE)),
                 np.zeros(3), np.zeros(3), np.zeros(4), np.zeros(4, dtype=bool), np.zeros(3),
                 np.zeros(REFERENCE_SIZE))
    answer = compiled.dispatchers().leader_answer
    assert answer(0, *arguments) > 0  # the cascade's thrust
    with pytest.raises(LookupError, match='leader controller the compiled tick does not know'):
        answer(len(controllers.LEADER_CONTROLLERS), *arguments)
