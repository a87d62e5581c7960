"""Each UAV's attitude is a unit quaternion with body rates (issue 31 item 6): a UAV tumbles
through any attitude (the ZYX Euler angles of the seed, Eq. 2.6, were singular at 90 deg
pitch, and a learning run's rates reached 1e152 rad/s there), the compiled path follows
Euler's rigid-body equations (Eq. 2.28) to their closed form and invariants, and a state that
is no attitude stops the run with a named reason, in the simulator and the engine alike."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from multilift_control.engine import Engine
from multilift_sim import kernels
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout, constant_arrays
from multilift_sim.physics.formation_dae import integrate_period
from multilift_sim.physics.layout import WRENCH_COLUMNS
from multilift_sim.simulation import FormationSimulator, SimulationStopped
from multilift_sim.statistics.layout import QUATERNION_NORM_TOLERANCE

PITCH_RATE = 8.0  # [rad/s]: a UAV tumbling nose-up, through 90 deg within 0.2 s


def _quaternion_product(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """p (x) q of quaternions (w, x, y, z)."""
    return np.concatenate(([p[0] * q[0] - p[1:] @ q[1:]],
                           p[0] * q[1:] + q[0] * p[1:] + np.cross(p[1:], q[1:])))


def _rotation(q: np.ndarray) -> np.ndarray:
    """R, body -> world, of a unit quaternion (w, x, y, z) (written out here, independently of
    physics.attitude)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def test_a_uav_tumbles_through_90_degrees_and_follows_the_closed_form_rotation():
    """UAV 1 of the single lift spun nose-up at 8 rad/s about its body y axis (a principal
    axis; equal rotor speeds and a cable through its centre of mass: no torque) for 1 s
    (458 deg, through +-90 deg pitch twice): q(t) = q_0 (x) (cos(w t / 2), 0, sin(w t / 2), 0)
    to 1e-9, the pitch output through its whole range, nothing stopped."""
    scenario = scenario_io.load('single_lift_swing')
    sim = FormationSimulator(scenario)
    layout = StateLayout(1)
    x = sim.state
    layout.uav_body_rates(x)[0] = (0.0, PITCH_RATE, 0.0)
    sim.state = x
    start = layout.uav_quaternions(x)[0].copy()
    hover, idle = [np.full(4, 1500.0)], [np.zeros(4, bool)]
    pitches = []
    for tick in range(1, 101):
        sim.advance(hover, idle)
        t = tick / scenario.simulation.control_rate
        half = 0.5 * PITCH_RATE * t
        expected = _quaternion_product(start, np.array([math.cos(half), 0.0, math.sin(half),
                                                        0.0]))
        quaternion = layout.uav_quaternions(sim.state)[0]
        assert np.abs(quaternion - expected).max() < 1e-9, (tick, quaternion, expected)
        assert np.abs(layout.uav_body_rates(sim.state)[0] - (0.0, PITCH_RATE, 0.0)).max() < 1e-12
        pitches.append(float(layout.uav_euler(sim.state)[0, 1]))
    assert PITCH_RATE * 1.0 > 2.0 * math.pi       # a full turn and more
    assert max(pitches) > math.radians(89.0) and min(pitches) < -math.radians(89.0)
    assert np.isfinite(sim.state).all() and np.abs(sim.state).max() < 1e3


def _free_uav(inertia=(0.01, 0.02, 0.04)):
    """The single lift's arrays with UAV 1 of an asymmetric inertia [kg m^2] and its cable
    slack (no constraint: the UAV is a free rigid body), zero wrenches (torque free)."""
    scenario = scenario_io.load('single_lift_swing')
    params = scenario.formation_params(None, None)
    uav = dataclasses.replace(params.uavs[0], inertia=inertia)
    params = dataclasses.replace(params, uavs=(uav,), payload_drag_coefficient=0.0)
    uavs, gusts, formation = constant_arrays(params)
    x = FormationSimulator(scenario).state
    layout = StateLayout(1)
    layout.set_uav_euler(x, [[0.3, -0.7, 2.0]])
    layout.uav_body_rates(x)[0] = (0.1, 2.0, -0.1)  # near the intermediate axis: it flips
    return x, uavs, gusts, formation, np.zeros((1, WRENCH_COLUMNS)), np.zeros(1, bool)


