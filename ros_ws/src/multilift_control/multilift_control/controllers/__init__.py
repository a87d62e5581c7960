"""The leader and follower controllers as registered parts (issue 31): one module per law,
`LEADER_CONTROLLERS` (`control.mode`: UAV 1's) and `FOLLOWER_CONTROLLERS` (`control.follower`:
UAVs 2..n) the registries (name -> module; the dicts of `multilift_sim.scenario.controllers`,
which the scenario's validation reads). docs/extending.md adds one of each.

A leader's module declares:
- `NAME` (the scenario's `control.mode`), `KEYS` (its own keys in `control:`) and with keys
  `parse(c) -> dict` (ControlConfig fields, its own values in `values`);
- `TRACKS_MISSION`: True when it answers with the mission reference (`/uav1/reference`);
- `arrays(scenario, index) -> (constants, memory)`: its float arrays, slots named in its
  module, built once (memory: its state at t = 0);
- `answer(constants, memory, cascade, mixer, mission, segments, steps, t, states,
  payload_position, payload_velocity, speeds, saturated, setpoint, reference) -> thrust`,
  compiled (`multilift_control.laws.jit`): its tick at t [s] over one UAV's slice of the
  engine's arrays: cascade the vehicle's CASCADE_* constants, mixer its MIXER_* rows (one per
  rotor it has), the mission's arrays (laws.layout MISSION_*, SEGMENT_*, STEP_*), states (n,
  UAV_STATE_SIZE) every UAV's measured state (its own first), the payload's position [m] and
  velocity [m/s] (world); it writes rotor speeds [rad/s] and saturation flags (one per rotor),
  roll, pitch, yaw asked [rad] and the reference it tracked (REFERENCE_* slots, NaN: none) and
  returns the collective thrust asked [N].

A follower's module declares `NAME` (`control.follower`), `KEYS` (and `parse`), and:
- `arrays(scenario, index) -> (constants, memory, law_p, law_q)`: its float arrays and two
  constant matrices (3, m) and (3, 3n) (the virtual constraints' P and Q; None: zeros);
- `shared(constants, masses, rows, targets, states, vectors) -> terms`, compiled: what every
  follower's law of a tick shares, computed once per tick (any value `answer` reads);
- `answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows, targets,
  law_p, law_q, terms, speeds, saturated, setpoint, errors, rates) -> thrust`, compiled:
  follower `index`'s (from 1) tick; vectors (n, 3) every UAV's lift R e_z u_T [N] (the thrust
  book's: the leader's answer to this state, the other followers' to the previous one),
  masses (n,) [kg], rows and targets the formation's virtual constraint rows (laws.layout
  ROW_*; `multilift_control.virtual_constraints`); errors and rates (its rows of g_vc) to
  write for the run's formation error statistics.

The engine's tick and the runtimes (`LeaderController`, `FollowerController`: the nodes and
`run_headless`) call the parts through the dispatchers generated from the registries
(`compiled`), so a controller's answer exists once. `register_leader`, `register_follower`
(or `registered` for a block) add a part after start-up (a test's toy part).
"""
from __future__ import annotations

import contextlib
import math
from collections.abc import Sequence
from types import ModuleType
from typing import Iterator

import numpy as np

from multilift_control import laws
from multilift_control.cascade import CascadeController, ControlOutput, FormationStates
from multilift_control.controllers import compiled
from multilift_control.controllers.followers import (cable_forces, heading, thrust_margin,
                                                     virtual_constraints)
from multilift_control.controllers.leaders import cascade, constant_rotor_speed
from multilift_control.laws.layout import REFERENCE_SIZE
from multilift_control.mission import MissionPath, Reference
from multilift_control.virtual_constraints import FormationGeometry, VirtualConstraints
from multilift_sim.scenario import INPUT_SHAPERS, Scenario
from multilift_sim.scenario.controllers import FOLLOWER_CONTROLLERS, LEADER_CONTROLLERS
from multilift_sim.start import formation_start, start_lengths

LEADER_REQUIRED = ('NAME', 'KEYS', 'TRACKS_MISSION', 'arrays', 'answer')
FOLLOWER_REQUIRED = ('NAME', 'KEYS', 'arrays', 'shared', 'answer')
SHIPPED_LEADERS = (cascade, constant_rotor_speed)
SHIPPED_FOLLOWERS = (virtual_constraints, thrust_margin, cable_forces, heading)
for _part in SHIPPED_LEADERS:
    LEADER_CONTROLLERS.setdefault(_part.NAME, _part)
for _part in SHIPPED_FOLLOWERS:
    FOLLOWER_CONTROLLERS.setdefault(_part.NAME, _part)
compiled.SHIPPED.append((SHIPPED_LEADERS, SHIPPED_FOLLOWERS))


