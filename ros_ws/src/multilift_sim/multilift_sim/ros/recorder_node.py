"""Records topics into a rosbag2 (MCAP) bag: `ros2 bag record` for this workspace.

    recorder_node --ros-args -p bag:=DIR [-p "topics:=['/a|pkg/msg/A', ...]"] [-p all:=false]
                  [-p time_source:=auto|sim|wall] [-p compression:=zstd|lz4|none]
                  [-p flush_period:=1.0]

- `topics` are subscribed at once; with `all` (default true) every other topic that has a
  publisher is added when it appears (graph polled every 0.5 s), the user's own nodes' topics
  included, except /rosout,
  /parameter_events and hidden topics.
- Subscriptions are raw (the CDR bytes go into the bag untouched), keep_last 10,000, reliable +
  transient_local (our publishers are reliable + transient_local, so a recorder that starts late
  still gets their startup messages). Where publishers already offer less when the topic is
  subscribed, the request is lowered to match them, as rosbag2 does (`introspection.adapted_qos`);
  a publisher that appears later and would not match (a node publishing with the defaults:
  reliable, volatile) makes the recorder subscribe again with the lowered request
  (`introspection.AdaptiveSubscription`, checked at every graph poll).
- Log time: rosbag2 stamps receive (wall) time. Our simulation runs in lockstep on simulated time,
  usually faster than real time, so wall times would stretch or squeeze the run and differ from
  run to run. With `time_source` auto (default) a bag whose first message finds /clock published
  is stamped with simulated time (0 before the first /clock, as ROS time with use_sim_time), else
  with wall time; chosen once per bag so log times never jump between clocks
  (`recording.LogTime`). In sim time a message is stamped with the latest /clock *sent* before
  it (by the senders' source timestamps), so reading late does not shift it: in a lockstep run
  the simulator's messages are logged at their own tick (their header.stamp). A message waits
  (HOLD_MAX s at most) until a /clock sent after it has arrived.
  (`ros2 bag record --use-sim-time` stamps with node time, which follows /clock as received.)
- Reading in rounds: every `ROUND_PERIOD` s the recorder takes what waits on every topic, in
  batches, straight from the subscriptions (the executor runs once a round, for the timers and
  graph events). rclpy's executor costs about 0.2 ms a wake-up; woken per message, the recorder was
  the largest CPU user of a ROS run (py-spy of `run twin_lift --bag`: 57 % of a core against
  the simulator's 50 %).
- `publish_time` of each MCAP message is the sender's source timestamp (wall time [ns]), as
  rosbag2 stores it.
- Every `flush_period` [s] the chunk in progress is finished, so a crash loses at most that much
  (and what waits for its log time to settle: a round, HOLD_MAX s at most);
  `bag.recover()` turns what a killed recorder left into a complete bag.
- SIGINT or SIGTERM: keep receiving until 0.3 s pass without a message (3 s at most; a second
  signal stops at once), close the bag (`metadata.yaml` written) and exit 0. A drain or close
  still running HANG_REPORT s after the signal writes its stacks to stderr (the log). A recorder
  that dies without closing the bag leaves its complete chunks: `multilift run` rebuilds the bag
  from them and says so (`multilift_tools.run_command._bag_state`).
"""

from __future__ import annotations

import faulthandler
import functools
import signal
import sys
import threading
import time

import rclpy
from rclpy.exceptions import ParameterUninitializedException
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions
from rclpy.subscription import Subscription
from rosgraph_msgs.msg import Clock

from multilift_sim.bag import recording
from multilift_sim.ros import introspection
from multilift_sim.ros.fastdds import use_fastdds_profile
from multilift_sim.bag import BagError, BagWriter
from multilift_sim.bag.metadata_yaml import qos_yaml

POLL_PERIOD = 0.5  # [s] graph poll for new topics
DRAIN_QUIET = 0.3  # [s] without messages that ends the drain
DRAIN_MAX = 3.0  # [s] longest drain
# Messages of one topic taken in one callback: the executor costs ~0.2 ms a message, a take
# ~0.01 ms, so a backlog is read in batches (bounded, so /clock and other topics keep their turn).
TAKE_BATCH = 256
ROUND_PERIOD = 0.02  # [s] between reading rounds (a round takes every message waiting)
CLOCK_DEPTH = introspection.RECORD_QOS_DEPTH  # /clock messages a round can find waiting
HOLD_MAX = 1.0  # [s] longest a message waits for the /clock after it (its log time settled)
HANG_REPORT = 7.0  # [s] after a stop signal: the stacks of a drain or close still running


