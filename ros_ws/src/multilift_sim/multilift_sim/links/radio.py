"""A radio link from the leader to each follower (`comms:`, issue 33 item 5): each control tick
the leader sends a packet, its measured state (MEASURED_COLUMNS, what it flew on) and the
collective thrust it answered with [N]; follower i receives the packet sent `latency` [s]
earlier (rounded to control ticks) unless it is lost: with probability `loss`, each packet and
receiver independently (drawn before the run from `comms.seed`), or because the leader was
farther than `range` [m] from the follower when it was sent. Until another arrives a follower
flies on the last packet it received (it does not extrapolate); the packet of tick 0 (the
formation at rest before take-off) reaches everyone.

Keys (SI): `latency` [s] (>= 0), `loss` (in [0, 1)), `range` [m] (> 0, default unlimited),
`seed` (integer). World frame z up.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import MEASURED_COLUMNS, MEASURED_POSITION

UNITS = {'comms.latency': 's', 'comms.loss': '', 'comms.range': 'm', 'comms.seed': ''}

# -- the link's constants row ------------------------------------------------------------------
LINK_LATENCY = 0          # control ticks from sending to receiving
LINK_RANGE = 1            # [m], inf: unlimited
LINK_COLUMNS = 2
# -- a packet: the leader's measured state, then its thrust [N] --------------------------------
PACKET_THRUST = MEASURED_COLUMNS
PACKET_COLUMNS = MEASURED_COLUMNS + 1
# -- one follower's memory ---------------------------------------------------------------------
LAST_TICK = 0             # the tick received last (-1: none)
HEARD = 1                 # the packet it flies on (PACKET_COLUMNS)
DELAY_LINE = HEARD + PACKET_COLUMNS  # the packets sent in the last latency + 1 ticks, by
#                                      tick % (latency + 1)


@dataclass(frozen=True)
class CommsConfig:
    """The `comms:` section."""
    latency: float            # [s]
    loss: float               # probability a packet is lost, per receiver, in [0, 1)
    range: float              # [m], inf: unlimited
    seed: int                 # the losses' random stream
    latency_ticks: int        # the latency in control ticks (the nearest)


def read_comms(top, control_rate: float) -> CommsConfig | None:
    """The `comms:` section (`top` the scenario's reading.Section), None without one."""
    if not top.has('comms'):
        return None
    d = top.section('comms')
    latency = d.non_negative('latency', 0.0)
    config = CommsConfig(
        latency=latency,
        loss=d.number('loss', 0.0, lambda v: 0 <= v < 1, 'must be within [0, 1)'),
        range=d.positive('range') if d.has('range') else math.inf, seed=d.count('seed', 0),
        latency_ticks=int(round(latency * control_rate)))
    d.done()
    return config


def link_arrays(comms: CommsConfig | None, n_uavs: int, ticks: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(constants (LINK_COLUMNS,) or (0,) without comms, delivered (n_uavs, ticks + 1): 1.0
    where follower i receives the packet sent at that tick (lost ones 0.0, drawn from
    comms.seed), memory (n_uavs, M): each follower's at the start)."""
    if comms is None:
        return np.zeros(0), np.ones((n_uavs, 0)), np.zeros((n_uavs, 0))
    constants = np.zeros(LINK_COLUMNS)
    constants[LINK_LATENCY], constants[LINK_RANGE] = comms.latency_ticks, comms.range
    rng = np.random.default_rng(comms.seed)
    delivered = (rng.random((n_uavs, ticks + 1)) >= comms.loss).astype(float)
    memory = np.zeros((n_uavs, DELAY_LINE + (comms.latency_ticks + 1) * PACKET_COLUMNS))
    memory[:, LAST_TICK] = -1.0
    return constants, delivered, memory


@jit
def receive(constants, delivered, memory, tick, leader, leader_thrust, own_position, heard):
    """At control tick `tick`, follower's link (its `delivered` (ticks + 1,), `memory`): the
    leader's packet of this tick (its measured state `leader` (MEASURED_COLUMNS,) and thrust
    [N]) sent; the one sent `latency` ticks ago received unless lost (a draw, or the leader
    then farther than the range from `own_position` (3,) [m], world); the packet the follower
    flies on into heard (MEASURED_COLUMNS,), its thrust [N] returned. A second call at one tick
    changes nothing."""
    if memory[LAST_TICK] != tick:
        memory[LAST_TICK] = tick
        latency = int(constants[LINK_LATENCY])
        slots = latency + 1
        line = DELAY_LINE + (tick % slots) * PACKET_COLUMNS
        for k in range(MEASURED_COLUMNS):
            memory[line + k] = leader[k]
        memory[line + PACKET_THRUST] = leader_thrust
        sent = tick - latency
        if tick == 0 or (0 < sent < delivered.shape[0] and delivered[sent] != 0.0):
            source = DELAY_LINE + (max(sent, 0) % slots) * PACKET_COLUMNS
            d2 = 0.0
            for j in range(3):
                d = memory[source + MEASURED_POSITION + j] - own_position[j]
                d2 += d * d
            if tick == 0 or math.sqrt(d2) <= constants[LINK_RANGE]:
                for k in range(PACKET_COLUMNS):
                    memory[HEARD + k] = memory[source + k]
    for k in range(MEASURED_COLUMNS):
        heard[k] = memory[HEARD + k]
    return memory[HEARD + PACKET_THRUST]