def _register(registry: dict, required: tuple[str, ...], kind: str, part: ModuleType) -> None:
    missing = [name for name in required if not hasattr(part, name)]
    if missing:
        raise ValueError(f'{kind} controller {part!r} lacks {", ".join(missing)}')
    if part.KEYS and not hasattr(part, 'parse'):
        raise ValueError(f'{kind} controller {part.NAME!r} has keys but no parse')
    if part.NAME in registry:
        raise ValueError(f'{kind} controller {part.NAME!r} is registered already')
    registry[part.NAME] = part
    compiled.refresh()


def register_leader(part: ModuleType) -> None:
    """Add a leader controller (a module, or any object, with LEADER_REQUIRED's names)."""
    _register(LEADER_CONTROLLERS, LEADER_REQUIRED, 'leader', part)


def register_follower(part: ModuleType) -> None:
    """Add a follower controller (a module, or any object, with FOLLOWER_REQUIRED's names)."""
    _register(FOLLOWER_CONTROLLERS, FOLLOWER_REQUIRED, 'follower', part)


def unregister(name: str) -> None:
    """Remove the leader or follower controller `name` that a register_* added."""
    for registry, shipped in ((LEADER_CONTROLLERS, SHIPPED_LEADERS),
                              (FOLLOWER_CONTROLLERS, SHIPPED_FOLLOWERS)):
        if name in registry:
            if registry[name] in shipped:
                raise ValueError(f'controller {name!r} ships with multilift_control')
            del registry[name]
            compiled.refresh()
            return
    raise KeyError(name)


@contextlib.contextmanager
def registered(*parts: ModuleType) -> Iterator[None]:
    """`parts` registered for the block (a test's toy leader and follower): a part with
    `TRACKS_MISSION` is a leader."""
    for part in parts:
        (register_leader if hasattr(part, 'TRACKS_MISSION') else register_follower)(part)
    try:
        yield
    finally:
        for part in parts:
            unregister(part.NAME)


def leader_part(scenario: Scenario) -> ModuleType:
    return LEADER_CONTROLLERS[scenario.control.mode]


def follower_part(scenario: Scenario) -> ModuleType:
    return FOLLOWER_CONTROLLERS[scenario.control.follower]


def law_index(registry: dict, name: str) -> int:
    """A part's index in its registry: its `law` in the dispatchers."""
    return list(registry).index(name)


def vehicle_cascade(scenario: Scenario, index: int) -> CascadeController:
    """UAV `index`'s cascade (its CASCADE_* constants and mixer): the inner loop every law may
    fly through, at its hover mass (the UAV and its payload share), the leader's with the
    swing feedback's rest."""
    uav = scenario.uavs[index]
    hover_mass = uav.vehicle.mass + scenario.payload.mass / scenario.n_uavs
    return CascadeController(uav.vehicle, scenario.control, hover_mass,
                             scenario.simulation.gravity,
                             swing_rest(scenario) if index == 0 else (0.0, 0.0))


def formation_rows(scenario: Scenario) -> tuple[np.ndarray, VirtualConstraints | None]:
    """(masses (n,) [kg]: the UAVs' hover masses, M_f,r; the formation's virtual constraints,
    None for one UAV): what every follower law reads of the formation."""
    n = scenario.n_uavs
    masses = np.array([u.vehicle.mass + scenario.payload.mass / n for u in scenario.uavs])
    if n == 1:
        return masses, None
    return masses, VirtualConstraints(FormationGeometry.from_config(scenario.formation, n))


class LeaderController:
    """UAV 1's controller of `control.mode`: its part's arrays and the compiled answer."""

    def __init__(self, scenario: Scenario, index: int = 0):
        self.part = leader_part(scenario)
        self.law = law_index(LEADER_CONTROLLERS, self.part.NAME)
        self.cascade = vehicle_cascade(scenario, index)
        self.path = MissionPath(scenario.mission, INPUT_SHAPERS[scenario.control.input_shaping],
                                swing_period(scenario), tracked_offset(scenario))
        self.constants, self.memory = (np.asarray(a, dtype=float)
                                       for a in self.part.arrays(scenario, index))
        control = scenario.control
        self.swing_feedback = bool(control.swing_stiffness or control.swing_damping)
        self._answer = laws.runnable(compiled.dispatchers().leader_answer)

    def update(self, t: float, states: FormationStates) -> tuple[ControlOutput, Reference | None]:
        """The answer to the formation's states at t [s] and the reference tracked (or None)."""
        c, p = self.cascade, self.path
        states = FormationStates.of(states)
        payload = states.payload_position, states.payload_velocity
        if payload[0] is None or payload[1] is None:
            if self.swing_feedback:
                raise ValueError('control.payload_feedback needs the payload\'s position and '
                                 'velocity (FormationStates.payload_position, _velocity)')
            payload = np.zeros(3), np.zeros(3)  # not read without the feedback
        rotors = c.mixer.rows.shape[0]
        speeds, saturated = np.zeros(rotors), np.zeros(rotors, dtype=bool)
        setpoint, reference = np.zeros(3), np.empty(REFERENCE_SIZE)
        thrust = self._answer(self.law, self.constants, self.memory, c.constants, c.mixer.rows,
                              p.mission, p.segments, p.steps, float(t), states.array, *payload,
                              speeds, saturated, setpoint, reference)
        output = ControlOutput(speeds, saturated, setpoint, thrust)
        return output, None if math.isnan(reference[0]) else Reference.of(reference)


