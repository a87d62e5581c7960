"""Prescribed UAV motion (issue 34 item 3: `uavs[i].trajectory`, `payload.initial_position` /
`initial_velocity`) against mechanics: a UAV moved horizontally as x(t) = A sin(w t) at half
the pendulum's natural frequency swings a payload started on the linear driven pendulum's
particular solution x_p(t) = A w0^2 / (w0^2 - w^2) sin(w t), which it must follow (within 1 %
of its amplitude) over five periods; the same for the twin-lift, both UAVs moved alike (the
payload's pendulum about the line through the cables' upper ends, of length h =
sqrt(l^2 - (d/2)^2)). The splines hold the file's rows; the compiled functions equal their
uncompiled run bit for bit. Bad input: tests/unit/test_prescribed_input.py."""
from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest

from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.drives import drive_table, spline_drive
from multilift_sim.formation_params import StateLayout, constant_arrays
from multilift_sim.physics import prescribed
from multilift_sim.physics.formation_dae import integrate_period
from multilift_sim.physics.layout import FORMATION_PRESCRIBED, FORMATION_SCALARS
from multilift_sim.physics.layout import (CABLE_COLUMNS, FORMATION_TIME, WRENCH_COLUMNS,
                                          DRIVE_EULER)
from multilift_sim.simulation import FormationSimulator

GRAVITY = 9.81
AMPLITUDE = 0.02    # A [m]: small, the pendulum's angle stays under 0.01 rad (linear)


def write_csv(path: Path, times, x, v=None, a=None, y=0.0, z=10.0, extra: str = '') -> None:
    """A trajectory file: t,x,y,z (with v: vx,vy,vz; with a: ax,ay,az) at `times`."""
    header = 't,x,y,z' + (',vx,vy,vz' if v is not None else '') + (
        ',ax,ay,az' if a is not None else '') + extra
    lines = [header]
    for k, t in enumerate(times):
        row = [t, x[k], y, z] + ([v[k], 0.0, 0.0] if v is not None else []) + (
            [a[k], 0.0, 0.0] if a is not None else [])
        lines.append(','.join(repr(float(c)) for c in row))
    path.write_text('\n'.join(lines) + '\n')


def driven_scenario(folder: Path, offsets: list[float], length: float, duration: float,
                    columns: str = 'xva', drag: float = 0.0) -> scenario_io.Scenario:
    """UAVs at y = offsets [m], z = 10 m, each moved as x = A sin(w t), w = w0 / 2, w0 the
    payload's pendulum frequency sqrt(g / h) (h its depth under the line through the UAVs);
    the payload started on the particular solution. Returns the scenario."""
    half = (offsets[-1] - offsets[0]) / 2
    depth = math.sqrt(length ** 2 - half ** 2)
    w0 = math.sqrt(GRAVITY / depth)
    w = w0 / 2
    gain = w0 ** 2 / (w0 ** 2 - w ** 2)  # the particular solution's amplitude over A
    times = np.arange(0.0, duration + 0.05 + 1e-9, 0.05)
    uavs = []
    for i, y in enumerate(offsets):
        name = f'uav{i + 1}.csv'
        write_csv(folder / name, times, AMPLITUDE * np.sin(w * times),
                  AMPLITUDE * w * np.cos(w * times) if 'v' in columns else None,
                  -AMPLITUDE * w * w * np.sin(w * times) if 'a' in columns else None, y=y)
        uavs.append({'cable_length': length, 'trajectory': name})
    data = {
        'name': 'driven', 'frame': 'world',
        'simulation': {'duration': duration, 'physics_rate': 1000.0, 'control_rate': 100.0,
                       'gravity': GRAVITY, 'baumgarte_alpha': 20.0, 'baumgarte_beta': 20.0,
                       'constraint_tolerance': 0.1, 'constraint_rate_tolerance': 1.0},
        'vehicle': {'preset': 'table_4_2'},
        'uavs': uavs,
        'payload': {'mass': 0.4, 'drag_coefficient': drag,
                    'initial_position': [0.0, (offsets[0] + offsets[-1]) / 2, 10.0 - depth],
                    'initial_velocity': [gain * AMPLITUDE * w, 0.0, 0.0]},
        'control': {'mode': 'constant_rotor_speed', 'constant_rotor_speed': None,
                    'position_gains': {'kp': [0] * 3, 'kd': [0] * 3, 'ki': [0] * 3},
                    'attitude_gains': {'kp': [0] * 3, 'kd': [0] * 3}},
        'mission': {'segments': []}}
    if len(offsets) > 1:
        data['formation'] = {'geometry': 'linear', 'offsets': [[0.0, offsets[1] - offsets[0],
                                                                 0.0]],
                             'alpha_vc': 2.1, 'beta_vc': 1.3}
    import yaml
    path = folder / 'driven.yaml'
    path.write_text(yaml.safe_dump(data))
    return scenario_io.load(str(path))


