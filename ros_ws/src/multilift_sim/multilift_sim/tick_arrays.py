"""The arrays the physics' half of a tick (`physics.tick`) reads and writes, named once.

`PhysicsArrays` holds what a run does not change, `PhysicsMemory` what a tick changes; every
field has the batch axis first (B formations; the simulator's batch is one). The engine's
arrays (`multilift_control.engine.arrays`) carry these same fields and the controllers' after
them, so the compiled functions of `physics.tick` serve both. Both are built here, from one
scenario, by `physics_fields`: the events, the unsteady wind and the sensors' draws once per
run. Units: SI, world frame z up (docs/conventions.md).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from multilift_sim.cables import CABLE_MODELS
from multilift_sim.formulations import Formulation, make_formulation
from multilift_sim.physics.layout import (CLEARANCE_COLUMNS, CLEARANCE_KINDS, CLEARANCE_VALUE,
                                          REEL_COLUMNS, REEL_LENGTH, STATUS_QUATERNION,
                                          STATUS_NOT_FINITE,
                                          STATUS_OFF_CONSTRAINT, STATUS_OFF_RATE, STATUS_RUNNING)
from multilift_sim.scenario import Scenario
from multilift_sim.scenario.world import world_arrays
from multilift_sim.schedules import event_array, wind_series
from multilift_sim.estimators.arrays import estimator_arrays
from multilift_sim.payload_estimators.arrays import payload_estimator_arrays
from multilift_sim.sensors.arrays import sensor_arrays
from multilift_sim.start import cable_reach, initial_state, swing_sampling
from multilift_sim.statistics import RunStatistics
from multilift_sim.statistics.layout import (CHECK_QUATERNION, CHECK_G, CHECK_G_DOT,
                                             CHECK_NON_FINITE)


class PhysicsArrays(NamedTuple):
    """What does not change during a run, for B formations (first axis)."""
    uavs: np.ndarray              # (B, n, UAV_COLUMNS)
    gusts: np.ndarray             # (B, k, GUST_COLUMNS)
    formation: np.ndarray         # (B, FORMATION_SCALARS)
    allocation: np.ndarray        # (B, n, 4, rotors): wrench per omega^2 (seed Eq. 2.14),
    #                               a UAV with fewer rotors padded with zero columns
    actuators: np.ndarray         # (B, n, ACTUATOR_COLUMNS): each UAV's rotor lag and rate limit
    rotor_speed_max: np.ndarray   # (B, n) [rad/s]: each UAV's rotors' largest speed
    cable_lengths: np.ndarray     # (B, n) [m]
    slack: np.ndarray             # (B,) bool: cable_model slack (else rigid)
    events: np.ndarray            # (B, k, EVENT_COLUMNS): the scenario's events in time order
    wind_series: np.ndarray       # (B, ticks + 1 or 0, 3): the unsteady wind by tick [m/s]
    state_size: np.ndarray        # (B,) int: the state's length (a rigid payload adds its attitude)
    # what the controllers receive (`sensors:`; K sensors, 0: none; sensors.arrays)
    sensor_models: np.ndarray     # (B, K) int: each sensor's model (index in SENSOR_MODELS)
    sensor_constants: np.ndarray  # (B, K, C): each one's constants row (its model's slots)
    sensor_draws: np.ndarray      # (B, K, n, S, D): every sample's draws, by UAV
    # the estimator of every UAV (`estimator:`; E = 1, 0: none; estimators.arrays)
    estimator_models: np.ndarray  # (B, E) int: its index in ESTIMATORS
    estimator_constants: np.ndarray  # (B, E, C): its constants row
    # the payload's estimator (`payload_estimator:`; P = 1, 0: none; payload_estimators.arrays)
    payload_estimator_models: np.ndarray  # (B, P) int: its index in PAYLOAD_ESTIMATORS
    payload_estimator_constants: np.ndarray  # (B, P, C): its constants row
    # time and Algorithm 1's tolerances
    physics_dt: np.ndarray        # (B,) [s]
    physics_steps: np.ndarray     # (B,) int: RK4 steps per control period
    period_ns: np.ndarray         # (B,) int: the control period [ns]
    tick_count: np.ndarray        # (B,) int: control periods of the run
    tolerances: np.ndarray        # (B, 2): |g| [m^2], |g_dot| [m^2/s]
    swing_every: np.ndarray       # (B,) int: the payload swing sampled every this many ticks
    reach: np.ndarray             # (B, n) [m]: each cable's reach for the swing's equilibrium
    # the world the clearances are measured against (`world:`; physics.clearance)
    world: np.ndarray             # (B, WORLD_COLUMNS): checked, ground, payload radius, record
    obstacles: np.ndarray         # (B, k, OBSTACLE_COLUMNS): the obstacles (k = 0: none)
    uav_radii: np.ndarray         # (B, n) [m]: each UAV's sphere (vehicle.radius)


class PhysicsMemory(NamedTuple):
    """What a tick changes, for B formations (first axis)."""
    state: np.ndarray             # (B, state_size): the formation state at the current tick
    taut: np.ndarray              # (B, n) bool: which cables are taut
    rotors: np.ndarray            # (B, n, rotors): rotor speeds [rad/s], NaN before a command
    effectiveness: np.ndarray     # (B, n, rotors): each rotor's share of its thrust, in [0, 1]
    released: np.ndarray          # (B, n) bool: the cables let go of for good (events)
    next_event: np.ndarray        # (B,) int: the row of the next event to come
    silent_until: np.ndarray      # (B, n) int: the first tick a silent controller is heard
    held: np.ndarray              # (B, n, rotors): the commands applied last [rad/s] (NaN: none)
    held_saturated: np.ndarray    # (B, n, rotors) bool: their saturation flags
    tick: np.ndarray              # (B,) int: control periods flown
    status: np.ndarray            # (B,) int: STATUS_RUNNING, _FINISHED or why it stopped
    worst_cable: np.ndarray       # (B,) int: the cable of a stop (from 0)
    worst_value: np.ndarray       # (B,): its |g| or |g_dot|
    g: np.ndarray                 # (B, n): g at the current tick [m^2]
    g_dot: np.ndarray             # (B, n): g_dot at the current tick [m^2/s]
    gust: np.ndarray              # (B, 3): the air velocity at the payload [m/s], world
    sensor_memory: np.ndarray     # (B, K, n, M): each sensor's memory of each UAV
    estimator_memory: np.ndarray  # (B, E, n, M): the estimator's memory of each UAV
    payload_estimator_memory: np.ndarray  # (B, P, M): the payload estimator's memory
    cable_tension: np.ndarray     # (B, n): each cable's tension T_i [N] at the last tick flown
    #                               (advance's; NaN before the first): what a load cell reads
    run: np.ndarray               # (B, run_size(n)): the run's figures (statistics RUN_*)
    reel: np.ndarray              # (B, n, REEL_COLUMNS): each cable's length [m], its reel's
    #                               rate [m/s] and command [m/s] (physics.winch)
    clearance: np.ndarray         # (B, CLEARANCE_KINDS, CLEARANCE_COLUMNS): least of each kind
    contact: np.ndarray           # (B, CLEARANCE_COLUMNS): the first contact (KIND -1: none)


def physics_fields(scenario: Scenario, model: Formulation | None = None) -> tuple[dict, dict]:
    """One formation's (PhysicsArrays fields, PhysicsMemory fields), without the batch axis,
    from `model` (the formulation `simulation.integrator` names, made here if not given: its
    constants, in the null-space form where it says so)."""
    n = scenario.n_uavs
    sim = scenario.simulation
    cables = CABLE_MODELS[scenario.cable_model]
    if model is None:
        model = make_formulation(sim.integrator, scenario.formation_params(),
                                 scenario.cable_model)
    uavs, gusts, formation, allocation, actuators = model.physics_constants()
    sensors = sensor_arrays(scenario)
    estimator = estimator_arrays(scenario)
    payload_estimator = payload_estimator_arrays(scenario)
    state = initial_state(scenario)
    rotors = allocation.shape[::2]  # (n, the largest rotor count)
    arrays = dict(
        uavs=uavs, gusts=gusts, formation=formation, allocation=allocation, actuators=actuators,
        rotor_speed_max=np.array([u.vehicle.rotor_speed_max for u in scenario.uavs]),
        cable_lengths=np.array([u.cable_length for u in scenario.uavs], dtype=float),
        slack=cables.SLACKENS, events=event_array(scenario),
        wind_series=wind_series(scenario), state_size=state.size,
        sensor_models=sensors.models, sensor_constants=sensors.constants,
        sensor_draws=sensors.draws, estimator_models=estimator.models,
        estimator_constants=estimator.constants,
        payload_estimator_models=payload_estimator.models,
        payload_estimator_constants=payload_estimator.constants,
        physics_dt=1.0 / sim.physics_rate, physics_steps=sim.physics_steps_per_tick,
        period_ns=int(round(1e9 / sim.control_rate)), tick_count=sim.tick_count,
        # (cables that stretch are no constraints: Algorithm 1's check of g does not apply)
        tolerances=(np.array([sim.constraint_tolerance, sim.constraint_rate_tolerance])
                    if cables.KEEPS_LENGTH and not any(u.cable_stiffness for u in scenario.uavs)
                    else np.full(2, math.inf)),
        swing_every=swing_sampling(n), reach=cable_reach(scenario),
        **dict(zip(('world', 'obstacles', 'uav_radii'), world_arrays(scenario))))
    clearance = np.zeros((CLEARANCE_KINDS, CLEARANCE_COLUMNS))
    clearance[:, CLEARANCE_VALUE] = math.inf  # none measured yet
    memory = dict(
        state=state, taut=np.ones(n, dtype=bool), rotors=np.full(rotors, math.nan),
        effectiveness=np.ones(rotors), released=np.zeros(n, dtype=bool), next_event=0,
        silent_until=np.zeros(n, dtype=np.int64), held=np.full(rotors, math.nan),
        held_saturated=np.zeros(rotors, dtype=bool), tick=0, status=STATUS_RUNNING,
        worst_cable=0, worst_value=0.0, g=np.zeros(n), g_dot=np.zeros(n), gust=np.zeros(3),
        sensor_memory=sensors.memory, estimator_memory=estimator.memory,
        payload_estimator_memory=payload_estimator.memory, cable_tension=np.full(n, math.nan),
        run=RunStatistics(n).run, reel=reel_memory(scenario),
        clearance=clearance, contact=np.full(CLEARANCE_COLUMNS, -1.0))
    return arrays, memory


def reel_memory(scenario: Scenario) -> np.ndarray:
    """Each cable's reel at the start (n, REEL_COLUMNS): its length [m], at rest, commanded
    to rest (every cable's, with a winch or not: the tension's l_i)."""
    reel = np.zeros((scenario.n_uavs, REEL_COLUMNS))
    reel[:, REEL_LENGTH] = [u.cable_length for u in scenario.uavs]
    return reel


def stacked(name: str, values: Sequence) -> np.ndarray:
    """The formations' values of field `name` stacked along a new first (batch) axis."""
    shapes = {np.shape(v) for v in values}
    if len(shapes) != 1:
        raise ValueError(f'the formations of a batch differ in the shape of {name}: '
                         f'{sorted(shapes)} (one batch: the same n, rotors, gusts, mission '
                         'segments and formation rows)')
    return np.ascontiguousarray(np.stack([np.asarray(v) for v in values]))


# a stopped formation's status -> the check's code (the words: simulation.stop_message)
STOP_CHECKS = {STATUS_NOT_FINITE: CHECK_NON_FINITE, STATUS_OFF_CONSTRAINT: CHECK_G,
               STATUS_OFF_RATE: CHECK_G_DOT, STATUS_QUATERNION: CHECK_QUATERNION}
