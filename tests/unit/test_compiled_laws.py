"""The control laws (multilift_control.laws) compiled against their uncompiled run
(`kernels.uncompiled`: the same source in Python): every law, over randomized states, gives the
same bits (np.array_equal) and leaves the same memory; a headless run flies the same bits
either way. What the laws compute is tested on its own in test_control.py, test_formation.py,
test_runtime.py and test_laws.py."""
from __future__ import annotations

import copy
import dataclasses
import json
import math

import numpy as np
import pytest
import yaml

from multilift_control import laws
from multilift_control.controllers import LeaderController
from multilift_control.formation import FormationFollower
from multilift_control.virtual_constraints import FormationGeometry, VirtualConstraints
from multilift_control.headless import run_headless
from multilift_control.laws import (cascade, constraints, follower, linalg, mixer, reference,
                                    swing)
from multilift_control.laws.layout import (CASCADE_GRAVITY, CASCADE_MAX_TILT,
                                           CASCADE_SQUARE_MAX, CASCADE_SQUARE_MIN,
                                           CASCADE_SWING_DAMPING, CASCADE_SWING_REST,
                                           CASCADE_SWING_STIFFNESS,
                                           CASCADE_THRUST_COEFFICIENT, FOLLOWER_FREE_MODE_GAIN,
                                           FOLLOWER_MEMORY_SIZE, REFERENCE_SIZE,
                                           UAV_STATE_SIZE)
from multilift_control.mission import MissionPath
from multilift_sim import kernels
from multilift_sim.physics import free_motion
from multilift_sim import scenario as scenario_io
from multilift_sim.scenario import INPUT_SHAPERS
from multilift_sim.simulation import FormationSimulator

pytest.importorskip('numba')

LAW_MODULES = (reference, mixer, cascade, linalg, constraints, follower)


def _all_laws() -> dict[str, object]:
    """Every compiled function of the laws' modules, by name."""
    return {f'{module.__name__}.{name}': value for module in LAW_MODULES
            for name, value in vars(module).items()
            if hasattr(value, 'py_func') and value.__module__ == module.__name__}


def _name(law) -> str:
    return f'{law.__module__}.{law.__name__}'


def _equal(a, b) -> bool:
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(map(_equal, a, b))
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


def _differences(a, b) -> list:
    """Where two results differ: (position in the tuple, compiled, uncompiled) in hex."""
    pairs = list(zip(a, b)) if isinstance(a, tuple) else [(a, b)]
    return [(k, [float(x).hex() for x in np.ravel(x)], [float(y).hex() for y in np.ravel(y)])
            for k, (x, y) in enumerate(pairs) if not _equal(x, y)]


class Checker:
    """Runs a law compiled and uncompiled on copies of the same arguments and asserts that the
    results and the arguments after the call (a law's memory) are equal bit for bit."""

    def __init__(self) -> None:
        self.met: set[str] = set()
        self._uncompiled: dict[str, object] = {}

    def __call__(self, law, *args):
        name = _name(law)
        python = self._uncompiled.setdefault(name, kernels.uncompiled(law))
        compiled_args, python_args = copy.deepcopy(args), copy.deepcopy(args)
        compiled = law(*compiled_args)
        uncompiled = python(*python_args)
        assert _equal(compiled, uncompiled), (name, _differences(compiled, uncompiled))
        for k, (a, b) in enumerate(zip(compiled_args, python_args)):
            assert _equal(a, b), (name, f'argument {k} after the call', a, b)
        self.met.add(name)
        return compiled, compiled_args


def _states(rng, nominal: np.ndarray, spread: float) -> np.ndarray:
    n = len(nominal)
    states = np.empty((n, UAV_STATE_SIZE))
    states[:, 0:3] = nominal + spread * rng.normal(size=(n, 3))
    states[:, 3:6] = spread * rng.normal(size=(n, 3))
    tilt = min(0.6, spread)
    states[:, 6:9] = rng.uniform(-tilt, tilt, size=(n, 3)) * np.array([1, 1, 5])
    states[:, 9:12] = tilt * rng.normal(size=(n, 3))
    return states


