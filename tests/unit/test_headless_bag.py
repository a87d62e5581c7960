"""The headless bag written from the engine's records (`record_headless`) is the bag of the
per-object path (`run_headless` observed tick by tick, what a ROS run's nodes compute): the same
bytes, file for file, over chunk boundaries, at t_max, for slack cables and for a run that
Algorithm 1 stops mid-chunk."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from multilift_sim import scenario as scenario_io
from multilift_sim.simulation import FormationSimulator, SimulationStopped
from multilift_sim.wire.tick_messages import state_rows
from multilift_tools import headless_bag
from multilift_tools.headless_bag import _record_per_object, record_headless


def _short(name: str, duration: float, cable_model: str = 'rigid',
           **simulation) -> scenario_io.Scenario:
    base = scenario_io.load(name)
    return dataclasses.replace(base, cable_model=cable_model, simulation=dataclasses.replace(
        base.simulation, duration=duration, **simulation))


def _same_bags(tmp_path, scenario, chunk: int, monkeypatch) -> tuple:
    """(engine run, per-object run) of `scenario` after asserting their bags' bytes equal."""
    monkeypatch.setattr(headless_bag, 'CHUNK_TICKS', chunk)
    runs = []
    for side, record in (('engine', record_headless), ('objects', _record_per_object)):
        runs.append(record(scenario, tmp_path / side / 'bag', raise_on_stop=False))
    names = sorted(p.name for p in (tmp_path / 'engine' / 'bag').iterdir())
    assert names == sorted(p.name for p in (tmp_path / 'objects' / 'bag').iterdir())
    assert 'metadata.yaml' in names and any(name.endswith('.mcap') for name in names)
    for name in names:
        assert (tmp_path / 'engine' / 'bag' / name).read_bytes() == \
            (tmp_path / 'objects' / 'bag' / name).read_bytes(), name
    return tuple(runs)


@pytest.mark.parametrize('name,duration,cables,chunk', [
    ('circle3', 0.73, 'rigid', 7),          # 3 UAVs: markers, t_max mid-chunk
    ('circle3', 0.5, 'rigid', 50),          # t_max at a chunk's end
    ('twin_lift', 1.0, 'slack', 30),
    ('single_lift_swing', 0.4, 'rigid', 16),
    ('prescribed_swing', 0.45, 'rigid', 16)])  # no controller (issue 34): no command topic
def test_the_engine_s_bag_is_the_per_object_path_s(tmp_path, monkeypatch, name, duration,
                                                    cables, chunk):
    engine_run, object_run = _same_bags(tmp_path, _short(name, duration, cables), chunk,
                                        monkeypatch)
    assert engine_run.error is None and object_run.error is None
    expected = object_run.summary()
    summary = engine_run.summary()
    del expected['sim']['wall_time'], summary['sim']['wall_time']
    assert summary == expected


def test_a_run_stopped_mid_chunk_writes_what_the_per_object_path_writes(tmp_path, monkeypatch):
    scenario = _short('twin_lift', 2.0, constraint_tolerance=1e-8)  # stops at t = 0.37 s
    engine_run, object_run = _same_bags(tmp_path, scenario, 16, monkeypatch)
    assert engine_run.error and engine_run.error == object_run.error
    with pytest.raises(SimulationStopped, match='constraint residual'):
        record_headless(scenario, tmp_path / 'raised' / 'bag')


def test_state_rows_are_the_snapshots_numbers():
    scenario = _short('circle3', 1.0)
    sim = FormationSimulator(scenario)
    sim.state = sim.state + np.random.default_rng(3).normal(0.0, 0.3, sim.state.shape)
    snapshot, odometry = state_rows(sim.state[None], scenario.n_uavs)
    snap = sim.snapshot()
    for i, uav in enumerate(snap.uavs):
        assert odometry[0, i, :3].tolist() == uav.position.tolist()
        assert odometry[0, i, 3:7].tolist() == uav.orientation.tolist()
        assert odometry[0, i, 7:10].tolist() == uav.body_velocity.tolist()
        assert odometry[0, i, 10:].tolist() == uav.body_rates.tolist()
    n = scenario.n_uavs
    assert snapshot[0, 9 * n:12 * n].tolist() == np.concatenate(
        [u.body_rates for u in snap.uavs]).tolist()


def test_a_hexa_beside_a_quad_writes_the_per_object_path_s_bag(tmp_path, monkeypatch):
    """Mixed rotor counts: the engine's padded rows written as each UAV's own rotors."""
    import yaml
    data = yaml.safe_load(scenario_io.resolve('twin_lift').read_text())
    data['simulation']['duration'] = 0.6
    data['uavs'][1] = {'frame_type': 'hexa_x'}
    engine_run, object_run = _same_bags(tmp_path, scenario_io.loads(yaml.safe_dump(data)), 16,
                                        monkeypatch)
    assert engine_run.error is None and object_run.error is None


def test_events_on_a_block_s_first_tick_inside_it_and_together(tmp_path, monkeypatch):
    """Ticks that events fall on are written message by message between the blocks
    (`EngineBag.ticks`): an event on a block's first tick (0.16 s, tick 16 of blocks of 16), one
    inside a block (0.21 s) and two on one tick (0.37 s) give the per-object path's bag."""
    import yaml
    data = yaml.safe_load(scenario_io.resolve('hexa_rotor_failure').read_text())
    data['simulation']['duration'] = 0.45
    data['events'] = [
        {'time': 0.16, 'type': 'rotor_effectiveness', 'uav': 1, 'rotor': 1,
         'effectiveness': 0.5},
        {'time': 0.21, 'type': 'rotor_effectiveness', 'uav': 2, 'rotor': 3,
         'effectiveness': 0.8},
        {'time': 0.37, 'type': 'rotor_effectiveness', 'uav': 1, 'rotor': 2,
         'effectiveness': 0.9},
        {'time': 0.37, 'type': 'rotor_effectiveness', 'uav': 2, 'rotor': 1,
         'effectiveness': 0.7}]
    engine_run, object_run = _same_bags(tmp_path, scenario_io.loads(yaml.safe_dump(data)), 16,
                                        monkeypatch)
    assert engine_run.error is None and object_run.error is None