class RecorderNode(Node):
    """Subscribes raw to the topics to record and writes them to one BagWriter."""

    def __init__(self) -> None:
        super().__init__('recorder')
        self.declare_parameter('bag', '')
        self.declare_parameter('topics', Parameter.Type.STRING_ARRAY)
        self.declare_parameter('all', True)
        self.declare_parameter('time_source', 'auto')
        self.declare_parameter('compression', 'zstd')
        self.declare_parameter('flush_period', 1.0)
        directory = self.get_parameter('bag').value
        if not directory:
            raise BagError('parameter bag (the bag directory) is required: -p bag:=DIR')
        try:
            listed = self.get_parameter('topics').value
        except ParameterUninitializedException:
            listed = []
        specs = [recording.parse_topic_spec(s) for s in listed]
        self._log_time = recording.LogTime(self.get_parameter('time_source').value)
        self.bag = BagWriter(directory, compression=self.get_parameter('compression').value,
                             custom_data={'recorder': 'multilift_sim recorder_node',
                                          'time_source': self._log_time.mode})
        self.last_receive = time.monotonic()
        self._types: dict[str, str] = {}
        self._recorded: dict[str, Subscription] = {}
        self._skipped: set[str] = set()
        self._in_bag: set[str] = set()
        # topic -> (publishers seen in the graph, of them matched by our reader) at a graph poll
        # where the topic had publishers: a topic that ends with no message is reported with it
        self._publishers_seen: dict[str, tuple[int, int]] = {}
        # messages whose sim log time may still change: (topic, data, sent [ns], taken at [s])
        self._held: list[tuple[str, bytes, int, float]] = []
        # the time source: reliable where /clock's publisher offers it, so no /clock is lost
        self._clock_source = introspection.AdaptiveSubscription(
            self, Clock, recording.CLOCK_TOPIC, self._on_clock, depth=CLOCK_DEPTH)
        for topic, type_name in specs:
            self._subscribe(topic, type_name)
        record_all = self.get_parameter('all').value
        self._record_all = record_all
        if record_all:
            self._discover()
        self.create_timer(POLL_PERIOD, self._discover)
        self.create_timer(self.get_parameter('flush_period').value, self._flush)
        self.get_logger().info(f'recording into {self.bag.directory} '
                               f'({len(specs)} listed topics, all={record_all})')

    def _subscribe(self, topic: str, type_name: str) -> None:
        try:
            msg_type = introspection.import_message_type(type_name)
        except ValueError as error:
            self.get_logger().error(f'not recording {topic}: {error}')
            self._skipped.add(topic)
            return
        self._types[topic] = type_name
        self._recorded[topic] = introspection.AdaptiveSubscription(
            self, msg_type, topic, functools.partial(self._on_message, topic), raw=True,
            on_adapt=lambda qos: self.get_logger().info(
                f'a new publisher on {topic}: subscribed again '
                f'({introspection.qos_text(qos)})'))
        self.get_logger().info(f'subscribed to {topic} [{type_name}] '
                               f'({introspection.qos_text(self._recorded[topic].qos)})')

    def _discover(self) -> None:
        self._clock_source.adapt()
        for topic, types in self.get_topic_names_and_types():
            if topic in self._recorded:
                self._recorded[topic].adapt()
                self._note_publishers(topic)
                continue
            if (not self._record_all or topic in self._skipped
                    or not recording.is_recordable(topic)
                    or self.count_publishers(topic) == 0):
                continue
            if len(types) > 1:
                self.get_logger().warn(f'{topic} has several types {types}; recording {types[0]}')
            self._subscribe(topic, types[0])

    def _note_publishers(self, topic: str) -> None:
        if topic in self._in_bag:
            return
        known = self.count_publishers(topic)
        if known:
            matched = self._recorded[topic].subscription.get_publisher_count()
            self._publishers_seen[topic] = (known, matched)

    def _add_to_bag(self, topic: str) -> None:
        offers = introspection.offered_qos(self.get_publishers_info_by_topic(topic))
        self.bag.add_topic(topic, self._types[topic], qos_yaml(offers))
        self._in_bag.add(topic)

    def _on_message(self, topic: str, data: bytes, info: dict) -> None:
        self._receive(topic, data, info['source_timestamp'])
        self._take_waiting(topic)

    def _take_waiting(self, topic: str) -> None:
        """Take what waits on `topic` (TAKE_BATCH messages at most)."""
        subscription = self._recorded[topic].subscription
        for _ in range(TAKE_BATCH):
            with subscription.handle:
                taken = subscription.handle.take_message(subscription.msg_type, True)
            if taken is None:
                return
            self._receive(topic, taken[0], taken[1]['source_timestamp'])

    def _receive(self, topic: str, data: bytes, sent_ns: int) -> None:
        self.last_receive = time.monotonic()
        if topic not in self._in_bag:
            self._add_to_bag(topic)
        self._write(topic, data, sent_ns)

    def _write(self, topic: str, data: bytes, sent_ns: int) -> None:
        """Write a message now (wall log time: received now), or hold it until its sim log time
        is settled (`release`)."""
        if self._log_time.decide(self._clock_published) == 'wall':
            self.bag.write(topic, data, self._log_time.stamp(self._clock_published), sent_ns)
        else:
            self._held.append((topic, data, sent_ns, time.monotonic()))

    def _clock_published(self) -> bool:
        return self.count_publishers(recording.CLOCK_TOPIC) > 0

    def release(self, everything: bool = False) -> None:
        """Write the held messages whose log time is settled, or held HOLD_MAX s (the /clock
        after them may never come: the run ended), or all of them."""
        if not self._held:
            return
        self._take_clocks()
        oldest = time.monotonic() - HOLD_MAX
        keep = []
        for held in self._held:
            topic, data, sent_ns, taken_at = held
            if everything or taken_at < oldest or self._log_time.settled(sent_ns):
                self.bag.write(topic, data,
                               self._log_time.stamp(self._clock_published, sent_ns), sent_ns)
            else:
                keep.append(held)
        self._held = keep

    def _on_clock(self, msg: Clock, info: dict) -> None:
        self._log_time.on_clock(msg.clock.sec * 1_000_000_000 + msg.clock.nanosec,
                                info['source_timestamp'])

    def _take_clocks(self) -> None:
        handle = self._clock_source.subscription.handle
        while True:
            with handle:
                taken = handle.take_message(Clock, False)
            if taken is None:
                return
            self._on_clock(*taken)

    def read_round(self, executor: SingleThreadedExecutor, timeout: float) -> None:
        """One turn of the executor (waiting up to `timeout` s: a message, a timer, a graph
        event), then every topic's waiting messages taken straight from its subscription."""
        executor.spin_once(timeout_sec=timeout)
        for topic in list(self._recorded):
            self._take_waiting(topic)
        self.release()

    def _flush(self) -> None:
        if not self.bag.closed:
            self.release()
            self.bag.flush()

    def drain(self, executor: SingleThreadedExecutor, abort: threading.Event) -> None:
        """Keep receiving until DRAIN_QUIET s without a message, DRAIN_MAX s or `abort`."""
        start = time.monotonic()
        while not abort.is_set() and rclpy.ok():
            now = time.monotonic()
            if now - max(start, self.last_receive) >= DRAIN_QUIET or now - start >= DRAIN_MAX:
                return
            executor.spin_once(timeout_sec=0.05)

    def close(self) -> None:
        """Add the subscribed topics that stayed silent, then close the bag."""
        if self.bag.closed:
            return
        self.release(everything=True)
        for topic in self._recorded:
            self._note_publishers(topic)
        for topic in self._types:
            if topic not in self._in_bag:
                self._add_to_bag(topic)
                if topic in self._publishers_seen:
                    known, matched = self._publishers_seen[topic]
                    # to stderr with the launcher's prefix: `multilift run` repeats it
                    print(f'warning: recorder: {topic} had {known} publisher(s) ({matched} '
                          'matched by the recorder) but no message of it arrived; the bag has '
                          'the topic without messages', file=sys.stderr, flush=True)
        self.bag.close()
        self.get_logger().info(f'closed {self.bag.directory}: {self.bag.message_count} messages '
                               f'on {len(self.bag.topics)} topics')


