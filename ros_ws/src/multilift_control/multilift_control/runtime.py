"""The controller runtime: what one UAV's controller needs each tick, written once for the
controller nodes and the headless loop (pure Python, no ROS).

A tick (seed Algorithm 1, in lockstep with the simulator): the simulator publishes the state
at t; the leader answers it first; each follower answers once it has every UAV's state at t
and the leader's answer to it, using as the other followers' thrusts their latest answers to
earlier states (the previous tick's) and, before any answer, the hover share. `answer_tick`
runs that sequence in one process; the nodes run it through messages, calling the same
`ControllerRuntime` methods, so both compute the same numbers (tests/ros/test_headless.py
compares their bags to 1e-9 m).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from multilift_control import laws
from multilift_control.cascade import ControlOutput, FormationStates, UavState
from multilift_control.controllers import FollowerController, LeaderController
from multilift_control.faults import FaultReallocation
from multilift_control.laws.follower import lift_vectors
from multilift_control.laws.links import heard_formation
from multilift_control.laws.layout import UAV_BODY_RATES, UAV_EULER, UAV_POSITION, UAV_VELOCITY
from multilift_control.laws.mixer import collective_thrust
from multilift_control.mission import Reference
from multilift_sim.links.radio import link_arrays
from multilift_sim.scenario import Scenario
from multilift_sim.simulation import FormationSimulator, Snapshot
from multilift_sim.statistics import FormationErrorStatistics, TrackingStatistics


@dataclass(frozen=True)
class ControllerAnswer:
    """A controller's answer to the formation state at t: what its node publishes."""
    index: int                                  # UAV index from 0 (0 = the leader)
    t_ns: int                                   # the state's time [ns]
    output: ControlOutput                       # rotor speeds, saturation, set-points
    reference: Reference | None = None          # the leader's mission reference at t
    formation_error: np.ndarray | None = None   # a follower's rows of g_vc [m or m^2]
    formation_error_rate: np.ndarray | None = None  # their rates [m/s or m^2/s]


class ThrustBook:
    """The collective thrusts u_T,j [N] a follower feeds to the virtual constraints
    (seed Eq. 3.9-3.12: u_f,r holds every UAV's thrust vector R_j e_z u_T,j).

    The leader's thrust is its answer to the same state (a follower waits for it); the other
    followers' are their latest answers to earlier states (a follower does not wait for its
    peers, so the result does not depend on who answers first); before any answer, the thrust
    that carries the UAV and its share of the payload. The arithmetic is the laws'
    (`laws.mixer.collective_thrust`, `laws.follower.lift_vectors`).
    """

    def __init__(self, scenario: Scenario):
        share = scenario.payload.mass / scenario.n_uavs
        gravity = scenario.simulation.gravity
        self.thrust_coefficients = [float(u.vehicle.thrust_coefficient) for u in scenario.uavs]
        self.thrusts = np.array([(u.vehicle.mass + share) * gravity
                                 for u in scenario.uavs])  # [N]
        self.leader: dict[int, float] = {}               # t_ns -> the leader's u_T [N]
        self.pending: dict[int, dict[int, float]] = {}   # t_ns -> {follower: u_T [N]}
        self._formed: tuple[int, np.ndarray] | None = None  # (t_ns, vectors) last formed
        self._collective_thrust = laws.runnable(collective_thrust)
        self._lift_vectors = laws.runnable(lift_vectors)

    def note(self, index: int, t_ns: int, rotor_speeds: np.ndarray) -> None:
        """UAV `index` (from 0) answered the state at t_ns with these rotor speeds [rad/s]."""
        thrust = self._collective_thrust(self.thrust_coefficients[index],
                                         np.asarray(rotor_speeds, dtype=float))
        if index == 0:
            self.leader[t_ns] = thrust
        else:
            self.pending.setdefault(t_ns, {})[index] = thrust

    def has_leader(self, t_ns: int) -> bool:
        return t_ns in self.leader

    def vectors(self, t_ns: int, states: Sequence[UavState]) -> np.ndarray:
        """Every UAV's thrust vector R_j(t) e_z u_T,j, world [N], shape (n, 3), for the state
        at t_ns; needs the leader's answer to it. Formed once per state: followers that share
        the book (one process, `formation_runtimes`) get the same array (read-only)."""
        if self._formed is not None and self._formed[0] == t_ns:
            return self._formed[1]
        for stamp in sorted(k for k in self.pending if k < t_ns):
            for j, thrust in self.pending.pop(stamp).items():
                self.thrusts[j] = thrust
        for stamp in [k for k in self.leader if k < t_ns]:
            del self.leader[stamp]
        self.thrusts[0] = self.leader.pop(t_ns)
        vectors = self._lift_vectors(FormationStates.of(states).array, self.thrusts)
        self._formed = (t_ns, vectors)
        return vectors