def fly_driven(scenario) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t [s], the UAVs' x (ticks, n), the payload's x (ticks,)) of a prescribed run stepped
    with no controller (the simulator's idle commands), every tick."""
    sim = FormationSimulator(scenario)
    times, uavs, payload = [], [], []
    while True:
        snap = sim.snapshot()
        times.append(sim.t)
        uavs.append([u.position[0] for u in snap.uavs])
        payload.append(snap.payload_position[0])
        if sim.finished:
            break
        sim.advance(*sim.idle_commands())
    return np.array(times), np.array(uavs), np.array(payload)


@pytest.mark.parametrize('offsets,length', [([0.0], 1.0), ([-1.0, 1.0], 2.0)],
                         ids=['single', 'twin'])
def test_the_payload_follows_the_driven_pendulums_steady_motion(tmp_path, offsets, length):
    half = (offsets[-1] - offsets[0]) / 2
    depth = math.sqrt(length ** 2 - half ** 2)
    w0 = math.sqrt(GRAVITY / depth)
    w = w0 / 2
    periods = 5
    duration = round(periods * 2 * math.pi / w, 1)
    scenario = driven_scenario(tmp_path, offsets, length, duration)
    assert scenario.prescribed == tuple(range(len(offsets))) and not scenario.controlled
    t, uavs, payload = fly_driven(scenario)
    assert t[-1] == pytest.approx(duration)
    # the UAVs are the file: A sin(w t) at every tick (the spline and the reset)
    assert np.abs(uavs - AMPLITUDE * np.sin(w * t)[:, None]).max() < 1e-9
    steady = w0 ** 2 / (w0 ** 2 - w ** 2) * AMPLITUDE * np.sin(w * t)
    amplitude = w0 ** 2 / (w0 ** 2 - w ** 2) * AMPLITUDE
    error = np.abs(payload - steady).max()
    assert error < 0.01 * amplitude, (error, amplitude)
    # it swung: the payload went out to its amplitude, not hanging still
    assert np.abs(payload).max() > 0.99 * amplitude


def test_off_the_particular_solution_the_free_swing_shows(tmp_path):
    """Started at rest (initial_velocity 0) the payload swings at w0 on top of the steady
    motion: the 1 % bar above is one a wrong start fails."""
    scenario = driven_scenario(tmp_path, [0.0], 1.0, 10.0)
    import dataclasses
    scenario = dataclasses.replace(scenario, payload=dataclasses.replace(
        scenario.payload, initial_velocity=(0.0, 0.0, 0.0)))
    t, _, payload = fly_driven(scenario)
    w0 = math.sqrt(GRAVITY / 1.0)
    amplitude = w0 ** 2 / (w0 ** 2 - (w0 / 2) ** 2) * AMPLITUDE
    steady = amplitude * np.sin(w0 / 2 * t)
    assert np.abs(payload - steady).max() > 0.2 * amplitude


def test_a_positions_only_file_is_splined_through_its_rows_with_its_motion(tmp_path):
    """Positions alone: the not-a-knot cubic spline, through every row, its velocity that of
    the motion (sin sampled every 0.05 s: within 1e-5 of A w cos), not stopped at the ends."""
    times = np.arange(0.0, 10.05, 0.05)
    w = 1.5
    drive = spline_drive('f', times, np.stack([np.sin(w * times), 0 * times, 0 * times], 1))
    formation = np.concatenate([np.zeros(FORMATION_SCALARS), drive_table([drive])])
    formation[FORMATION_PRESCRIBED] = 1.0
    evaluate = kernels.runnable(prescribed.drive_axis)
    for t in (0.0, 0.025, 3.3, 10.0):
        value, rate, acceleration = evaluate(formation, drive_of(formation), 0, t)
        assert value == pytest.approx(math.sin(w * t), abs=1e-6)
        assert rate == pytest.approx(w * math.cos(w * t), abs=2e-4)
        assert acceleration == pytest.approx(-w * w * math.sin(w * t), abs=2e-2)


def drive_of(formation) -> int:
    return kernels.runnable(prescribed.drive_of)(formation, 0)


def test_velocities_and_accelerations_are_the_files_and_continuous():
    """With vx,vy,vz and ax,ay,az the quintic Hermite spline takes each row's values exactly;
    with velocities alone the acceleration is continuous across the rows."""
    rng = np.random.default_rng(3)
    times = np.cumsum(rng.uniform(0.1, 0.5, 8)) - 0.1
    positions, velocities, accelerations = (rng.normal(size=(8, 3)) for _ in range(3))
    for given in (accelerations, None):
        drive = spline_drive('f', times, positions, velocities, given,
                             euler=rng.normal(size=(8, 3)) * 0.1)
        formation = np.concatenate([np.zeros(FORMATION_SCALARS), drive_table([drive])])
        formation[FORMATION_PRESCRIBED] = 1.0
        evaluate = prescribed.drive_axis.py_func
        for k, t in enumerate(times):
            for axis in range(3):
                before = evaluate(formation, drive_of(formation), axis, t - 1e-11)
                value, rate, acceleration = evaluate(formation, drive_of(formation), axis, t)
                assert value == pytest.approx(positions[k, axis], abs=1e-12)
                assert rate == pytest.approx(velocities[k, axis], abs=1e-9)
                if given is not None:
                    assert acceleration == pytest.approx(given[k, axis], abs=1e-8)
                assert before[2] == pytest.approx(acceleration, abs=1e-6)  # continuous


def test_the_attitude_comes_from_the_file_else_level(tmp_path):
    """roll, pitch, yaw columns: the UAV's quaternion and body rates at each tick are theirs
    (yaw turning at 0.2 rad/s: body rate r = 0.2); without them level at the UAV's yaw."""
    times = np.arange(0.0, 3.05, 0.05)
    path = tmp_path / 'turning.csv'
    lines = ['t,x,y,z,roll,pitch,yaw'] + [f'{float(t)!r},0,0,10,0,0,{0.2 * float(t)!r}'
                                          for t in times]
    path.write_text('\n'.join(lines) + '\n')
    text = (Path(__file__).resolve().parents[2] / 'scenarios' / 'prescribed_swing.yaml'
            ).read_text()
    text = text.replace('prescribed_swing.csv', 'turning.csv').replace(
        'duration: 20.0', 'duration: 2.0').replace('initial_velocity: [0.0417612260356422',
                                                   'initial_velocity: [0.0')
    (tmp_path / 'turning.yaml').write_text(text)
    sim = FormationSimulator(scenario_io.load(str(tmp_path / 'turning.yaml')))
    for _ in range(150):
        sim.advance(*sim.idle_commands())
    snap = sim.snapshot()
    assert snap.uavs[0].euler == pytest.approx([0.0, 0.0, 0.2 * 1.5], abs=1e-9)
    assert snap.uavs[0].body_rates == pytest.approx([0.0, 0.0, 0.2], abs=1e-9)
    level = FormationSimulator(scenario_io.load('prescribed_swing'))
    level.advance(*level.idle_commands())
    assert level.snapshot().uavs[0].euler == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)
    assert DRIVE_EULER == 3


