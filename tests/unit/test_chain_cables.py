"""`cable_model: chain` (issue 32 item 2) as code: its solve and a control period compiled are
their source run by Python to the bits; its keys' bad input and its stepping rule are one line
and exit 2; its state's node blocks are the layout's slots; its start puts the nodes on the
rigid cable's line."""
from __future__ import annotations

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.headless import run_headless
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.physics import layout
from multilift_sim.physics.formation_dae import integrate_period, solve
from multilift_sim.simulation import FormationSimulator
from multilift_sim.statistics import summary_row


def _chain(**cable):
    data = yaml.safe_load((SCENARIOS / 'twin_lift_chain.yaml').read_text())
    data['cable'].update(cable)
    return yaml.safe_dump(data)


def _swinging(attach: bool = False):
    """twin_lift_chain (its cables held off the UAVs' centres with `attach`) after 20 ticks
    of uneven rotors (the chains swinging), its payload moved into the first gust:
    (simulator, state, wrenches)."""
    data = yaml.safe_load(_chain())
    if attach:
        data['uavs'][0]['attach_point'] = [0.05, -0.02, -0.08]
        data['uavs'][1]['attach_point'] = [-0.03, 0.04, -0.08]
    sim = FormationSimulator(scenario_io.loads(yaml.safe_dump(data)))
    hover = [np.array([1800.0, 1790.0, 1800.0, 1810.0]) for _ in range(2)]
    idle = [np.zeros(4, bool) for _ in range(2)]
    for _ in range(20):
        sim.advance(hover, idle)
    x = sim.state.copy()
    shift = np.r_[np.asarray(sim.scenario.gusts[0].center)
                  - sim.model.layout.payload_position(x)[:2], 0.0]
    sim.model.layout.payload_position(x)[:] += shift
    sim.model.layout.uav_positions(x)[:] += shift
    sim.model.layout.chain_positions(x)[:] += shift
    return sim, x, sim.model.wrenches(hover)


@pytest.mark.parametrize('attach', [False, True])
def test_the_chain_s_solve_and_period_compiled_are_their_source_bit_for_bit(attach):
    sim, x, wrenches = _swinging(attach)
    model, n = sim.model, 2
    constants = (model._uavs, model._gusts, model._formation)
    taut = np.ones(n, bool)
    results = []
    for function in (solve, kernels.uncompiled(solve)):
        acc, multipliers = np.empty(x.size - model.layout.n_coordinates), np.empty(n)
        function(x, wrenches, *constants, taut, acc, multipliers,
                 np.empty((n, layout.CABLE_COLUMNS)))
        results.append((acc, multipliers))
    assert np.array_equal(results[0][0], results[1][0])
    assert np.array_equal(results[0][1], results[1][1])
    assert np.all(results[0][1] > 0.0)
    periods = [function(x, wrenches, *constants, taut, 0.0025, 4)
               for function in (integrate_period, kernels.uncompiled(integrate_period))]
    for compiled, python in zip(*periods):
        assert np.array_equal(compiled, python)
    assert not np.array_equal(periods[0][0], x)


def test_the_chain_s_nodes_are_the_layout_s_slots_and_start_on_the_rigid_line():
    s = scenario_io.load(SCENARIOS / 'twin_lift_chain.yaml')
    links = s.cable['links']
    state = StateLayout(2, chain_nodes=links - 1)
    x = FormationSimulator(s).state
    assert x.size == state.size == layout.attitude_slot(2) + 2 * (links - 1) * layout.NODE_STATE
    marks = np.arange(state.size, dtype=float)
    assert state.chain_positions(marks)[1, 2, 0] == layout.chain_node_slot(
        state.size, 2, links - 1, 1, 3)
    assert state.chain_velocities(marks)[0, 0, 0] == layout.attitude_slot(2) + 3
    assert layout.chain_inner_nodes(state.size, 2) == links - 1
    assert layout.chain_inner_nodes(layout.attitude_slot(2) + 7, 2) == 0
    assert layout.rigid_payload_state(layout.attitude_slot(2) + 7, 2)
    beam = StateLayout(2, True, chain_nodes=links - 1)   # a rigid payload's block, then nodes
    assert layout.rigid_payload_state(beam.size, 2)
    assert layout.chain_inner_nodes(beam.size, 2) == links - 1
    assert beam.chain_positions(np.arange(beam.size, dtype=float))[0, 0, 0] == \
        layout.attitude_slot(2) + layout.PAYLOAD_ATTITUDE
    uavs, payload = state.uav_positions(x), state.payload_position(x)
    for i in range(2):
        line = uavs[i] + np.outer(np.arange(1, links) / links, payload - uavs[i])
        assert np.allclose(state.chain_positions(x)[i], line, atol=1e-12)


