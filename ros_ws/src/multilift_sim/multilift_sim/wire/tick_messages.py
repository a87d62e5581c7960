"""What the simulator sends each control tick, as CDR bytes by topic (no rclpy).

The simulator node publishes these bytes as they are (`Publisher.publish` of serialized
bytes: about a fifth of the cost of building and serializing an rclpy message), and the
headless bag writes the very same bytes, so a ROS run and a headless run carry the same
messages by construction. The values come from multilift_sim.wire.msgvalues and .scene, the
packing from multilift_sim.wire.cdr (tests/unit/test_cdr.py holds it to rclpy's serialization).
World frame, SI units.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from multilift_sim import kernels
from multilift_sim.formation_params import StateLayout
from multilift_sim.wire import cdr, cdr_scene
from multilift_sim.wire.msgvalues import (IDENTITY, PAYLOAD_FRAME, SNAPSHOT_BLOCKS, WORLD_FRAME,
                                          formation_event, formation_snapshot, uav_frame, vec3)
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_COLUMNS,
                                          MEASURED_POSITION, ODOMETRY_BODY_VELOCITY,
                                          ODOMETRY_COLUMNS, ODOMETRY_QUATERNION)
from multilift_sim.physics.measurement import odometry_rows, odometry_states
from multilift_sim.scenario import Scenario
from multilift_sim.wire.scene import FormationScene
from multilift_sim.simulation import Snapshot
from multilift_sim.estimators.published import payload_read
from multilift_sim.topics import (CABLE_LENGTH, CLOCK, ESTIMATE, EVENTS, FORMATION_SNAPSHOT,
                                  FORMATION_STATE, MARKERS, MEASURED_ODOM, PAYLOAD_ESTIMATE,
                                  PAYLOAD_GUST, PAYLOAD_ODOM, TF, THRUST_MARGIN, ODOM, WIND,
                                  margin_topics, uav_topic)

Message = tuple[str, bytes]  # (topic, CDR bytes)
# (topic, the CDR bytes of K messages (K, size) uint8): a topic's messages of K ticks
MessageRows = tuple[str, np.ndarray]
_ZERO = (0.0, 0.0, 0.0)
# an odometry row's 13 numbers (msgvalues.odometry's order: position, orientation (x, y, z, w),
# body-frame velocity, body rates) taken from the rows of physics.measurement.odometry_states
ODOMETRY_NUMBERS = np.r_[MEASURED_POSITION:MEASURED_POSITION + 3,
                         ODOMETRY_QUATERNION:ODOMETRY_QUATERNION + 4,
                         ODOMETRY_BODY_VELOCITY:ODOMETRY_BODY_VELOCITY + 3,
                         MEASURED_BODY_RATES:MEASURED_BODY_RATES + 3]


class SimulatorMessages:
    """The simulator's messages of one run (`scenario`), packed tick by tick."""

    def __init__(self, scenario: Scenario) -> None:
        n = scenario.n_uavs
        self._clock = cdr.Clock()
        self._snapshot = cdr.FormationSnapshot([u.vehicle.n_rotors for u in scenario.uavs])
        self._odometry = [(uav_topic(i, ODOM), cdr.Odometry(uav_frame(i)))
                          for i in range(1, n + 1)]
        # what the controllers receive, UAV by UAV, where the scenario has `sensors:`
        self._measured = [(uav_topic(i, MEASURED_ODOM), cdr.Odometry(uav_frame(i)))
                          for i in range(1, n + 1)] if scenario.measures else []
        # each UAV's estimate with its covariance (/uav{i}/estimate), with an estimator
        self._estimates = [(uav_topic(i, ESTIMATE), cdr.Odometry(uav_frame(i), covariance=True))
                           for i in range(1, n + 1)] if scenario.estimator is not None else []
        # each winch's cable length (/uav{i}/cable_length), where UAVs carry winches
        self._lengths = [(i - 1, uav_topic(i, CABLE_LENGTH), cdr.Float64())
                         for i in scenario.winches]
        # each UAV's thrust margin (/uav{i}/thrust_margin), in a reorganising formation: its
        # topic, its packer, its rotors' largest sum of squared speeds N omega_max^2 [rad^2/s^2]
        self._margins = [(uav_topic(i, THRUST_MARGIN), cdr.Float64(), u.vehicle)
                         for i, u in enumerate(scenario.uavs, start=1)] \
            if margin_topics(scenario) else []
        self._payload = cdr.Odometry(PAYLOAD_FRAME)
        # the payload's estimate with its covariance (/payload/estimate), with a payload
        # estimator
        self._payload_estimate = cdr.Odometry(PAYLOAD_FRAME, covariance=True) \
            if scenario.payload_estimator is not None else None
        self._gust = cdr.Vector3Stamped()
        self._wind = cdr.Vector3Stamped() if scenario.has_wind else None  # /formation/wind
        # /tf: world -> each UAV, world -> payload, and a rigid payload's attach points
        # (payload -> payload/attach{i}: where cable i holds it, docs/rigid_payload.md)
        self._attach = list(scenario.payload.attach_points or ())
        frames = [uav_frame(i) for i in range(1, n + 1)] + [PAYLOAD_FRAME]
        attach_frames = [f'{PAYLOAD_FRAME}/attach{i}' for i in range(1, len(self._attach) + 1)]
        self._tf = cdr_scene.TFMessage(frames + attach_frames, parents=[WORLD_FRAME] * len(frames)
                                 + [PAYLOAD_FRAME] * len(attach_frames))
        self._state = cdr.formation_state(n)
        self._scene = FormationScene(scenario)
        self._markers = cdr_scene.MarkerArray(self._scene.specs)
        self._event = cdr.FormationEvent()

    def state(self, snap: Snapshot, gust: Sequence[float],
              applied: Sequence[np.ndarray] | None, last: bool = False,
              wind: Sequence[float] | None = None) -> list[Message]:
        """The state at the tick of `snap`, in the order the node sends it: /clock, then
        /formation/snapshot (what the controllers wait for: what they receive of the state;
        `applied`: the rotor speeds held up to this tick, None at t = 0; none at the run's
        `last` tick, which no controller answers), then for users, tools and bags every
        /uav{i}/odom (the state), with `sensors:` every /uav{i}/measured_odom, /payload/odom,
        /payload/gust (`gust`: the seed's gusts' air velocity at the payload [m/s]), where the
        air moves everywhere /formation/wind (`wind` [m/s], world, over the period from the
        tick), and /tf."""
        snapshot = None if last else formation_snapshot(snap, applied)
        uavs = snap.odometry[:, ODOMETRY_NUMBERS].tolist()
        measured = measured_odometry(snap.measured[None])[0].tolist() if self._measured \
            else None
        payload_velocity, payload_pose = payload_motion(snap.payload_attitude,
                                                        snap.payload_velocity)
        return self.state_of(
            snap.t_ns, None if snapshot is None else np.concatenate(snapshot).tolist(),
            None if snapshot is None else len(snapshot[-1]), uavs,
            snap.payload_position.tolist(), payload_velocity, vec3(gust),
            measured, None if wind is None else vec3(wind), payload_pose,
            snap.cable_lengths.tolist(),
            snap.estimate.tolist() if self._estimates else None,
            None if self._payload_estimate is None else snap.payload_estimate.tolist())

    def state_of(self, t_ns: int, snapshot: list[float] | None, previous: int | None,
                 uavs: Sequence[Sequence[float]], payload_position: Sequence[float],
                 payload_velocity: Sequence[float], gust: Sequence[float],
                 measured: Sequence[Sequence[float]] | None = None,
                 wind: Sequence[float] | None = None,
                 payload_pose: tuple[Sequence[float], Sequence[float]] | None = None,
                 cable_lengths: Sequence[float] = (),
                 estimates: Sequence[Sequence[float]] | None = None,
                 payload_estimate: Sequence[float] | None = None) -> list[Message]:
        """`state` from plain numbers (the one packing of both): `snapshot` the
        FormationSnapshot's numbers in a row (`cdr.FormationSnapshot.pack_row`; None at the
        last tick) with `previous` rotor speeds at its end, per UAV its odometry's 13 numbers
        (position, orientation (x, y, z, w), body-frame velocity, body rates: msgvalues
        .odometry) and (with `sensors:`) those of what its controllers receive, the payload's
        position and velocity, the gust and (where the air moves everywhere) the wind, world
        [m, m/s]; a rigid payload's `payload_pose` (its orientation (x, y, z, w) and body rates
        [rad/s]; its velocity then in its own frame, as nav_msgs/Odometry's twist is), and
        every cable's length [m] (/uav{i}/cable_length of the UAVs with a winch), and with an
        estimator every UAV's estimate (estimators.published's 85 numbers, /uav{i}/estimate),
        with a payload estimator the payload's (the same numbers, /payload/estimate)."""
        orientation, spin = (IDENTITY, _ZERO) if payload_pose is None else payload_pose
        out = [(CLOCK, self._clock.pack(t_ns))]
        if snapshot is not None:
            out.append(self.snapshot_of(t_ns, snapshot, previous))
        for uav, (topic, packer) in zip(uavs, self._odometry):
            out.append((topic, packer.pack_row(t_ns, uav)))
        if measured is not None:
            for uav, (topic, packer) in zip(measured, self._measured):
                out.append((topic, packer.pack_row(t_ns, uav)))
        if estimates is not None:
            for uav, (topic, packer) in zip(estimates, self._estimates):
                out.append((topic, packer.pack_row(t_ns, uav)))
        for i, topic, packer in self._lengths:
            out.append((topic, packer.pack(cable_lengths[i])))
        out.append((PAYLOAD_ODOM, self._payload.pack(t_ns, payload_position, orientation,
                                                     payload_velocity, spin)))
        if payload_estimate is not None:
            out.append((PAYLOAD_ESTIMATE, self._payload_estimate.pack_row(t_ns,
                                                                          payload_estimate)))
        out.append((PAYLOAD_GUST, self._gust.pack(t_ns, *gust)))
        if self._wind is not None:
            out.append((WIND, self._wind.pack(t_ns, *wind)))
        out.append((TF, self._tf.pack(
            t_ns, [u[:3] for u in uavs] + [payload_position] + self._attach,
            [u[3:7] for u in uavs] + [orientation] + [IDENTITY] * len(self._attach))))
        return out

    def snapshot_of(self, t_ns: int, snapshot: list[float], previous: int) -> Message:
        """`state_of`'s /formation/snapshot alone."""
        return FORMATION_SNAPSHOT, self._snapshot.pack_row(t_ns, snapshot, previous)

    def state_rows_of(self, t_ns: np.ndarray, snapshot: np.ndarray | None, previous: int,
                      uavs: np.ndarray, payload_position: np.ndarray,
                      payload_velocity: np.ndarray, gust: np.ndarray,
                      measured: np.ndarray | None = None, wind: np.ndarray | None = None,
                      payload_pose: tuple[np.ndarray, np.ndarray] | None = None,
                      cable_lengths: np.ndarray | None = None,
                      estimates: np.ndarray | None = None,
                      payload_estimate: np.ndarray | None = None) -> list[MessageRows]:
        """`state_of` of K ticks at once (t_ns (K,) [ns]), topic by topic in its order: the
        same arguments, each with a first axis of K ticks (snapshot (K, 12 n + 6 + previous),
        uavs and measured (K, n, 13), payload_pose (orientations (K, 4), body rates (K, 3)),
        cable_lengths (K, n), estimates (K, n, 85), ...); row k of a topic's bytes is the
        message `state_of` packs at tick k (tests/unit/test_headless_bag.py)."""
        k = len(t_ns)
        if payload_pose is None:
            orientation, spin = np.broadcast_to(IDENTITY, (k, 4)), np.zeros((k, 3))
        else:
            orientation, spin = payload_pose
        out = [(CLOCK, self._clock.pack_rows(t_ns))]
        if snapshot is not None:
            out.append((FORMATION_SNAPSHOT, self._snapshot.pack_rows(t_ns, snapshot, previous)))
        for i, (topic, packer) in enumerate(self._odometry):
            out.append((topic, packer.pack_rows(t_ns, uavs[:, i])))
        for uav, (topic, packer) in enumerate(self._measured if measured is not None else ()):
            out.append((topic, packer.pack_rows(t_ns, measured[:, uav])))
        for uav, (topic, packer) in enumerate(self._estimates if estimates is not None else ()):
            out.append((topic, packer.pack_rows(t_ns, estimates[:, uav])))
        for i, topic, packer in self._lengths:
            out.append((topic, packer.pack_rows(cable_lengths[:, i])))
        out.append((PAYLOAD_ODOM, self._payload.pack_rows(t_ns, np.concatenate(
            (payload_position, orientation, payload_velocity, spin), axis=1))))
        if payload_estimate is not None:
            out.append((PAYLOAD_ESTIMATE, self._payload_estimate.pack_rows(t_ns,
                                                                           payload_estimate)))
        out.append((PAYLOAD_GUST, self._gust.pack_rows(t_ns, gust)))
        if self._wind is not None:
            out.append((WIND, self._wind.pack_rows(t_ns, wind)))
        attach = len(self._attach)
        translations = np.concatenate((uavs[..., :3], payload_position[:, None],
                                       np.broadcast_to(np.reshape(self._attach, (1, attach, 3)),
                                                       (k, attach, 3))), axis=1)
        rotations = np.concatenate((uavs[..., 3:7], orientation[:, None],
                                    np.broadcast_to(IDENTITY, (k, attach, 4))), axis=1)
        out.append((TF, self._tf.pack_rows(t_ns, translations, rotations)))
        return out

    def formation_rows_of(self, t_ns: np.ndarray, tension: np.ndarray, g: np.ndarray,
                          g_dot: np.ndarray, taut: np.ndarray) -> MessageRows:
        """`formation_of` of K ticks (t_ns (K,), the rest (K, n))."""
        return FORMATION_STATE, self._state.pack_rows(t_ns, tension, g, g_dot, taut)

    def margin_rows(self, rotor_speeds: Sequence[np.ndarray]) -> list[MessageRows]:
        """`margins` of K ticks: each UAV's rotor speeds (K, its rotors) [rad/s]."""
        return [(topic, packer.pack_rows(vehicle.thrust_margin(speeds)))
                for (topic, packer, vehicle), speeds in zip(self._margins, rotor_speeds)]

    def events(self, t_ns: int, rows: np.ndarray) -> list[Message]:
        """/formation/events: one message per event row (physics.layout EVENT_*) that
        happened at the tick t_ns, sent after the tick's state (which shows them)."""
        return [(EVENTS, self._event.pack(t_ns, *formation_event(row))) for row in rows]

    def formation(self, t_ns: int, tension: np.ndarray, g: np.ndarray, g_dot: np.ndarray,
                  taut: np.ndarray) -> Message:
        """/formation/state: per cable the tension [N], g [m^2], g_dot [m^2/s], taut."""
        return self.formation_of(t_ns, tension.tolist(), g.tolist(), g_dot.tolist(),
                                 taut.tolist())

    def formation_of(self, t_ns: int, tension: Sequence[float], g: Sequence[float],
                     g_dot: Sequence[float], taut: Sequence[bool]) -> Message:
        """`formation` from plain numbers."""
        return FORMATION_STATE, self._state.pack(t_ns, tension, g, g_dot, taut)

    def margins(self, rotor_speeds: Sequence[Sequence[float]] | None) -> list[Message]:
        """/uav{i}/thrust_margin of a tick (a reorganising formation, else none): each UAV's
        1 - u_T / u_T,max = 1 - sum_r omega_r^2 / (N omega_max^2) of the rotor speeds its
        commands held over the tick [rad/s] (seed Eq. 2.9 with equal k_T; every rotor counted
        fully effective, as `multilift plot`'s thrust_margins.png; the summary's
        least_thrust_margin also counts a failed rotor's effectiveness)."""
        out: list[Message] = []
        if rotor_speeds is None:  # no command yet
            return out
        for (topic, packer, vehicle), speeds in zip(self._margins, rotor_speeds):
            out.append((topic, packer.pack(vehicle.thrust_margin(speeds))))
        return out

    def markers(self, snap: Snapshot, tension: np.ndarray, taut: np.ndarray) -> Message:
        """/visualization/markers: the formation of `snap` drawn (cables by tension)."""
        return self.markers_of(snap.t_ns, [u.position for u in snap.uavs],
                               [u.euler for u in snap.uavs], snap.payload_position, tension,
                               taut, None if snap.payload_attitude is None
                               else snap.payload_attitude[0], snap.chain_points)

    def markers_of(self, t_ns: int, positions: Sequence[Sequence[float]],
                   euler: Sequence[Sequence[float]], payload_position: Sequence[float],
                   tension: Sequence[float], taut: Sequence[bool],
                   payload_orientation: Sequence[float] | None = None,
                   chain_points: Sequence | None = None) -> Message:
        """`markers` from plain numbers: every UAV's position [m] and ZYX Euler angles [rad],
        the payload's position [m] (and a rigid one's orientation (x, y, z, w)), the cables'
        tension [N] and which are taut (and heavy cables' inner nodes (n, N - 1, 3) [m])."""
        self._scene.update(positions, euler, payload_position, tension, taut,
                           payload_orientation, chain_points)
        return MARKERS, self._markers.pack(t_ns)


