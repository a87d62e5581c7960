"""Simulator node: integrates the formation DAE in lockstep with the controllers.

Each control tick it publishes `/clock`, `/formation/snapshot` (every UAV's and the payload's
state at t and the rotor speeds applied up to t: what the controllers read, one message a tick),
and for users, tools and bags the state at t as `/uav{i}/odom`, `/payload/odom`, `/tf`
(world -> uav{i}/base_link and world -> payload, the odometry's poses) and `/payload/gust` (the
gust velocity at the payload, world frame; `/visualization/markers` every tenth tick); it waits
for a `/uav{i}/rotor_cmd` stamped t from every UAV, publishes `/formation/state`, and integrates
to the next tick. No command within `command_timeout` wall seconds stops the run naming the
silent UAV. Parameters: scenario (name or path), record (wait for a recorder), realtime (pace to
the wall clock), duration (override t_max, s), summary_dir, progress_file, external (`uav1,uav3`:
UAVs flown by controller nodes it does not start, the user's own or ours on another host;
before t = 0 the simulator waits for a node publishing their rotor commands that subscribes to
a state topic, `topics.state_topics`),
startup_timeout (wall seconds to wait for the graph, s; 0: STARTUP_TIMEOUT).

The rotor command subscriptions adapt to the publishers' QoS (`introspection.
AdaptiveSubscription`): any reliable publisher is heard, transient_local or volatile.
"""
from __future__ import annotations

import time
from typing import NoReturn

import numpy as np
from geometry_msgs.msg import Vector3Stamped
from multilift_msgs.msg import (FormationEvent, FormationSnapshot, FormationState, RotorCommand,
                                WinchCommand)
from nav_msgs.msg import Odometry
from rclpy.node import Node, NodeNameNonExistentError
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from multilift_sim import scenario as scenario_io
from multilift_sim.ros.common import (FIRST_ACK_TIMEOUT, PUBLISHER_QOS, STARTUP_TIMEOUT,
                                      Fatal, RawPublishers, ns_from_stamp,
                                      recorder_hears, recorder_missing, run_node, wait_until,
                                      write_summary)
from multilift_sim.ros.introspection import AdaptiveSubscription
from multilift_sim.topics import (CABLE_LENGTH, CLOCK, ESTIMATE, EVENTS, FORMATION_SNAPSHOT,
                                  FORMATION_STATE, MARKER_DECIMATION, MARKERS, MEASURED_ODOM,
                                  ODOM, PAYLOAD_ESTIMATE, PAYLOAD_GUST, PAYLOAD_ODOM, ROTOR_CMD,
                                  TF, THRUST_MARGIN, WIND, WINCH_CMD, WINCH_CMD_STAMPED,
                                  margin_topics, parse_external, state_topics, uav_topic)
from multilift_sim.simulation import FormationSimulator, SimulationStopped, Snapshot, TickCables
from multilift_sim.schedules import run_seeds
from multilift_sim.wire.tick_messages import SimulatorMessages


# [s] the graph stays complete this long before t = 0 when a user's node answers (see
# missing_peers): discovery reaches every participant within milliseconds of each other
EXTERNAL_SETTLE = 0.5
# a live reel rate's subscription: reliable and volatile, what a default publisher
# (create_publisher(Float64, topic, 10)) offers; a transient_local publisher matches it too
WINCH_QOS = QoSProfile(depth=10)


