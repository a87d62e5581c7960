"""What both controller nodes share: `/formation/snapshot` -> model types, and their life."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from rclpy.node import Node

from multilift_control.cascade import FormationStates, UavState
from multilift_sim.wire import cdr
from multilift_sim.ros.common import Fatal, serve_controllers
from multilift_sim.scenario import Scenario
from multilift_sim.topics import FORMATION_SNAPSHOT as SNAPSHOT_TOPIC  # noqa: F401 (nodes)


class SnapshotReader:
    """`/formation/snapshot` as it arrives (CDR bytes: the nodes subscribe with raw=True, which
    spares rclpy's message objects) -> (t [ns], every UAV's state at t from the leader on with
    the payload's position and velocity, the rotor speeds applied up to t per UAV (empty at
    t = 0)), for the formation of `scenario`."""

    def __init__(self, scenario: Scenario) -> None:
        counts = [u.vehicle.n_rotors for u in scenario.uavs]
        self._cdr = cdr.FormationSnapshot(counts)
        self._edges = np.cumsum(counts)[:-1]
        self._scenario = scenario.name

    def __call__(self, data: bytes) -> tuple[int, FormationStates, list[np.ndarray]]:
        try:
            (t_ns, position, velocity, euler, body_rates, payload_position, payload_velocity,
             previous) = self._cdr.unpack(data)
        except ValueError as error:
            raise Fatal(f'{SNAPSHOT_TOPIC} is not of scenario {self._scenario}\'s formation '
                        f'({error}): is another simulator on this ROS domain?') from None
        states = FormationStates((UavState(*row) for row in zip(
            position.reshape(-1, 3), velocity.reshape(-1, 3), euler.reshape(-1, 3),
            body_rates.reshape(-1, 3))), payload_position, payload_velocity)
        return t_ns, states, np.split(previous, self._edges) if previous.size else []


def serve(nodes: Sequence[Node]) -> None:
    """Controller nodes' life, in a process of their own or composed (`controllers_node`):
    `serve_controllers`, each node's summary named and written by its runtime."""
    serve_controllers(nodes, lambda node: (node.runtime.name, node.runtime.summary()))