class FollowerController:
    """Follower UAV `index`'s (>= 1) controller of `control.follower`: its part's arrays and the
    compiled answer (`update`)."""

    def __init__(self, scenario: Scenario, index: int):
        self.part = follower_part(scenario)
        self.law = law_index(FOLLOWER_CONTROLLERS, self.part.NAME)
        self.index = index
        self.cascade = vehicle_cascade(scenario, index)
        self.masses, self.constraints = formation_rows(scenario)
        self.own_rows = len(self.constraints.rows_of(index))
        constants, memory, law_p, law_q = self.part.arrays(scenario, index)
        if law_p is None:  # a part without matrices: zeros
            m, n = self.constraints.rows.shape[0], scenario.n_uavs
            law_p, law_q = np.zeros((3, m)), np.zeros((3, 3 * n))
        self.constants, self.memory, self.law_p, self.law_q = (
            np.asarray(a, dtype=float) for a in (constants, memory, law_p, law_q))
        self._answer = laws.runnable(compiled.dispatchers().follower_answer)

    def update(self, t: float, states: Sequence, thrust_vectors: np.ndarray
               ) -> tuple[ControlOutput, np.ndarray, np.ndarray]:
        """(the answer at t [s], its rows of g_vc [m or m^2], their rates) to every UAV's
        states (UavStates, or the laws' (n, UAV_STATE_SIZE) array) and lifts thrust_vectors
        (n, 3), world [N]."""
        c = self.cascade
        rotors = c.mixer.rows.shape[0]
        speeds, saturated = np.zeros(rotors), np.zeros(rotors, dtype=bool)
        setpoint = np.zeros(3)
        errors, rates = np.full(self.own_rows, math.nan), np.full(self.own_rows, math.nan)
        thrust = self._answer(self.law, self.index, self.constants, self.memory, c.constants,
                              c.mixer.rows, float(t), states if isinstance(states, np.ndarray)
                              else FormationStates.of(states).array,
                              np.asarray(thrust_vectors, dtype=float), self.masses,
                              self.constraints.rows, self.constraints.targets, self.law_p,
                              self.law_q, speeds, saturated, setpoint, errors, rates)
        return ControlOutput(speeds, saturated, setpoint, thrust), errors, rates


def swing_rest(scenario: Scenario) -> tuple[float, float]:
    """s_0 of the swing feedback (`laws.swing`): the payload's (x, y) from the UAVs' mean
    position at the formation's hanging rest [m] (`simulation.formation_start`, without the
    payload.swing_deg release); 0 for one UAV, whose payload hangs straight below."""
    if scenario.n_uavs == 1:
        return 0.0, 0.0
    uavs, payload = formation_start(scenario)
    offset = payload - uavs.mean(axis=0)
    return float(offset[0]), float(offset[1])


def tracked_offset(scenario: Scenario) -> np.ndarray | None:
    """`mission.tracks: payload`: the leader's position less the payload's at the formation's
    hanging rest (`simulation.formation_start`: the payload at rest under its cables), world [m],
    which moves the payload's path to the leader's; None (the path as written) for `leader`."""
    if scenario.mission.tracks != 'payload':
        return None
    if scenario.n_uavs == 1:  # the payload straight below its cable's length
        return np.array([0.0, 0.0, start_lengths(scenario)[0]])
    uavs, payload = formation_start(scenario)
    return uavs[0] - payload


def swing_period(scenario: Scenario) -> float:
    """The hanging payload's pendulum period 2 pi sqrt(h / g) [s], h its depth below the UAVs'
    mean position at the formation's hanging rest (one UAV: its cable's length): what
    `control.payload_feedback.input_shaping` shapes the mission's corners for. For two UAVs it
    is the swing across their line (along it the cables hold the payload to the UAVs)."""
    if scenario.n_uavs == 1:
        depth = scenario.uavs[0].cable_length
    else:
        uavs, payload = formation_start(scenario)
        depth = float(uavs.mean(axis=0)[2] - payload[2])
    return 2.0 * math.pi * math.sqrt(depth / scenario.simulation.gravity)
