"""What the controllers do about the scenario's faults (`events:`, docs/events.md), knowing
each at once (perfect fault detection and isolation), from the tick the fault falls on:

- a UAV whose rotor loses effectiveness allocates its wrench over what its rotors can still
  give (`RotorMixer` of the effectiveness, the failed rotor's row left out);
- when a follower's cable lets go (a linear or V formation), the formation takes new offsets
  (`release_targets`): the released UAV flies clear, CLEAR_DISTANCE farther out from the
  leader on the same bearing (at its altitude: a follower's height is its own loop's, z_1
  plus its altitude offset); when one follower is left with the leader, it moves so that
  the payload hangs where it hung before (under the midpoint of the two, the old centroid
  of the UAVs whose cables held it), the two then sharing its weight equally (equal cables).
  Distance and circle formations keep their rows. The targets move there over
  RELEASE_TRANSITION seconds along a smoothstep (a step of metres saturated the rotors of the
  UAVs that moved for 3 s in `v3_uav_loss`; a 3 s ramp, none).

`fault_mixers` and `target_schedule` compute, once per run, what each event leaves the
controllers with, and when; the engine's tick copies it in at its tick (`engine.tick.events`),
and a controller's runtime does the same (`FaultReallocation`), so both paths answer alike.
"""
from __future__ import annotations

import numpy as np

from multilift_control.cascade import RotorMixer
from multilift_control.virtual_constraints import FormationGeometry, VirtualConstraints
from multilift_control.laws.layout import MIXER_SIZE
from multilift_sim.formation_geometry import hanging_payload
from multilift_control.reactions import lets_go, reaction_of, reallocates
from multilift_sim.physics.layout import EVENT_TICK, EVENT_UAV
from multilift_sim.scenario import Scenario
from multilift_sim.schedules import event_array

CLEAR_DISTANCE = 4.0  # [m] farther from the leader, horizontally, a released UAV flies
RELEASE_TRANSITION = 5.0  # [s] the formation takes to move to its new offsets


def fault_mixers(scenario: Scenario) -> np.ndarray:
    """(k, rotors, MIXER_SIZE): for each event row (`simulation.event_array`) whose reaction
    reallocates a mixer (`reactions`: a rotor's effectiveness) the mixer rows of its UAV after
    it (every earlier fault of that UAV kept); zeros for the others (unused). `rotors`: the
    most any UAV has."""
    rows = event_array(scenario)
    rotors = max(u.vehicle.n_rotors for u in scenario.uavs)
    effectiveness = [np.ones(u.vehicle.n_rotors) for u in scenario.uavs]
    out = np.zeros((len(rows), rotors, MIXER_SIZE))
    for k, row in enumerate(rows):
        if not reallocates(row):
            continue
        uav = reaction_of(row).rotors(row, effectiveness)
        mixer = RotorMixer(scenario.uavs[uav].vehicle, effectiveness[uav]).rows
        out[k, :mixer.shape[0]] = mixer
    return out


def mixer_uavs(scenario: Scenario) -> np.ndarray:
    """(k,) int: for each event row the UAV (from 0) whose mixer it reallocates
    (`fault_mixers[k]` its rows), -1 none."""
    rows = event_array(scenario)
    return np.array([int(row[EVENT_UAV]) if reallocates(row) else -1 for row in rows],
                    dtype=np.int64)


def _initial_targets(scenario: Scenario) -> tuple[VirtualConstraints | None, np.ndarray]:
    """(the formation's VirtualConstraints, a copy of their targets before any event), or
    (None, no targets) without a formation."""
    if scenario.formation is None or scenario.n_uavs < 2:
        return None, np.zeros(0)
    constraints = VirtualConstraints(FormationGeometry.from_config(scenario.formation,
                                                                   scenario.n_uavs))
    return constraints, np.array(constraints.targets)


