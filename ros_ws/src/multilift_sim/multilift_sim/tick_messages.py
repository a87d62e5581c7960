"""What the simulator sends each control tick, as CDR bytes by topic (no rclpy).

The simulator node publishes these bytes as they are (`Publisher.publish` of serialized
bytes: about a fifth of the cost of building and serializing an rclpy message), and the
headless bag writes the very same bytes, so a ROS run and a headless run carry the same
messages by construction. The values come from multilift_sim.msgvalues and .scene, the
packing from multilift_sim.cdr (tests/unit/test_cdr.py holds it to rclpy's serialization).
World frame, SI units.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from multilift_sim import cdr
from multilift_sim.msgvalues import (IDENTITY, PAYLOAD_FRAME, formation_snapshot, odometry,
                                     quaternion, uav_frame, vec3)
from multilift_sim.scenario import Scenario
from multilift_sim.scene import FormationScene
from multilift_sim.simulation import Snapshot
from multilift_sim.topics import (CLOCK, FORMATION_SNAPSHOT, FORMATION_STATE, MARKERS,
                                  PAYLOAD_GUST, PAYLOAD_ODOM, TF, ODOM, uav_topic)

Message = tuple[str, bytes]  # (topic, CDR bytes)


class SimulatorMessages:
    """The simulator's messages of one run (`scenario`), packed tick by tick."""

    def __init__(self, scenario: Scenario) -> None:
        n = scenario.n_uavs
        self._clock = cdr.Clock()
        self._snapshot = cdr.FormationSnapshot([u.vehicle.n_rotors for u in scenario.uavs])
        self._odometry = [(uav_topic(i, ODOM), cdr.Odometry(uav_frame(i)))
                          for i in range(1, n + 1)]
        self._payload = cdr.Odometry(PAYLOAD_FRAME)
        self._gust = cdr.Vector3Stamped()
        self._tf = cdr.TFMessage([uav_frame(i) for i in range(1, n + 1)] + [PAYLOAD_FRAME])
        self._state = cdr.formation_state(n)
        self._scene = FormationScene(scenario)
        self._markers = cdr.MarkerArray(self._scene.specs)

    def state(self, snap: Snapshot, gust: Sequence[float],
              applied: Sequence[np.ndarray] | None, last: bool = False) -> list[Message]:
        """The state at the tick of `snap`, in the order the node sends it: /clock, then
        /formation/snapshot (what the controllers wait for; `applied`: the rotor speeds held
        up to this tick, None at t = 0; none at the run's `last` tick, which no controller
        answers), then for users, tools and bags every /uav{i}/odom, /payload/odom,
        /payload/gust (`gust`: the air velocity at the payload [m/s]) and /tf."""
        t_ns = snap.t_ns
        out = [(CLOCK, self._clock.pack(t_ns))]
        if not last:
            out.append((FORMATION_SNAPSHOT,
                        self._snapshot.pack(t_ns, *formation_snapshot(snap, applied))))
        for uav, (topic, packer) in zip(snap.uavs, self._odometry):
            out.append((topic, packer.pack(t_ns, *odometry(uav.position, uav.velocity,
                                                           uav.euler, uav.rotation,
                                                           uav.body_rates))))
        out.append((PAYLOAD_ODOM, self._payload.pack(
            t_ns, *odometry(snap.payload_position, snap.payload_velocity, None, None, None))))
        out.append((PAYLOAD_GUST, self._gust.pack(t_ns, *vec3(gust))))
        out.append((TF, self._tf.pack(
            t_ns, [vec3(u.position) for u in snap.uavs] + [vec3(snap.payload_position)],
            [quaternion(u.euler) for u in snap.uavs] + [IDENTITY])))
        return out

    def formation(self, t_ns: int, tension: np.ndarray, g: np.ndarray, g_dot: np.ndarray,
                  taut: np.ndarray) -> Message:
        """/formation/state: per cable the tension [N], g [m^2], g_dot [m^2/s], taut."""
        return FORMATION_STATE, self._state.pack(t_ns, tension.tolist(), g.tolist(),
                                                 g_dot.tolist(), taut.tolist())

    def markers(self, snap: Snapshot, tension: np.ndarray, taut: np.ndarray) -> Message:
        """/visualization/markers: the formation of `snap` drawn (cables by tension)."""
        self._scene.update([u.position for u in snap.uavs], [u.euler for u in snap.uavs],
                           snap.payload_position, tension, taut)
        return MARKERS, self._markers.pack(snap.t_ns)
