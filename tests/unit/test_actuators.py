"""Rotor actuators (multilift_sim.physics.actuators, issue 21 item 1): each rotor's speed
follows its command through a first-order lag with a rate limit, its thrust and moment scaled
by an effectiveness.

Held against their definitions: the lag's step response against a fine numerical solution of
d omega/dt = clip((omega_c - omega) / tau_m, -rate_max, rate_max); a climbing single-lift's
velocity against the quadrature of the lagging thrust; instant rotors against the seed's
held-wrench integration to the bit; the engine against the per-object run (FormationSimulator,
the ROS path) to the bit with lagging rotors; compiled against the uncompiled run."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import yaml

from conftest import SCENARIOS
from multilift_control.engine import Engine
from multilift_control.headless import run_headless
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import actuator_array
from multilift_sim.physics.actuators import actuated_period, rotor_speed_at
from multilift_sim.physics.allocation import rotor_wrenches
from multilift_sim.physics.formation_dae import integrate_period
from multilift_sim.physics.layout import (ACTUATOR_TIME_CONSTANT, FORMATION_SUBSTEPS,
                                          WRENCH_COLUMNS)
from multilift_sim.start import initial_state


def _lag_ode(start, command, time_constant, rate_limit, s, steps=20000):
    """omega(s) by RK4 on the lag's own definition (independent of the closed form); without a
    lag, the rate limit's steps, each stopping at the command."""
    h, omega = s / steps, start
    if time_constant <= 0.0:
        for _ in range(steps):
            omega += max(-rate_limit * h, min(rate_limit * h, command - omega))
        return omega

    def rate(omega):
        return max(-rate_limit, min(rate_limit, (command - omega) / time_constant))
    for _ in range(steps):
        k1 = rate(omega)
        k2 = rate(omega + 0.5 * h * k1)
        k3 = rate(omega + 0.5 * h * k2)
        k4 = rate(omega + h * k3)
        omega += h / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
    return omega


@pytest.mark.parametrize('start,command,time_constant,rate_limit', [
    (1000.0, 1400.0, 0.05, math.inf),      # the lag alone: never reaches the rate limit
    (1400.0, 900.0, 0.05, 4000.0),         # a ramp down at the limit, then the lag
    (1000.0, 1100.0, 0.02, 20000.0),       # a small step, under the limit throughout
    (800.0, 1600.0, 0.0, 10000.0)])        # no lag: the ramp, then the command
def test_the_step_response_is_the_lag_s_solution(start, command, time_constant, rate_limit):
    for s in (0.004, 0.02, 0.05, 0.1, 0.3):
        expected = _lag_ode(start, command, time_constant, rate_limit, s)
        got = rotor_speed_at(start, command, time_constant, rate_limit, s)
        assert got == pytest.approx(expected, abs=1e-6 * abs(command - start))
        assert got == kernels.uncompiled(rotor_speed_at)(start, command, time_constant,
                                                         rate_limit, s)
    if math.isinf(rate_limit):  # the first-order step response: 63.2 % of the step at tau_m
        at_tau = rotor_speed_at(start, command, time_constant, rate_limit, time_constant)
        assert (at_tau - start) / (command - start) == pytest.approx(1.0 - math.exp(-1.0),
                                                                     abs=1e-12)
    assert rotor_speed_at(start, command, 0.0, math.inf, 1e-9) == command  # instant rotors


def _vehicle_lag(scenario, time_constant, rate_limit=math.inf):
    return dataclasses.replace(scenario, uavs=tuple(dataclasses.replace(
        u, vehicle=dataclasses.replace(u.vehicle, motor_time_constant=time_constant,
                                       motor_rate_limit=rate_limit)) for u in scenario.uavs))