def _followers():
    """Followers of every kind of rows and option: (follower, nominal positions)."""
    out = []
    for name, options in (('twin_lift', {}), ('v5', {'own_thrust': 'measured'}),
                          ('circle3', {}), ('circle3', {'free_mode_gain': None})):
        s = scenario_io.load(name)
        f = FormationFollower.from_scenario(s, s.n_uavs - 1, **options)
        out.append((f, f.constraints.nominal_positions(np.array([1.0, 2.0, 3.0]))))
    s = scenario_io.load('circle3')
    rows = VirtualConstraints(FormationGeometry('distance', 4, distance=4.0))
    masses = np.full(4, 3.1)
    f = FormationFollower(s.uavs[1].vehicle, 2, rows, masses, s.control, 3.1, 9.81, 2.1, 1.3,
                          free_mode_gain=4.2)
    out.append((f, rows.nominal_positions(np.zeros(3))))
    return out


def test_every_law_compiled_equals_its_uncompiled_run_bit_for_bit():
    check = Checker()
    rng = np.random.default_rng(7)
    twin = scenario_io.load('twin_lift')
    leader = LeaderController(twin, 0)
    c, m = leader.cascade.constants, leader.cascade.mixer.rows
    damped = c.copy()  # with the swing feedback (control.payload_feedback) on
    damped[CASCADE_SWING_STIFFNESS], damped[CASCADE_SWING_DAMPING] = 0.8, 0.3
    damped[CASCADE_SWING_REST:CASCADE_SWING_REST + 2] = 0.2, -0.1
    raw_mission = dataclasses.replace(twin.mission, reference_filter_time=0.0)
    raw = MissionPath(raw_mission)
    shaped = [MissionPath(mission, INPUT_SHAPERS['zvd'], 6.4)  # control.payload_feedback
              for mission in (twin.mission, raw_mission)]
    paths = (leader.path, raw, *shaped)
    waypoints = MissionPath(scenario_io.loads(yaml.safe_dump(dict(
        yaml.safe_load((scenario_io.scenario_dir() / 'single_lift.yaml').read_text()),
        mission={'type': 'waypoints', 'waypoints': [
            {'time': 0.0, 'position': [0.0, 0.0, 0.0]},
            {'time': 4.0, 'position': [1.0, 0.5, 0.5], 'yaw': 0.3},
            {'time': 9.0, 'position': [2.0, -1.0, 0.5]},
            {'time': 12.0, 'position': [0.0, 0.0, 1.0], 'yaw': -0.4}]}))).mission)
    followers = _followers()
    memories = {id(f): f.memory.copy() for f, _ in followers}
    cascade_memory = leader.cascade.memory.copy()
    leader_memory = leader.cascade.memory.copy()
    saturated = clamped = 0
    for tick in range(150):
        t = 0.01 * tick
        far = tick >= 50  # near hover first, then far off (saturation, clamped integrals)
        spread = 3.0 if far else 0.01
        for path in paths:
            moment = float(rng.uniform(-2.0, 130.0))
            check(reference.raw_reference, path.mission, path.segments, moment,
                  np.empty(REFERENCE_SIZE))
            check(reference.mission_reference, path.mission, path.segments, path.steps, moment)
        moment = float(rng.uniform(-2.0, 14.0))  # a waypoints mission (a polynomial's pieces)
        check(reference.polynomial_reference, waypoints.mission, waypoints.segments, moment,
              np.empty(REFERENCE_SIZE))
        check(reference.mission_reference, waypoints.mission, waypoints.segments,
              waypoints.steps, moment)
        state = _states(rng, np.zeros((1, 3)), spread)[0]
        ref = (40.0 if far else 0.01) * rng.normal(size=REFERENCE_SIZE)
        ref[0] += 200.0 if far else 0.0  # an error that lasts: the integral clamps
        yaw = float(rng.uniform(-3, 3)) if far else float(state[8])
        force = (30.0 if far else 0.1) * rng.normal(size=3) + [0, 0, 30.0]
        wrench = np.r_[rng.uniform(0, 60), (0.5 if far else 0.01) * rng.normal(size=3)]
        speeds, _ = check(mixer.rotor_speeds, m, c[CASCADE_SQUARE_MIN], c[CASCADE_SQUARE_MAX],
                          wrench)[0]
        check(mixer.collective_thrust, c[CASCADE_THRUST_COEFFICIENT], speeds)
        check(cascade.clipped, float(rng.normal(scale=6.0)), 0.5 * c[CASCADE_GRAVITY])
        check(cascade.wrap_angle, float(rng.uniform(-20, 20)))
        check(cascade.elapsed, np.array([t - 0.01 if tick else math.nan]), 0, t)
        check(cascade.position_force, c, cascade_memory, t, state, ref)
        check(cascade.attitude_from_force, force, yaw, c[CASCADE_MAX_TILT])
        check(free_motion.thrust_axis, *rng.uniform(-1.5, 1.5, size=3))  # the follower's
        check(cascade.body_rates_and_gyro, c, state)
        check(cascade.attitude_torque, c, state, rng.uniform(-1, 1, size=3))
        check(cascade.attitude_command, c, m, state, rng.uniform(-0.3, 0.3, size=3),
              rng.uniform(10.0, 40.0))
        check(cascade.command, c, m, state, force, yaw)
        out, (_, _, cascade_memory, *_) = check(cascade.cascade_update, c, m, cascade_memory,
                                                t, state, ref, yaw)
        saturated += bool(out[1].any())
        clamped += np.abs(cascade_memory[:3]).max() == 0.5 * c[CASCADE_GRAVITY]
        # the leader of a twin-lift, its swing feedback (control.payload_feedback) on every
        # other tick
        formation = _states(rng, np.array([[0.0, 0.0, 0.0], [-3.5, -2.0, 0.0]]), spread)
        payload_position = [-1.7, -1.0, -10.0] + spread * rng.normal(size=3)
        payload_velocity = rng.normal(size=3)
        check(swing.swing_feedback, damped, formation, payload_position, payload_velocity)
        _, (*_, leader_memory, _, _, _, _, _, _, _) = check(
            cascade.leader_update, damped if tick % 2 else c, m, leader_memory,
            leader.path.mission, leader.path.segments, leader.path.steps, t, formation,
            payload_position, payload_velocity)
        # the linear algebra: full rank, rank deficient, wide, square singular
        matrix = rng.normal(size=(int(rng.integers(1, 5)), int(rng.integers(1, 6))))
        if tick % 3 == 0:
            matrix[-1] = matrix[0]
        check(linalg.right_singular, matrix)
        square = matrix @ matrix.T
        check(linalg.minimum_norm_solve, square, rng.normal(size=len(square)))
        for f, nominal in followers:
            rows, targets = f.constraints.rows, f.constraints.targets
            states = _states(rng, nominal, 0.3 if far else 0.01)
            r, v = states[:, 0:3].copy(), states[:, 3:6].copy()
            u = f.masses[:, None] * [0, 0, 9.81] + rng.normal(size=(len(r), 3))
            k = int(rng.integers(len(rows)))
            check(constraints.row_residual, rows, targets, r, k)
            check(constraints.row_rate, rows, r, v, k)
            g, _ = check(constraints.residual, rows, targets, r)
            check(constraints.jacobian, rows, r)
            check(constraints.jacobian_rate_product, rows, v)
            check(constraints.rows_of, rows, f.index)
            check(constraints.rows_by_uav, rows, len(r))
            check(constraints.free_follower_motions, rows, r, 1e-9)
            check(follower.virtual_forces, rows, targets, f.masses, 9.81, 4.2, 1.69, r, v, u)
            check(follower.free_mode_correction, f.masses, 4.2, f.index, r, v, u, rows)
            check(follower.driven_entry, f.masses, 9.81, 4.2, f.index, 2, u[f.index, 2],
                  v[f.index, 2])
            terms, _ = check(follower.formation_terms, f.constants, f.masses, rows, targets,
                             states, u)
            if f.constraints.linear:
                check(follower.linear_virtual_force, f.constants, f.law_p, f.law_q, f.index,
                      terms[3], rng.normal(size=3), g)
            check(follower.lift_vectors, states, rng.uniform(0, 60, size=len(r)))
            args = (f.constants, f.masses, rows, targets, f.law_p, f.law_q, f.index)
            check(follower.follower_force, *args, memories[id(f)].copy(), t, u, terms)
            loaded, _ = check(follower.loaded_terms, f.constants, f.masses, rows, targets,
                              states, u, rng.normal(size=(len(r), 3)))  # static pulls
            check(follower.follower_force, *args, memories[id(f)].copy(), t, u, loaded)
            ticked, _ = check(follower.follower_tick, *args, memories[id(f)].copy(), t, states,
                              u, f.cascade.constants, f.cascade.mixer.rows)
            updated, after = check(follower.follower_update, *args, memories[id(f)], t,
                                   states, u, terms, f.cascade.constants, f.cascade.mixer.rows)
            memories[id(f)] = after[7]
            assert _equal(ticked, updated)  # the terms and the step in one call: the same
    assert 10 < saturated < 140 and clamped > 0  # both regimes were met
    for f, _ in followers:  # the memories moved: lift, heading, integral
        assert not np.isnan(memories[id(f)]).any()
        assert memories[id(f)][0] != 0.0
    assert {f.constants[FOLLOWER_FREE_MODE_GAIN] > 0 for f, _ in followers} == {True, False}
    assert len(memories[id(followers[0][0])]) == FOLLOWER_MEMORY_SIZE
    missing = set(_all_laws()) - check.met
    assert not missing, f'laws not compared: {sorted(missing)}'