class SimNode(Node):
    def __init__(self) -> None:
        super().__init__('sim')
        name = self.declare_parameter('scenario', '').value
        self.record = bool(self.declare_parameter('record', False).value)
        self.realtime = bool(self.declare_parameter('realtime', False).value)
        duration = float(self.declare_parameter('duration', 0.0).value)
        self.summary_dir = self.declare_parameter('summary_dir', '').value
        self.progress_file = self.declare_parameter('progress_file', '').value
        external = str(self.declare_parameter('external', '').value)
        self.startup_timeout = float(self.declare_parameter('startup_timeout', 0.0).value) \
            or STARTUP_TIMEOUT
        live = bool(self.declare_parameter('live', False).value)
        if not name:
            raise Fatal('parameter "scenario" is required (a name in scenarios/ or a path)')
        scenario = scenario_io.load(name)
        if duration > 0:
            scenario = scenario.with_duration(duration)  # a ScenarioError ends the node (2)
        self.scenario = scenario
        self.sim = FormationSimulator(scenario)
        n = scenario.n_uavs
        try:
            self.external = parse_external(external, n)
        except ValueError as error:
            raise Fatal(f'parameter "external": {error}') from None
        self.clock_pub = self.create_publisher(Clock, CLOCK, PUBLISHER_QOS)
        self.odom_pubs = [self.create_publisher(Odometry, uav_topic(i + 1, ODOM), PUBLISHER_QOS)
                          for i in range(n)]
        self.payload_pub = self.create_publisher(Odometry, PAYLOAD_ODOM, PUBLISHER_QOS)
        self.snapshot_pub = self.create_publisher(FormationSnapshot, FORMATION_SNAPSHOT,
                                                  PUBLISHER_QOS)
        self.applied: list[np.ndarray] | None = None  # rotor speeds held up to this tick
        self.formation_pub = self.create_publisher(FormationState, FORMATION_STATE,
                                                   PUBLISHER_QOS)
        self.gust_pub = self.create_publisher(Vector3Stamped, PAYLOAD_GUST, PUBLISHER_QOS)
        self.marker_pub = self.create_publisher(MarkerArray, MARKERS, PUBLISHER_QOS)
        self.tf_pub = self.create_publisher(TFMessage, TF, PUBLISHER_QOS)
        # /formation/events only where the scenario has events (topics.run_topics)
        events = [self.create_publisher(FormationEvent, EVENTS, PUBLISHER_QOS)] \
            if scenario.events else []
        # /formation/wind where the air moves everywhere
        winds = [self.create_publisher(Vector3Stamped, WIND, PUBLISHER_QOS)] \
            if scenario.has_wind else []
        # /uav{i}/measured_odom, what the controllers receive, where it has `sensors:`
        self.measured_pubs = [self.create_publisher(Odometry, uav_topic(i + 1, MEASURED_ODOM),
                                                    PUBLISHER_QOS)
                              for i in range(n)] if scenario.measures else []
        # /uav{i}/estimate, each UAV's estimate with its covariance, with an estimator
        estimates = [self.create_publisher(Odometry, uav_topic(i + 1, ESTIMATE), PUBLISHER_QOS)
                     for i in range(n)] if scenario.estimator is not None else []
        # /payload/estimate, the payload's estimate with its covariance, with a payload estimator
        payload_estimate = [self.create_publisher(Odometry, PAYLOAD_ESTIMATE, PUBLISHER_QOS)] \
            if scenario.payload_estimator is not None else []
        # /uav{i}/cable_length of each UAV with a winch
        lengths = [self.create_publisher(Float64, uav_topic(i, CABLE_LENGTH), PUBLISHER_QOS)
                   for i in scenario.winches]
        # /uav{i}/thrust_margin of every UAV of a reorganising formation
        margins = [self.create_publisher(Float64, uav_topic(i, THRUST_MARGIN), PUBLISHER_QOS)
                   for i in range(1, n + 1)] if margin_topics(scenario) else []
        # every message goes out as CDR bytes packed from the tick's numbers (tick_messages)
        self.packer = SimulatorMessages(scenario)
        self.outputs = RawPublishers(
            self.clock_pub, *self.odom_pubs, self.payload_pub, self.snapshot_pub,
            self.formation_pub, self.gust_pub, self.marker_pub, self.tf_pub, *events, *winds,
            *self.measured_pubs, *estimates, *payload_estimate, *lengths, *margins,
            confirm_first=FIRST_ACK_TIMEOUT if self.record else 0.0)
        # a user's node publishes volatile as a rule: ask it of theirs from the start (our own
        # controllers offer transient_local, which the request adapts to)
        self.cmd_subs = [AdaptiveSubscription(
            self, RotorCommand, uav_topic(i + 1, ROTOR_CMD),
            lambda msg, i=i: self._on_command(i, msg), depth=PUBLISHER_QOS.depth,
            durability=DurabilityPolicy.VOLATILE if i + 1 in self.external else None)
            for i in range(n if scenario.controlled else 0)]  # none: every UAV prescribed
        self.commands: list[RotorCommand | None] = [None] * len(self.cmd_subs)
        # live reel rates (`run --live`) for each UAV with a winch, from the next period on
        self.winch_subs = [self.create_subscription(
            Float64, uav_topic(i, WINCH_CMD), lambda msg, i=i: self._on_winch(i, msg),
            WINCH_QOS) for i in (scenario.winches if live else ())] + [
            self.create_subscription(WinchCommand, uav_topic(i, WINCH_CMD_STAMPED),
                                     lambda msg, i=i: self._on_winch(i, msg), WINCH_QOS)
            for i in (scenario.winches if live else ())]

    def _on_command(self, index: int, msg: RotorCommand) -> None:
        if ns_from_stamp(msg.header.stamp) == self.sim.t_ns:
            self.commands[index] = msg

    def _on_winch(self, index: int, msg: Float64 | WinchCommand) -> None:
        """/uav{index}/winch_cmd: its winch reels at msg.data [m/s] from the period of the
        tick being answered on (Float64 carries no stamp); /uav{index}/winch_cmd_stamped: at
        msg.rate from the first tick at or after msg.header.stamp (simulated time; a stamp
        already past: the tick being answered). A rate that is no number is logged and
        ignored."""
        stamped = isinstance(msg, WinchCommand)
        rate = float(msg.rate if stamped else msg.data)
        at_ns = ns_from_stamp(msg.header.stamp) if stamped else None
        try:
            tick = self.sim.command_winch(index - 1, rate, at_ns)
        except ValueError as error:
            leaf = WINCH_CMD_STAMPED if stamped else WINCH_CMD
            self.get_logger().warning(f'{uav_topic(index, leaf)} ignored: {error}')
            return
        late = '' if at_ns is None or at_ns >= self.sim.t_ns else \
            f' ({(self.sim.t_ns - at_ns) * 1e-9:.3f} s after its stamp)'
        self.get_logger().info(f'uav{index} winch commanded to {rate:g} m/s at t = '
                               f'{tick * self.sim.period_ns * 1e-9:.3f} s{late}')

    _external_ready_since: float | None = None

    def missing_peers(self) -> str | None:
        """What the lockstep still waits for before t = 0, or None."""
        missing = []
        for i, sub in enumerate(self.cmd_subs):
            sub.adapt()
            topic = uav_topic(i + 1, ROTOR_CMD)
            if i + 1 not in self.external:
                if sub.subscription.get_publisher_count() < 1:
                    missing.append(f'a controller publishing {topic}')
                continue
            # a node we did not start (a user's, or our leader or follower on another host):
            # it must hear the state at t = 0 (a volatile reader gets only what is published
            # after it matched), whichever state topic it reads, and answer on the command topic
            if not self._reads_state(topic):
                missing.append(f'the external controller of uav{i + 1} to subscribe to a state '
                               f'topic ({self._state_topics_text(i + 1)})')
            if sub.subscription.get_publisher_count() < 1:
                missing.append(f'the external controller of uav{i + 1} to publish {topic}')
            elif self.record and not recorder_hears(self, topic):
                missing.append(f'the recorder to subscribe to {topic}')
        if missing:
            self._external_ready_since = None
            return '; '.join(missing)
        if self.external and self.record:
            # the recorder's reader of a user's volatile command topic is in our graph, but the
            # user's writer learns of it on its own: a command published before that match is
            # lost to the bag, so the graph has to stay complete a moment first
            now = time.monotonic()
            if self._external_ready_since is None:
                self._external_ready_since = now
            if now - self._external_ready_since < EXTERNAL_SETTLE:
                return 'the external controllers\' writers to match the recorder'
        if self.record:
            return recorder_missing(self, [self.clock_pub, self.payload_pub, self.formation_pub,
                                           self.snapshot_pub, self.gust_pub, self.marker_pub,
                                           self.tf_pub,
                                           *self.odom_pubs, *self.measured_pubs])
        return None

    def _reads_state(self, command_topic: str) -> bool:
        """Whether a node publishing `command_topic` subscribes to one of the simulator's state
        topics. The graph lists a node's subscriptions once our participant discovered them,
        which is when our writers match them."""
        wanted = set(state_topics(self.sim.n, self.scenario.measures))
        for info in self.get_publishers_info_by_topic(command_topic):
            if not info.node_namespace.startswith('/'):
                continue  # the writer is known, its node not yet (_NODE_NAMESPACE_UNKNOWN_)
            try:
                read = self.get_subscriber_names_and_types_by_node(info.node_name,
                                                                   info.node_namespace)
            except NodeNameNonExistentError:  # its node's announcement has not arrived yet
                continue
            if any(name in wanted for name, _ in read):
                return True
        return False

    def _state_topics_text(self, index: int) -> str:
        """The state topics in words for UAV `index`: its own odometry first."""
        own = uav_topic(index, ODOM)
        others = [t for t in state_topics(self.sim.n, self.scenario.measures)
                  if t != own]
        return ', '.join([own] + others)

    def publish_state(self) -> Snapshot:
        """The state at this tick, the controllers' snapshot first (they answer while the rest
        goes out; at the run's last tick there is nothing to answer and no snapshot); returns
        the snapshot."""
        snap = self.sim.snapshot()
        self.outputs.send(self.packer.state(snap, self.sim.payload_gust, self.applied,
                                            last=self.sim.finished, wind=self.sim.wind))
        if self.sim.happened:  # the scenario's events this state is the first to show
            self.outputs.send(self.packer.events(snap.t_ns, self.sim.happened_rows()))
        return snap

    def wait_for_commands(self) -> None:
        deadline = time.monotonic() + self.scenario.simulation.command_timeout
        next_adapt = time.monotonic() + 0.5
        while any(c is None for c in self.commands):
            if time.monotonic() > next_adapt:  # a controller came back with other QoS
                next_adapt = time.monotonic() + 0.5
                for sub in self.cmd_subs:
                    sub.adapt()
            if time.monotonic() > deadline:
                silent = [f'uav{i + 1}' for i, c in enumerate(self.commands) if c is None]
                raise Fatal(f'no rotor command from {", ".join(silent)} within '
                            f'{self.scenario.simulation.command_timeout:g} s (wall) for the '
                            f'state at t = {self.sim.t:.3f} s')
            self.executor.spin_once(timeout_sec=0.1)

    def publish_formation(self, snap: Snapshot, held: TickCables) -> None:
        """/formation/state (and the markers) of the tick of `snap`, once it is integrated:
        the tension comes from that integration (`FormationSimulator.cables_of`)."""
        tension, g, g_dot = self.sim.cables_of(held)
        self.outputs.send([self.packer.formation(snap.t_ns, tension, g, g_dot, held.taut)]
                          + self.packer.margins(held.rotor_speeds))
        if held.tick % MARKER_DECIMATION == 0:
            self.outputs.send([self.packer.markers(snap, tension, held.taut)])

    def run(self) -> None:
        wait_until(self, self.missing_peers, self.startup_timeout)
        wall_start = time.monotonic()
        last_progress = 0.0
        try:
            while True:
                self.commands = [None] * len(self.cmd_subs)
                snap = self.publish_state()
                if self.sim.finished:
                    # a run of duration T asks for commands for the states before T only: the
                    # last tick's cables are those of the commands held since the tick before
                    self.publish_formation(snap, self.sim.tick_cables(self.applied))
                    break
                self.wait_for_commands()
                if self.scenario.controlled:
                    speeds = [np.array(c.angular_velocity, dtype=float) for c in self.commands]
                    flags = [np.array(c.saturated, dtype=bool) for c in self.commands]
                else:  # every UAV's motion prescribed: no controller, no command
                    speeds, flags = self.sim.idle_commands()
                held = self.sim.tick_cables(speeds)
                try:
                    self.sim.advance(speeds, flags)
                finally:  # a stopped run has its last tick's /formation/state too
                    self.publish_formation(snap, held)
                self.applied = speeds
                wall = time.monotonic() - wall_start
                if self.realtime and self.sim.t > wall:
                    time.sleep(self.sim.t - wall)
                if self.progress_file and wall - last_progress > 0.5:
                    last_progress = wall
                    self._progress(wall)
        except SimulationStopped as exc:
            self._finish(time.monotonic() - wall_start, str(exc))
            raise Fatal(str(exc)) from None
        self._finish(time.monotonic() - wall_start, None)

    def _progress(self, wall: float) -> None:
        t_max = self.sim.tick_count * self.sim.period_ns * 1e-9
        with open(self.progress_file, 'w') as f:
            f.write(f'{self.sim.t:.3f} {t_max:.3f} {wall:.3f}\n')

    def _finish(self, wall: float, error: str | None) -> None:
        if self.progress_file:
            self._progress(wall)
        stats = self.sim.stats.as_dict()
        stats.update(wall_time=wall, error=error, scenario=self.scenario.name,
                     events=self.sim.events_summary(),
                     seeds=run_seeds(self.scenario), **self.sim.clearance_summary())
        write_summary(self.summary_dir, 'sim', stats)


def main(args: list[str] | None = None) -> NoReturn:
    run_node(SimNode, lambda node: node.run(), args)


if __name__ == '__main__':
    main()