def test_a_lagging_climb_integrates_the_lagging_thrust():
    """A level single-lift at rest, without drag, its rotors commanded from hover to 10 %
    more: UAV and payload climb as one body, (m + m_p) v_dot = 4 k_T omega(t)^2 - (m + m_p) g,
    omega(t) the lag's step response. Each 5 ms RK4 step's held rotors (the step's mean of
    omega^2) give the velocity to the quadrature's to 1e-6 relative."""
    scenario = _vehicle_lag(scenario_io.load('single_lift'), 0.05, 6000.0)
    scenario = dataclasses.replace(scenario, payload=dataclasses.replace(
        scenario.payload, drag_coefficient=0.0))
    vehicle = scenario.uavs[0].vehicle
    model = FormationModel(scenario.formation_params())
    total = vehicle.mass + scenario.payload.mass
    hover = math.sqrt(total * 9.81 / (4 * vehicle.thrust_coefficient))
    command = 1.1 * hover
    model.rotors[:] = hover
    x, dt, steps, periods = initial_state(scenario), 0.005, 2, 40
    for _ in range(periods):
        x = model.integrate(x, [np.full(4, command)], dt, steps).state
    duration = periods * steps * dt
    s = np.linspace(0.0, duration, 40001)
    omega = np.array([rotor_speed_at(hover, command, 0.05, 6000.0, t) for t in s])
    acceleration = 4 * vehicle.thrust_coefficient * omega ** 2 / total - 9.81
    velocity = np.sum(0.5 * (acceleration[1:] + acceleration[:-1]) * np.diff(s))
    layout = model.layout
    assert layout.uav_velocities(x)[0, 2] == pytest.approx(velocity, rel=1e-6)  # UAV climbs ...
    assert layout.payload_velocity(x)[2] == pytest.approx(velocity, rel=1e-6)  # ... the payload
    assert velocity > 0.05  # it did climb
    assert model.rotors[0] == pytest.approx(
        [rotor_speed_at(hover, command, 0.05, 6000.0, duration)] * 4, rel=1e-15)


def test_instant_rotors_are_the_seed_s_held_wrenches_to_the_bit():
    scenario = scenario_io.load('circle3')
    model = FormationModel(scenario.formation_params())
    rng = np.random.default_rng(7)
    speeds = rng.uniform(1000.0, 1500.0, size=(3, 4))
    x = initial_state(scenario)
    wrenches = np.empty((3, WRENCH_COLUMNS))
    rotor_wrenches(model.allocation, speeds, np.ones((3, 4)), wrenches)
    expected = integrate_period(x, wrenches, model._uavs, model._gusts, model._formation,
                                np.ones(3, dtype=bool), 0.005, 2)
    got = model.integrate(x, list(speeds), 0.005, 2)
    assert np.array_equal(got.state, expected[0])
    assert np.array_equal(got.cable_tension, 2.0 * model.cable_lengths * expected[1])
    assert np.isnan(model.rotors).all()  # not kept: instant rotors are their commands


@pytest.mark.parametrize('cables', ['rigid', 'slack'])
def test_the_engine_flies_lagging_rotors_as_the_ros_path_does(cables):
    base = scenario_io.load('twin_lift').with_duration(8.0)
    scenario = dataclasses.replace(_vehicle_lag(base, 0.03, 8000.0), cable_model=cables)
    engine = Engine(scenario)
    engine.step(10 ** 6)
    run = run_headless(scenario)
    assert engine.finished[0]
    assert np.array_equal(engine.state[0], run.simulator.state)
    assert np.array_equal(engine.memory.rotors[0], run.simulator.rotors)
    instant = Engine(base)
    instant.step(10 ** 6)
    assert np.abs(instant.state[0] - engine.state[0]).max() > 1e-4  # the lag did something
    assert engine.summary(0)['sim']['max_abs_constraint'] < base.simulation.constraint_tolerance


def test_compiled_equals_its_uncompiled_run():
    scenario = _vehicle_lag(scenario_io.load('circle3'), 0.04, 5000.0)
    model = FormationModel(scenario.formation_params())
    rng = np.random.default_rng(3)
    commands = rng.uniform(1000.0, 1500.0, size=(3, 4))
    start = rng.uniform(1000.0, 1500.0, size=(3, 4))
    effectiveness = np.ones((3, 4))
    effectiveness[1, 2] = 0.4
    x = initial_state(scenario)
    results = []
    for function in (actuated_period, kernels.uncompiled(actuated_period)):
        rotors = start.copy()
        out = function(x, commands, rotors, actuator_array(scenario.formation_params()),
                       effectiveness, model.allocation, model._uavs, model._gusts,
                       model._formation, np.ones(3, dtype=bool), np.zeros(3, dtype=bool),
                       False, 0.005, 2)
        results.append((out, rotors))
    (compiled, compiled_rotors), (python, python_rotors) = results
    for a, b in zip(compiled, python):
        assert np.array_equal(a, b)
    assert np.array_equal(compiled_rotors, python_rotors)
    assert not np.array_equal(compiled_rotors, commands)  # still on their way