def main(args: list[str] | None = None) -> int:
    """Run the recorder until SIGINT/SIGTERM; 0 on a clean close, 2 on bad parameters."""
    use_fastdds_profile()
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    stop, abort = threading.Event(), threading.Event()

    def on_signal(signum: int, frame: object) -> None:
        if not stop.is_set():
            # if the drain or the close hangs (in DDS code, maybe holding the GIL), its stacks
            # reach the log before the launcher's SIGKILL (10 s after its SIGINT)
            faulthandler.dump_traceback_later(HANG_REPORT, file=sys.stderr)
        (abort if stop.is_set() else stop).set()

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    node = None
    try:
        node = RecorderNode()
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not stop.is_set() and rclpy.ok():
            node.read_round(executor, 0.1)
            # a sleep, not stop.wait(): the handler runs in this thread and Event.set takes the
            # lock Event.wait holds at moments, so a signal there hung the recorder until the
            # launcher's SIGKILL (seen in a fresh-clone CI run: the bag had to be rebuilt)
            time.sleep(ROUND_PERIOD)
        node.drain(executor, abort)
    except (BagError, ValueError) as error:  # bad parameters or bag directory
        print(f'recorder_node: {error}', file=sys.stderr)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.close()
            faulthandler.cancel_dump_traceback_later()
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