def test_runnable_follows_multilift_kernel(monkeypatch):
    monkeypatch.setenv('MULTILIFT_KERNEL', 'auto')
    assert laws.runnable(mixer.rotor_speeds) is mixer.rotor_speeds
    monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
    python = laws.runnable(mixer.rotor_speeds)
    assert not hasattr(python, 'py_func')
    assert python.__code__ is mixer.rotor_speeds.py_func.__code__
    monkeypatch.setenv('MULTILIFT_KERNEL', 'aot')  # pycc's build is gone, and so is its mode
    with pytest.raises(ValueError, match='expected one of auto, jit, python'):
        laws.runnable(mixer.rotor_speeds)


@pytest.mark.parametrize('name,duration', [('twin_lift', 8.0), ('circle3', 3.0)])
def test_headless_run_compiled_equals_uncompiled_bit_for_bit(monkeypatch, name, duration):
    """The laws compiled and uncompiled under the same (compiled) physics: the same bits;
    and MULTILIFT_KERNEL=python (the physics uncompiled too) within 1e-9 m."""
    base = scenario_io.load(name)
    scenario = dataclasses.replace(base, simulation=dataclasses.replace(
        base.simulation, duration=duration))

    def fly():
        run = run_headless(scenario)
        summary = run.summary()
        summary['sim'].pop('wall_time')
        return run.simulator.state, json.dumps(summary, sort_keys=True, default=str)

    monkeypatch.setenv('MULTILIFT_KERNEL', 'auto')
    compiled = fly()
    with monkeypatch.context() as patch:
        patch.setattr(laws, 'runnable', kernels.uncompiled)
        uncompiled = fly()
    monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
    python = fly()
    assert np.array_equal(compiled[0], uncompiled[0])
    assert compiled[1] == uncompiled[1]
    assert np.abs(compiled[0] - python[0]).max() < 1e-9
    assert np.abs(compiled[0] - FormationSimulator(scenario).state).max() > 0.1  # it flew