def _edited(edit) -> str:
    data = yaml.safe_load((SCENARIOS / 'twin_lift.yaml').read_text())
    edit(data)
    return yaml.safe_dump(data)


def test_actuator_keys_are_validated():
    s = scenario_io.loads(_edited(lambda d: d['vehicle'].update(
        motor_time_constant=0.03, motor_rate_limit=9000.0)))
    assert {(u.vehicle.motor_time_constant, u.vehicle.motor_rate_limit) for u in s.uavs} == {
        (0.03, 9000.0)}
    default = scenario_io.load('twin_lift').uavs[0].vehicle
    assert (default.motor_time_constant, default.motor_rate_limit) == (0.0, math.inf)
    s = scenario_io.loads(_edited(lambda d: d['uavs'][1].update(
        motor_time_constant=0.05)))  # one UAV's own actuators
    assert [u.vehicle.motor_time_constant for u in s.uavs] == [0.0, 0.05]
    for edit, message in [
            (lambda d: d['vehicle'].update(motor_time_constant=-0.01),
             'vehicle.motor_time_constant'),
            (lambda d: d['vehicle'].update(motor_rate_limit=0.0), 'vehicle.motor_rate_limit'),
            (lambda d: (d['vehicle'].update(motor_time_constant=0.02),
                        d['simulation'].update(integrator='nullspace')),
             'need simulation.integrator: baumgarte')]:
        with pytest.raises(scenario_io.ScenarioError, match=message):
            scenario_io.loads(_edited(edit), 'x.yaml')


@pytest.mark.parametrize('lag', [False, True], ids=['instant', 'lagging'])
@pytest.mark.parametrize('slack', [False, True], ids=['rigid', 'slack'])
def test_k_substeps_are_the_period_in_k_times_finer_steps(lag, slack):
    """FORMATION_SUBSTEPS = k (docs/architecture.md, "The stepper"): the period's `steps`
    physics steps of dt taken as k RK4 steps of dt / k each, the same bits as the period
    asked for in k * steps steps of dt / k (instant or lagging rotors, rigid or slack cables;
    compiled and uncompiled alike); k = 1 is dt itself; and finer, closer to a reference of
    much finer steps."""
    scenario = scenario_io.load('twin_lift')
    model = FormationModel(scenario.formation_params())
    actuators = actuator_array(scenario.formation_params())
    if lag:
        actuators[:, ACTUATOR_TIME_CONSTANT] = 0.03
    rng = np.random.default_rng(5)
    x = initial_state(scenario)
    model.layout.rates(x)[:] = rng.normal(0.0, 0.3, model.layout.n_coordinates)
    model.layout.uav_body_rates(x)[:] = rng.normal(0.0, 1.0, (2, 3))
    commands = rng.uniform(1300.0, 1700.0, size=(2, 4))
    start = rng.uniform(1300.0, 1700.0, size=(2, 4))
    dt, steps = 0.005, 2

    def period(substeps, h, count, function=actuated_period):
        formation = model._formation.copy()
        formation[FORMATION_SUBSTEPS] = substeps
        return function(x, commands, start.copy(), actuators, np.ones((2, 4)), model.allocation,
                        model._uavs, model._gusts, formation, np.ones(2, dtype=bool),
                        np.zeros(2, dtype=bool), slack, h, count)

    for k in (1, 3):
        finer = period(1, dt / k, steps * k)
        for function in (actuated_period, kernels.uncompiled(actuated_period)):
            for a, b in zip(period(k, dt, steps, function), finer):
                assert np.array_equal(a, b)
    reference = period(1, dt / 64, steps * 64)[0]
    coarse, fine = period(1, dt, steps)[0], period(4, dt, steps)[0]
    assert np.abs(fine - reference).max() < 0.1 * np.abs(coarse - reference).max()