def release_targets(scenario: Scenario) -> np.ndarray:
    """(k, m): for each event row (`simulation.event_array`) the virtual-constraint targets
    (`VirtualConstraints.targets`) the formation has after it (every earlier release kept; see
    the module docstring); the targets before it for the other kinds."""
    rows = event_array(scenario)
    constraints, targets = _initial_targets(scenario)
    out = np.empty((len(rows), len(targets)))
    if constraints is None:
        return out
    holding = np.ones(scenario.n_uavs, dtype=bool)  # whose cables hold the payload
    lengths = [u.cable_length for u in scenario.uavs]
    for k, row in enumerate(rows):
        uav = lets_go(row)
        if uav > 0 and constraints.linear:
            # offsets o_i = r_1 - r_i, three rows per follower (VirtualConstraints)
            offsets = np.vstack([np.zeros(3), targets.reshape(-1, 3)])
            positions = -offsets  # the nominal places relative to the leader
            _, payload = hanging_payload(positions[holding], np.asarray(lengths)[holding])
            holding[uav] = False
            out_of_way = offsets[uav].copy()
            reach = np.hypot(*out_of_way[:2])
            if reach > 0.0:
                out_of_way[:2] *= (reach + CLEAR_DISTANCE) / reach
            offsets[uav] = out_of_way
            left = np.flatnonzero(holding[1:]) + 1
            if len(left) == 1:  # the twin left: the payload under its two UAVs' midpoint
                offsets[left[0], :2] = -2.0 * payload[:2]
            targets = offsets[1:].reshape(-1)
        out[k] = targets
    return out


def target_schedule(scenario: Scenario) -> np.ndarray:
    """(S, 1 + m) rows (tick, the formation's targets from that tick on), in tick order:
    after each cable release, RELEASE_TRANSITION seconds of control ticks along a smoothstep
    from the targets before it to `release_targets`' (each from the previous release's end)."""
    rows = event_array(scenario)
    final = release_targets(scenario)
    out = []
    if final.shape[1] == 0:
        return np.zeros((0, 1 + final.shape[1]))
    _, previous = _initial_targets(scenario)
    ticks = max(1, int(round(RELEASE_TRANSITION * scenario.simulation.control_rate)))
    for k, row in enumerate(rows):
        if lets_go(row) < 0 or np.array_equal(final[k], previous):
            continue
        for step in range(ticks):
            x = (step + 1) / ticks
            out.append(np.concatenate(([row[EVENT_TICK] + step],
                                       previous + (final[k] - previous) * x * x * (3 - 2 * x))))
        previous = final[k]
    out.sort(key=lambda r: r[0])
    return np.array(out).reshape(-1, 1 + final.shape[1])


class FaultReallocation:
    """UAV `index`'s controller side of the faults: `at(tick, mixer, constraints)` writes the
    mixer rows of every event reallocating this UAV's mixer, and a follower's formation
    targets after every release of a cable, up to `tick` into `mixer` (a RotorMixer) and
    `constraints` (its VirtualConstraints; None for the leader)."""

    def __init__(self, scenario: Scenario, index: int):
        rows = event_array(scenario)
        mixers, uavs = fault_mixers(scenario), mixer_uavs(scenario)
        self._pending = []
        for k, row in enumerate(rows):
            if uavs[k] == index:
                self._pending.append((int(row[EVENT_TICK]), 'mixer', mixers[k]))
        if index > 0:
            self._pending += [(int(row[0]), 'targets', row[1:])
                              for row in target_schedule(scenario)]
        self._pending.sort(key=lambda item: item[0])

    def at(self, tick: int, mixer: RotorMixer | None,
           constraints: VirtualConstraints | None) -> None:
        while self._pending and self._pending[0][0] <= tick:
            _, what, values = self._pending.pop(0)
            if what == 'mixer' and mixer is not None:
                mixer.rows[:] = values[:mixer.rows.shape[0]]
            elif what == 'targets' and constraints is not None:
                constraints.targets = values.copy()  # writable, as the engine's: one signature
