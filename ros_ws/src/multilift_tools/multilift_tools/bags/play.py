"""`BagPlayer`: a bag's messages published with their recorded timing, as `ros2 bag play`.

play (needs metadata.yaml or an MCAP summary: reindex a torn bag first): one publisher per
topic, raw CDR bytes as recorded, at log time / R after the first played
message (wall clock; sleeps are absolute, so delays do not accumulate). Publisher QoS follows
rosbag2 (`Rosbag2QoS::adapt_offer_to_recorded_offers`): the recorded offers' reliability and
durability when every offer agrees, else reliable + volatile; keep_last PLAY_DEPTH. `/clock`:
a bag that recorded /clock (our simulator's runs) has it played like any topic, which is the
simulated time itself; when /clock is not played (not recorded, or left out by --topics) the
player publishes the playback time (the bag's log time) on /clock at --clock-rate Hz. --loop
starts over after the last message (time jumps back); --start-offset S skips the first S seconds
of the bag; --delay S waits S wall seconds after creating the publishers (discovery), and
--wait-for-subscribers until every publisher has a subscriber. Topics whose message package is
not installed are skipped with a warning, as rosbag2 does. Ctrl-C or SIGTERM stops at once; at
the end the player waits up to ACK_WAIT s for reliable subscribers to acknowledge.
"""
from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Iterable, Iterator

from mcap.reader import make_reader

from multilift_sim.topics import CLOCK as CLOCK_TOPIC
from multilift_tools.bags.summary import BagToolError, mcap_file, read_summary

PLAY_DEPTH = 100  # keep_last depth of the player's publishers (our nodes' PUBLISHER_QOS depth)
ACK_WAIT = 3.0  # [s] longest wait for reliable subscribers to acknowledge the last messages
WAIT_FOR_SUBSCRIBERS_MAX = 30.0  # [s] longest --wait-for-subscribers wait
SLEEP_SLICE = 0.05  # [s] longest sleep between checks of Ctrl-C


@dataclass(frozen=True)
class PlayOptions:
    """Options of `bag play`: rate factor, loop, topics (None = all), start offset [s], delay
    after creating publishers [s], wait for subscribers, rate of a generated /clock [Hz]."""

    rate: float = 1.0
    loop: bool = False
    topics: tuple[str, ...] | None = None
    start_offset: float = 0.0
    delay: float = 0.0
    wait_for_subscribers: bool = False
    clock_rate: float = 100.0


def playback_qos_policies(profiles: list[dict[str, Any]]) -> tuple[str, str]:
    """(reliability, durability) for a player's publisher from the recorded offered profiles.

    rosbag2's rule: the recorded policies when every profile agrees, else reliable + volatile
    (also with no profile). Unknown or 'system_default' policies fall back the same way.
    """
    reliabilities = {str(p.get('reliability', '')).lower() for p in profiles}
    durabilities = {str(p.get('durability', '')).lower() for p in profiles}
    if (len(reliabilities) == 1 and len(durabilities) == 1
            and reliabilities <= {'reliable', 'best_effort'}
            and durabilities <= {'volatile', 'transient_local'}):
        return reliabilities.pop(), durabilities.pop()
    return 'reliable', 'volatile'


@dataclass(frozen=True, order=True)
class PlayEvent:
    """One thing to publish at bag time `time_ns` [ns]: a recorded message (`data`, CDR), or a
    generated /clock tick (`topic` == CLOCK_TOPIC, `data` None)."""

    time_ns: int
    order: int
    topic: str = field(compare=False)
    data: bytes | None = field(compare=False, default=None)


def play_events(messages: Iterable[tuple[str, bytes, int]], start_ns: int,
                clock_period_ns: int | None) -> Iterator[PlayEvent]:
    """Recorded `(topic, data, log_time_ns)` messages (in log time order, from `start_ns` on)
    merged with /clock ticks every `clock_period_ns` [ns] from `start_ns` (None: no ticks).

    A tick and a message at the same time: the tick comes first. Ticks stop at the last message.
    """
    order = 0
    next_tick = start_ns
    for topic, data, log_time in messages:
        while clock_period_ns is not None and next_tick <= log_time:
            yield PlayEvent(next_tick, order, CLOCK_TOPIC)
            order += 1
            next_tick += clock_period_ns
        yield PlayEvent(log_time, order, topic, data)
        order += 1


def wall_offset(time_ns: int, first_ns: int, rate: float) -> float:
    """Wall seconds after the start of playback at which bag time `time_ns` [ns] is played."""
    return (time_ns - first_ns) * 1e-9 / rate


class _Stop:
    """Set by SIGINT/SIGTERM; sleeps that end early when it is set."""

    def __init__(self) -> None:
        self.event = threading.Event()

    def __call__(self, signum: int, frame: object) -> None:
        self.event.set()

    def sleep_until(self, deadline: float) -> bool:
        """Sleep until time.monotonic() >= deadline; False if stopped first."""
        while not self.event.is_set():
            left = deadline - time.monotonic()
            if left <= 0:
                return True
            # a sleep, not self.event.wait(): the signal handler (this thread) sets the event,
            # and Event.set takes the lock Event.wait holds at moments: a deadlock
            time.sleep(min(left, SLEEP_SLICE))
        return False