@pytest.mark.parametrize('cable, says', [
    ({'links': 0}, 'cable.links: 0 must be an integer >= 2'),
    ({'links': 1}, 'cable.links: 1 must be an integer >= 2'),
    ({'links': 2.5}, 'cable.links: 2.5 must be an integer >= 2'),
    ({'mass_per_length': -0.015}, 'cable.mass_per_length: -0.015 must be > 0'),
    ({'diameter': -0.004}, 'cable.diameter: -0.004 must be >= 0'),
    ({'bend_stiffness': 100.0}, 'cable.bend_stiffness'),
])
def test_bad_chain_keys_are_one_line(cable, says):
    with pytest.raises(scenario_io.ScenarioError) as caught:
        scenario_io.loads(_chain(**cable))
    assert says in str(caught.value) and '\n' not in str(caught.value)


def test_a_chain_stepped_too_coarsely_is_refused_naming_its_sub_steps():
    """twin_lift_chain's chains: fastest transverse mode bounded by 2 sqrt(T / mu) / (l / N),
    T the whole weight (0.8 kg + 2 x 0.154 kg) g: 157 rad/s, so 1 sub-step at 200 Hz (omega h
    0.79) is refused and the message's 2 fly."""
    data = yaml.safe_load(_chain())
    data['simulation']['substeps'] = 1
    with pytest.raises(scenario_io.ScenarioError) as caught:
        scenario_io.loads(yaml.safe_dump(data))
    text = str(caught.value)
    assert 'omega h = 0.79' in text and 'bounded by 157 rad/s' in text
    assert 'substeps >= 2' in text and '\n' not in text
    data['simulation']['substeps'] = 2
    scenario_io.loads(yaml.safe_dump(data))


def test_the_summary_gives_each_chain_s_sag_and_the_markers_draw_its_links():
    """A second of twin_lift_chain hovering: each cable's max sag (an inner node's largest
    distance from its chord, at the ticks) as measured here from the states, in the figures
    and summary.json's `max_sag` (a sweep row's: the larger); the cable markers are the N
    links through the nodes."""
    from multilift_sim.wire.scene import FormationScene
    s = scenario_io.load(SCENARIOS / 'twin_lift_chain.yaml').with_duration(1.0)
    sim = FormationSimulator(s)
    links = s.cable['links']
    state = StateLayout(2, chain_nodes=links - 1)
    speeds = [np.full(4, 1900.0) for _ in range(2)]
    idle = [np.zeros(4, bool) for _ in range(2)]
    sags = np.zeros(2)
    while not sim.finished:
        x = sim.state
        for i in range(2):
            top, chord = state.uav_positions(x)[i], state.payload_position(x) - \
                state.uav_positions(x)[i]
            off = state.chain_positions(x)[i] - top
            along = off @ chord / (chord @ chord)
            sags[i] = max(sags[i], np.linalg.norm(off - np.outer(along, chord), axis=1).max())
        sim.advance(speeds, idle)
    assert np.all(sags > 1e-3)    # they sag from the straight start
    np.testing.assert_allclose(sim.stats.chain_figures['max_sag'], sags, rtol=1e-12)
    assert sim.stats.as_dict()['max_sag'] == sim.stats.chain_figures['max_sag']
    row = summary_row({'sim': sim.stats.as_dict()})  # a sweep's row: the worst cable's
    assert row['max_sag'] == sags.max() and row['max_stretch'] is None
    snap = sim.snapshot()
    scene = FormationScene(s)
    scene.update([u.position for u in snap.uavs], [u.euler for u in snap.uavs],
                 snap.payload_position, [5.0, 5.0], None, None, snap.chain_points)
    cable = scene.cables[1]
    assert len(cable.points) == 2 * links
    np.testing.assert_allclose(cable.points[1], state.chain_positions(sim.state)[1, 0])
    np.testing.assert_allclose(cable.points[-1], state.payload_position(sim.state))
    rigid = FormationScene(scenario_io.load(SCENARIOS / 'twin_lift.yaml'))
    assert len(rigid.cables[0].points) == 16   # other cables drawn as before


def test_engine_and_simulator_fly_a_chain_twin_lift_alike():
    """The batched engine and the simulator step twin_lift_chain (8 s, controllers flying) to
    the same bits: the one compiled tick."""
    from multilift_control.headless import fly, run_headless
    s = scenario_io.load(SCENARIOS / 'twin_lift_chain.yaml').with_duration(8.0)
    engine, simulator = fly(s), run_headless(s)
    np.testing.assert_array_equal(engine.engine.state[0], simulator.simulator.state)
    assert engine.engine.memory.status[0] == 1  # finished


