"""The control laws compiled (multilift_control._numba_laws) against their pure-Python
methods, the reference: the same controller built with the kernels on and off
(MULTILIFT_KERNEL) answers the same states with the same numbers (1e-12 relative: numpy's
small products may add in another order), remembers the same integrals and lifts, and a whole
headless run flies the same trajectory."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from multilift_control.cascade import (COMPILED_LAWS, CascadeController, FormationStates,
                                      UavState)
from multilift_control.formation import FormationFollower
from multilift_control.headless import run_headless
from multilift_control.mission import MissionPath
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io

pytest.importorskip('numba')


def _both(monkeypatch, build):
    """(compiled, pure) objects of `build()`: the kernels on, then off, at construction."""
    monkeypatch.setenv('MULTILIFT_KERNEL', 'auto')
    assert kernels.compiled_module(COMPILED_LAWS) is not None
    compiled = build()
    monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
    assert kernels.compiled_module(COMPILED_LAWS) is None
    return compiled, build()


def _close(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.allclose(a, b, rtol=1e-12, atol=1e-12)


def _same_output(a, b) -> None:
    assert _close(a.rotor_speeds, b.rotor_speeds)
    assert np.array_equal(a.saturated, b.saturated)
    assert _close(a.attitude_setpoint, b.attitude_setpoint)
    assert _close(a.thrust, b.thrust)


def _random_state(rng, scale: float = 1.0, tilt: float = 0.6) -> UavState:
    return UavState(position=scale * rng.normal(size=3), velocity=scale * rng.normal(size=3),
                    euler=rng.uniform(-tilt, tilt, size=3) * np.array([1, 1, 5]),
                    body_rates=tilt * rng.normal(size=3))


def test_cascade_compiled_equals_pure_through_saturation(monkeypatch):
    scenario = scenario_io.load('twin_lift')
    vehicle, gains = scenario.uavs[0].vehicle, scenario.control
    compiled, pure = _both(monkeypatch, lambda: CascadeController(vehicle, gains, 2.9, 9.81))
    rng = np.random.default_rng(11)
    saturated_ticks, clamped_ticks = 0, 0
    for tick in range(300):
        t = 0.01 * tick
        # near hover at first, then far away (the rotors saturate, the integral clamps)
        near = tick < 100
        state = _random_state(rng, scale=0.01 if near else 1.0, tilt=0.001 if near else 0.6)
        reach = 0.01 if near else 40.0
        refs = [reach * rng.normal(size=3), reach * rng.normal(size=3),
                reach * rng.normal(size=3)]
        yaw = float(state.euler[2]) if near else float(rng.uniform(-3, 3))
        a = compiled.update(t, state, *refs, yaw_ref=yaw)
        b = pure.update(t, state, *refs, yaw_ref=yaw)
        _same_output(a, b)
        assert _close(compiled.integral, pure.integral)
        saturated_ticks += bool(a.saturated.any())
        clamped_ticks += np.abs(compiled.integral).max() == 0.5 * 9.81
        force = (0.1 if near else 30.0) * rng.normal(size=3) + [0, 0, 30.0]
        _same_output(compiled.command(state, force, yaw), pure.command(state, force, yaw))
    assert 10 < saturated_ticks < 290  # both cases were met
    assert clamped_ticks > 0


@pytest.mark.parametrize('name,own_thrust', [('twin_lift', 'commanded'), ('v5', 'commanded'),
                                             ('v5', 'measured'), ('circle3', 'commanded')])
def test_follower_compiled_equals_pure(monkeypatch, name, own_thrust):
    """Linear and V rows run compiled; a circle's (nonlinear rows) force stays in numpy and
    only its cascade command is compiled."""
    scenario = scenario_io.load(name)
    index = scenario.n_uavs - 1
    compiled, pure = _both(monkeypatch, lambda: FormationFollower.from_scenario(
        scenario, index, own_thrust=own_thrust))
    rng = np.random.default_rng(5)
    for tick in range(200):
        t = 0.01 * tick
        states = FormationStates(_random_state(rng, 3.0) for _ in range(scenario.n_uavs))
        vectors = rng.normal(size=(scenario.n_uavs, 3)) + [0, 0, 30.0]
        vectors.flags.writeable = False  # as the ThrustBook gives them
        out_a, errors_a, rates_a = compiled.update(t, states, vectors)
        out_b, errors_b, rates_b = pure.update(t, states, vectors)
        _same_output(out_a, out_b)
        assert _close(errors_a, errors_b) and _close(rates_a, rates_b)
        assert _close(compiled.lift, pure.lift)
        assert compiled.integral == pytest.approx(pure.integral, rel=1e-12, abs=1e-12)
    assert compiled.lift is not None and compiled.integral != 0.0


def test_filtered_mission_compiled_equals_pure(monkeypatch):
    mission = scenario_io.load('twin_lift').mission
    assert mission.reference_filter_time > 0
    compiled, pure = _both(monkeypatch, lambda: MissionPath(mission))
    for t in np.r_[-1.0, np.linspace(0.0, 130.0, 2601)]:
        a, b = compiled(t), pure(t)
        for field in ('position', 'velocity', 'acceleration'):
            assert _close(getattr(a, field), getattr(b, field)), (t, field)


def test_headless_run_compiled_equals_pure(monkeypatch):
    base = scenario_io.load('twin_lift')
    scenario = dataclasses.replace(base, simulation=dataclasses.replace(
        base.simulation, duration=8.0))
    monkeypatch.setenv('MULTILIFT_KERNEL', 'auto')
    compiled = run_headless(scenario)
    monkeypatch.setenv('MULTILIFT_KERNEL', 'python')
    pure = run_headless(scenario)
    assert np.abs(compiled.simulator.state - pure.simulator.state).max() < 1e-9
    a, b = compiled.summary(), pure.summary()
    for key in ('leader', 'follower2'):
        for figure, value in a[key].items():
            assert value == pytest.approx(b[key][figure], rel=1e-9, abs=1e-12), (key, figure)