def test_the_prescribed_physics_compiled_is_its_source_bit_for_bit():
    """drive_axis, prescribe_state, prescribed_solve and a control period through them (the
    stage times in FORMATION_TIME): compiled and uncompiled give the same bits."""
    scenario = scenario_io.load('prescribed_swing')
    params = scenario.formation_params()
    uavs, gusts, formation = constant_arrays(params)
    sim = FormationSimulator(scenario)
    for _ in range(37):
        sim.advance(*sim.idle_commands())
    x = sim.state
    n = scenario.n_uavs
    wrenches = np.zeros((n, WRENCH_COLUMNS))
    taut = np.ones(n, dtype=bool)
    formation = formation.copy()
    formation[FORMATION_TIME] = sim.t
    layout = StateLayout(n)
    calls = [
        (prescribed.drive_axis, (formation, drive_of(formation), 0, 3.21)),
        (prescribed.prescribe_state, (x.copy(), n, formation, 1.234)),
        (prescribed.prescribed_solve, (x, wrenches, uavs, gusts, formation, taut,
                                       np.zeros(x.size - layout.n_coordinates), np.zeros(n),
                                       np.zeros((n, CABLE_COLUMNS)))),
        (integrate_period, (x, wrenches, uavs, gusts, formation.copy(), taut, 0.001, 10)),
    ]
    for function, args in calls:
        compiled_args, python_args = copy.deepcopy(args), copy.deepcopy(args)
        compiled = function(*compiled_args)
        python = kernels.uncompiled(function)(*python_args)
        assert same(compiled, python), function.__name__
        assert same(tuple(compiled_args), tuple(python_args)), function.__name__


def same(a, b) -> bool:
    """Equal bit for bit (tuples element by element, None with None)."""
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(map(same, a, b))
    if a is None or b is None:
        return a is b
    return np.array_equal(np.asarray(a), np.asarray(b))