def state_rows(states: np.ndarray, n: int, measured: np.ndarray | None = None,
               payload_estimate: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The numbers `SimulatorMessages.state_of` takes, for K formation states (K, len(x))
    of n UAVs at once: (the FormationSnapshot rows (K, 12 n + 6) without the rotor speeds,
    every UAV's odometry row (K, n, 13)). One call of physics.measurement.odometry_states,
    which `FormationSimulator.snapshot` calls too: the same bits tick by tick
    (tests/unit/test_headless_bag.py). The snapshot carries what the controllers received,
    `measured` (K, n, MEASURED_COLUMNS), where given (the engine's record), else the state's,
    and of the payload its estimate `payload_estimate` (K, ESTIMATE_COLUMNS) where given (a
    payload estimator), else the state's."""
    k, layout = states.shape[0], StateLayout(n)
    rows = np.empty((k, n, ODOMETRY_COLUMNS))
    odometry_states(np.ascontiguousarray(states), n, rows)
    received = rows if measured is None else measured
    snapshot = np.concatenate(
        [received[..., block:block + 3].reshape(k, 3 * n) for block in SNAPSHOT_BLOCKS]
        + list((layout.payload_position(states), layout.payload_velocity(states))
               if payload_estimate is None else payload_read(payload_estimate)), axis=1)
    return snapshot, rows[..., ODOMETRY_NUMBERS]


def measured_odometry(measured: np.ndarray) -> np.ndarray:
    """The odometry's 13 numbers (K, n, 13) (`SimulatorMessages.state_of`'s `measured`) of
    what the controllers receive, (K, n, MEASURED_COLUMNS) (physics.measurement.odometry_rows:
    the attitude and body-frame velocity of the measurement)."""
    k, n = measured.shape[:2]
    rows = np.zeros((k, n, ODOMETRY_COLUMNS))
    rows[..., :MEASURED_COLUMNS] = measured
    kernels.runnable(odometry_rows)(rows)
    return rows[..., ODOMETRY_NUMBERS]


def payload_motion(attitude: tuple | None, velocity: np.ndarray) -> tuple[list, tuple | None]:
    """What /payload/odom and /tf carry of the payload's motion: (its velocity [m/s], in its own
    frame for a rigid body (R_p^T v_p, as nav_msgs/Odometry's twist is), else world; its pose
    for `SimulatorMessages.state_of`: (orientation (x, y, z, w), body rates [rad/s]), None for
    a point payload) from `simulation.payload_attitude`'s triple (or None)."""
    if attitude is None:
        return velocity.tolist(), None
    quaternion, rates, rotation = attitude
    return (rotation.T @ velocity).tolist(), (tuple(quaternion.tolist()), tuple(rates.tolist()))