class ControllerRuntime:
    """UAV `index`'s controller (0: the leader of `control.mode`, else the follower of
    `control.follower`: `multilift_control.controllers`) with its bookkeeping and its run
    statistics."""

    def __init__(self, scenario: Scenario, index: int, thrusts: ThrustBook | None = None):
        """`thrusts`: a follower's ThrustBook, shared by the followers of one process
        (`formation_runtimes`); by default its own (a node's)."""
        self.index = index
        self.is_follower = index > 0
        self._period_ns = int(round(1e9 / scenario.simulation.control_rate))
        self._faults = FaultReallocation(scenario, index)
        if self.is_follower:
            self.follower = FollowerController(scenario, index)
            self.thrusts = ThrustBook(scenario) if thrusts is None else thrusts
            self.statistics = FormationErrorStatistics()
            # its link from the leader (`comms:`; None: it hears at once)
            link, delivered, memory = link_arrays(scenario.comms, scenario.n_uavs,
                                                  scenario.simulation.tick_count)
            self._link = (link, delivered[index], memory[index]) if link.shape[0] else None
            self._heard_formation = laws.runnable(heard_formation)
            self._lift_vectors = laws.runnable(lift_vectors)
        else:
            self.leader = LeaderController(scenario, index)
            self.statistics = TrackingStatistics()

    @property
    def name(self) -> str:
        """The node's name and its summary's: `leader`, `follower2`, ..."""
        return f'follower{self.index + 1}' if self.is_follower else 'leader'

    def note_command(self, index: int, t_ns: int, rotor_speeds: np.ndarray) -> None:
        """UAV `index` (from 0) answered the state at t_ns (a follower's input)."""
        if self.is_follower:
            self.thrusts.note(index, t_ns, rotor_speeds)

    def ready(self, t_ns: int) -> bool:
        """Whether this controller can answer the state at t_ns (given every UAV's state)."""
        return not self.is_follower or self.thrusts.has_leader(t_ns)

    def answer(self, t_ns: int, states: Sequence[UavState]) -> ControllerAnswer:
        """The answer to the formation state at t_ns (`states`: every UAV, from the leader)."""
        t = t_ns * 1e-9
        controller = self.follower if self.is_follower else self.leader
        # the faults known from their tick on: this UAV's rotors, a follower's cable released
        self._faults.at(t_ns // self._period_ns, controller.cascade.mixer,
                        self.follower.constraints if self.is_follower else None)
        if not self.is_follower:
            output, reference = self.leader.update(t, states)
            if reference is not None:
                self.statistics.add(reference.position, states[0].position)
            return ControllerAnswer(0, t_ns, output, reference=reference)
        vectors = self.thrusts.vectors(t_ns, states)
        if self._link is not None:  # the leader as its link delivered it (laws.links)
            states, vectors = self._heard(t_ns // self._period_ns, states)
        output, errors, rates = self.follower.update(t, states, vectors)
        self.statistics.add(errors)
        return ControllerAnswer(self.index, t_ns, output, formation_error=errors,
                                formation_error_rate=rates)

    def _heard(self, tick: int, states: Sequence[UavState]) -> tuple[np.ndarray, np.ndarray]:
        """(the states (n, UAV_STATE_SIZE), the lifts (n, 3) [N]) as this follower hears them
        at `tick` over its link (`laws.links.heard_formation`), the book's thrusts at it."""
        array = FormationStates.of(states).array
        heard, heard_thrusts = np.empty_like(array), np.empty(array.shape[0])
        self._heard_formation(*self._link, tick, self.index,
                              array, self.thrusts.thrusts, heard, heard_thrusts)
        return heard, self._lift_vectors(heard, heard_thrusts)

    def summary(self) -> dict:
        """This controller's run statistics (`multilift_sim.statistics`)."""
        return self.statistics.as_dict()


def formation_runtimes(scenario: Scenario) -> list[ControllerRuntime]:
    """Every UAV's controller in one process (the headless loop): the followers share one
    ThrustBook, as they all see the same answers, so a tick notes each answer once (O(n),
    where a book per follower would be O(n^2))."""
    thrusts = ThrustBook(scenario)
    return [ControllerRuntime(scenario, i, thrusts) for i in range(scenario.n_uavs)] \
        if scenario.controlled else []  # none: every UAV's motion is prescribed


def answer_tick(runtimes: list[ControllerRuntime], t_ns: int,
                states: Sequence[UavState]) -> list[ControllerAnswer]:
    """Every controller's answer to the state at t_ns, in the order the ROS graph gives them:
    the leader first, then the followers, each of whose books then notes every answer; none
    without controllers (every UAV prescribed)."""
    if not runtimes:
        return []
    leader = runtimes[0].answer(t_ns, states)
    books = list({id(r.thrusts): r.thrusts for r in runtimes[1:]}.values())
    for book in books:
        book.note(0, t_ns, leader.output.rotor_speeds)
    answers = [leader] + [runtime.answer(t_ns, states) for runtime in runtimes[1:]]
    for book in books:
        for answer in answers[1:]:
            book.note(answer.index, t_ns, answer.output.rotor_speeds)
    return answers


def uav_states(snapshot: Snapshot) -> FormationStates:
    """What the controllers measure of the formation at the snapshot's tick (its
    `measured` rows: the state, or with `sensors:` the sensors' measurement) and the payload's
    position and velocity (the state's)."""
    return FormationStates((UavState(row[UAV_POSITION:UAV_POSITION + 3],
                                     row[UAV_VELOCITY:UAV_VELOCITY + 3],
                                     row[UAV_EULER:UAV_EULER + 3],
                                     row[UAV_BODY_RATES:UAV_BODY_RATES + 3])
                            for row in snapshot.measured), snapshot.payload_position,
                           snapshot.payload_velocity)


def prepare_node_laws(scenario: Scenario, index: int) -> None:
    """Choose and load the control laws of a controller node of UAV `index` (from 0), before
    its topics appear (the simulator's `command_timeout` counts from the first state).

    The laws run compiled unless MULTILIFT_KERNEL=python: one throwaway answer to the
    scenario's start loads them from numba's cache here (scripts/setup filled it; about 0.2 s,
    with numba's import 0.5 s, which importing the laws costs anyway). Uncompiled, a follower
    of a circle of three took 1.8-7 ms a tick against 0.08 ms compiled. Compiled and uncompiled
    give the same bits (tests/unit/test_compiled_laws.py)."""
    if laws.runnable(collective_thrust) is not collective_thrust:  # uncompiled
        return
    runtime = ControllerRuntime(scenario, index)
    if runtime.is_follower:
        runtime.note_command(0, 0, np.zeros(scenario.uavs[0].vehicle.n_rotors))
    runtime.answer(0, uav_states(FormationSimulator(scenario).snapshot()))