def _invariants(x: np.ndarray, inertia: np.ndarray) -> tuple[float, np.ndarray]:
    """(rotational kinetic energy 1/2 w.J w [J], angular momentum R J w [kg m^2/s], world)."""
    layout = StateLayout(1)
    omega = layout.uav_body_rates(x)[0]
    return (0.5 * float(omega @ (inertia * omega)),
            _rotation(layout.uav_quaternions(x)[0]) @ (inertia * omega))


def test_a_torque_free_tumble_keeps_energy_and_angular_momentum():
    """An asymmetric UAV spun near its intermediate axis (it flips, Dzhanibekov) for 5 s of
    1 ms RK4 steps through the compiled period: its rotational kinetic energy and its angular
    momentum in the world frame stay to 1e-9 relative, and it did tumble."""
    x, uavs, gusts, formation, wrenches, taut = _free_uav()
    inertia = np.array([0.01, 0.02, 0.04])
    energy, momentum = _invariants(x, inertia)
    states = [x]
    for _ in range(50):  # 50 periods of 100 steps of 1 ms
        states.append(integrate_period(states[-1], wrenches, uavs, gusts, formation, taut,
                                       1e-3, 100)[0])
    for state in states[1:]:
        energy_k, momentum_k = _invariants(state, inertia)
        assert abs(energy_k - energy) <= 1e-9 * energy
        assert np.linalg.norm(momentum_k - momentum) <= 1e-9 * np.linalg.norm(momentum)
        assert abs(np.linalg.norm(StateLayout(1).uav_quaternions(state)[0]) - 1.0) < 1e-14
    rates_y = [StateLayout(1).uav_body_rates(s)[0, 1] for s in states]
    assert max(rates_y) > 1.9 and min(rates_y) < -1.9       # it flipped over


def test_the_compiled_tumble_is_its_source_bit_for_bit():
    x, uavs, gusts, formation, wrenches, taut = _free_uav()
    compiled = integrate_period(x, wrenches, uavs, gusts, formation, taut, 1e-3, 20)
    python = kernels.uncompiled(integrate_period)(x, wrenches, uavs, gusts, formation, taut,
                                                  1e-3, 20)
    for a, b in zip(compiled, python):
        assert np.array_equal(a, b)


def _broken(state: np.ndarray, n: int) -> np.ndarray:
    x = state.copy()
    StateLayout(n).uav_quaternions(x)[n - 1] *= 1.0 + 10.0 * QUATERNION_NORM_TOLERANCE
    return x


def test_a_state_that_is_no_attitude_stops_the_run_naming_the_uav():
    scenario = scenario_io.load('twin_lift').with_duration(2.0)
    sim = FormationSimulator(scenario)
    x = _broken(sim.state, 2)
    sim.state = x
    hover, idle = [np.full(4, 1500.0)] * 2, [np.zeros(4, bool)] * 2
    with pytest.raises(SimulationStopped) as stop:
        sim.advance(hover, idle)
    message = str(stop.value)
    assert message.startswith('uav2: its attitude quaternion\'s norm is 1e-08 off 1 at '
                              't = 0.000 s'), message
    assert np.array_equal(sim.state, x)              # not integrated


def test_a_non_finite_state_stops_the_run_by_name():
    scenario = scenario_io.load('twin_lift').with_duration(2.0)
    sim = FormationSimulator(scenario)
    x = sim.state
    StateLayout(2).uav_body_rates(x)[0, 2] = math.inf
    sim.state = x
    with pytest.raises(SimulationStopped) as stop:
        sim.advance([np.full(4, 1500.0)] * 2, [np.zeros(4, bool)] * 2)
    assert str(stop.value) == 'the formation state became non-finite at t = 0.010 s'


def test_the_engine_stops_the_same_formation_with_the_same_words():
    scenario = scenario_io.load('twin_lift').with_duration(2.0)
    sim = FormationSimulator(scenario)
    engine = Engine(scenario)
    x = _broken(sim.state, 2)
    sim.state = x
    engine.memory.state[0, :] = x
    speeds = engine.answer()[0][0].copy()  # the controllers' first answer
    flags = np.zeros(speeds.shape, bool)
    with pytest.raises(SimulationStopped) as stop:
        sim.advance(list(speeds), list(flags))
    engine.step_commanded(speeds[None], flags[None])
    assert engine.stopped[0] and engine.stop_reason(0) == str(stop.value)
    assert np.array_equal(engine.state[0], sim.state)