@pytest.mark.parametrize('cable,message', [
    ({'damping': 2.0}, 'needs stiffness [N/m] or axial_stiffness [N] (elastic links)'),
    ({'stiffness': -5.0}, 'stiffness: -5.0 must be > 0'),
    ({'axial_stiffness': 1.5e5}, 'simulation.substeps: 2 steps the chain cables at omega h'),
])
def test_bad_elastic_links_are_one_line(cable, message):
    """Elastic links take the rope's keys; damping alone, a negative stiffness and a stepping
    too coarse for the links' axial waves (2 mm Dyneema's EA on 30 links: thousands of rad/s)
    are refused in one line."""
    with pytest.raises(scenario_io.ScenarioError, match='^[^\n]*$') as caught:
        scenario_io.loads(_chain(**cable))
    assert message in str(caught.value)


def test_elastic_links_compiled_equal_their_uncompiled_source_reeled(monkeypatch):
    """A single lift on 5 elastic links (EA 2 kN) whose winch pays out 0.4 m/s: the compiled
    tick and its uncompiled source within 1e-9 m over 1.2 s; the chain longer than its
    reeled length (stretched by the payload)."""
    data = yaml.safe_load((SCENARIOS / 'single_lift.yaml').read_text())
    data.update(cable_model='chain', cable={'links': 5, 'mass_per_length': 0.1,
                                            'axial_stiffness': 2e3})
    data['uavs'][0]['winch'] = {'rate_limit': 0.5, 'acceleration_limit': 0.5,
                                'min_length': 1.0, 'max_length': 6.0}
    data['events'] = [{'time': 0.2, 'type': 'winch_rate', 'uav': 1, 'rate': 0.4}]
    data['simulation'].update(duration=1.2, substeps=8)
    s = scenario_io.loads(yaml.safe_dump(data))
    states = {}
    for kernel in ('auto', 'python'):
        monkeypatch.setenv('MULTILIFT_KERNEL', kernel)
        states[kernel] = run_headless(s).simulator.state
    assert np.abs(states['auto'] - states['python']).max() < 1e-9
    layout = StateLayout(1, chain_nodes=4)
    x = states['auto']
    places = np.vstack([layout.uav_positions(x)[:1], layout.chain_positions(x)[0],
                        layout.payload_position(x)[None]])
    assert np.linalg.norm(np.diff(places, axis=0), axis=1).sum() > 2.5 + 0.2


def test_a_chain_s_path_starts_at_its_hold_on_the_uav_and_ends_at_the_beam():
    """`cable_paths` (the sag's and stretch's path): on beam_lift's chains held 0.1, 0.05,
    -0.1 m off each UAV's centre, each path starts at r_i + R_i a_i and ends at r_p + R_p b_i
    (worked out here from the state's quaternions), its inner nodes between; compiled equal to
    its uncompiled source."""
    from multilift_sim.physics.chain_cables import cable_paths
    data = yaml.safe_load((SCENARIOS / 'beam_lift.yaml').read_text())
    data.update(cable_model='chain', cable={'links': 6, 'mass_per_length': 0.05})
    attach = np.array([0.1, 0.05, -0.1])
    for u in data['uavs']:
        u['attach_point'] = attach.tolist()
    s = scenario_io.loads(yaml.safe_dump(data))
    sim = FormationSimulator(s)
    hover = [np.full(4, 1900.0), np.full(4, 1890.0)]
    for _ in range(20):
        sim.advance(hover, [np.zeros(4, bool)] * 2)
    x = sim.state
    state = StateLayout(2, True, chain_nodes=5)
    paths = cable_paths(x, sim.arrays.uavs[0], 5)
    np.testing.assert_array_equal(paths, kernels.uncompiled(cable_paths)(
        x, sim.arrays.uavs[0], 5))
    beam = _rotation(state.payload_quaternion(x))
    for i in range(2):
        uav = _rotation(state.uav_quaternions(x)[i])
        assert np.allclose(paths[i, 0], state.uav_positions(x)[i] + uav @ attach, atol=1e-12)
        end = state.payload_position(x) + beam @ np.array(s.payload.attach_points[i])
        assert np.allclose(paths[i, -1], end, atol=1e-12)
        np.testing.assert_array_equal(paths[i, 1:-1], state.chain_positions(x)[i])


def _rotation(q) -> np.ndarray:
    """R of the unit quaternion q = (w, x, y, z) (the state's order)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