class BagPlayer:
    """Publishes one bag's messages (see the module docstring) from a node of its own."""

    def __init__(self, path: str | os.PathLike, options: PlayOptions,
                 stop: _Stop | None = None, log=print) -> None:
        self.options = options
        self.stop = stop or _Stop()
        self.log = log
        self.summary = read_summary(path)
        if self.summary.source == 'scan':
            raise BagToolError(f'{self.summary.directory} has neither metadata.yaml nor an MCAP '
                               'summary (was its recorder killed?): run `multilift bag '
                               f'reindex {self.summary.directory}` first')
        self.mcap_path = mcap_file(self.summary.directory,
                                   {'relative_file_paths': self.summary.files})
        recorded = {t.name: t for t in self.summary.topics}
        wanted = list(options.topics) if options.topics else sorted(recorded)
        for name in wanted:
            if name not in recorded:
                self.log(f'warning: topic {name} is not in the bag; ignored')
        self.topics = [recorded[name] for name in wanted if name in recorded]
        if not self.topics:
            raise BagToolError(f'{self.summary.directory}: no topic to play')
        self.publishers: dict[str, Any] = {}
        self.clock_publisher = None
        self.node = None
        self.published = 0

    def _make_publishers(self) -> None:
        import rclpy
        from rclpy.qos import (DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile,
                               ReliabilityPolicy)
        from rosgraph_msgs.msg import Clock

        from multilift_sim.ros.introspection import import_message_type
        self.node = rclpy.create_node(f'multilift_bag_player_{os.getpid()}',
                                      start_parameter_services=False)
        for topic in self.topics:
            try:
                msg_type = import_message_type(topic.type)
            except ValueError as error:
                self.log(f'warning: not playing {topic.name}: {error}')
                continue
            reliability, durability = playback_qos_policies(topic.offered_qos_profiles)
            qos = QoSProfile(
                history=HistoryPolicy.KEEP_LAST, depth=PLAY_DEPTH,
                reliability=(ReliabilityPolicy.RELIABLE if reliability == 'reliable'
                             else ReliabilityPolicy.BEST_EFFORT),
                durability=(DurabilityPolicy.TRANSIENT_LOCAL if durability == 'transient_local'
                            else DurabilityPolicy.VOLATILE),
                liveliness=LivelinessPolicy.AUTOMATIC)
            self.publishers[topic.name] = self.node.create_publisher(msg_type, topic.name, qos)
        if not self.publishers:
            raise BagToolError(f'{self.summary.directory}: none of the topics can be played')
        if CLOCK_TOPIC not in self.publishers and self.options.clock_rate > 0:
            self.clock_publisher = self.node.create_publisher(
                Clock, CLOCK_TOPIC, QoSProfile(
                    history=HistoryPolicy.KEEP_LAST, depth=1,
                    reliability=ReliabilityPolicy.RELIABLE,
                    durability=DurabilityPolicy.TRANSIENT_LOCAL))

    def _wait_for_subscribers(self) -> bool:
        deadline = time.monotonic() + WAIT_FOR_SUBSCRIBERS_MAX
        publishers = dict(self.publishers)  # the generated /clock's too
        if self.clock_publisher is not None:
            publishers[CLOCK_TOPIC] = self.clock_publisher
        while True:
            lonely = [name for name, pub in publishers.items()
                      if pub.get_subscription_count() == 0]
            if not lonely:
                return True
            if time.monotonic() > deadline:
                self.log(f'warning: no subscriber on {", ".join(lonely)} after '
                         f'{WAIT_FOR_SUBSCRIBERS_MAX:g} s; playing anyway')
                return True
            if not self.stop.sleep_until(time.monotonic() + 0.05):
                return False

    def _messages(self, start_ns: int) -> Iterator[tuple[str, bytes, int]]:
        with open(self.mcap_path, 'rb') as stream:
            reader = make_reader(stream)
            for _, channel, message in reader.iter_messages(
                    topics=list(self.publishers), start_time=start_ns, log_time_order=True):
                yield channel.topic, message.data, message.log_time

    def _publish_clock(self, t_ns: int) -> None:
        from builtin_interfaces.msg import Time
        from rosgraph_msgs.msg import Clock
        self.clock_publisher.publish(Clock(clock=Time(sec=t_ns // 1_000_000_000,
                                                      nanosec=t_ns % 1_000_000_000)))

    def play_once(self, start_ns: int) -> bool:
        """Play from bag time `start_ns` [ns] to the end; False if stopped."""
        period = (int(round(1e9 / self.options.clock_rate))
                  if self.clock_publisher is not None else None)
        wall_start = None
        first_ns = start_ns
        for event in play_events(self._messages(start_ns), start_ns, period):
            if wall_start is None:
                wall_start = time.monotonic()
            deadline = wall_start + wall_offset(event.time_ns, first_ns, self.options.rate)
            if not self.stop.sleep_until(deadline):
                return False
            if event.data is None:
                self._publish_clock(event.time_ns)
            else:
                self.publishers[event.topic].publish(event.data)
                self.published += 1
        return True

    def run(self) -> bool:
        """Create the publishers, wait as asked, play (and loop); False if stopped."""
        self._make_publishers()
        if self.options.delay > 0 and not self.stop.sleep_until(
                time.monotonic() + self.options.delay):
            return False
        if self.options.wait_for_subscribers and not self._wait_for_subscribers():
            return False
        start_ns = self.summary.starting_time_ns + int(round(self.options.start_offset * 1e9))
        while True:
            if not self.play_once(start_ns):
                return False
            if not self.options.loop:
                break
        self._wait_for_acks()
        return True

    def _wait_for_acks(self) -> None:
        from rclpy.duration import Duration
        deadline = time.monotonic() + ACK_WAIT
        for publisher in self.publishers.values():
            left = deadline - time.monotonic()
            if left <= 0 or self.stop.event.is_set():
                return
            publisher.wait_for_all_acked(Duration(nanoseconds=int(left * 1e9)))

    def close(self) -> None:
        """Destroy the node (and its publishers)."""
        if self.node is not None:
            self.node.destroy_node()
            self.node = None
