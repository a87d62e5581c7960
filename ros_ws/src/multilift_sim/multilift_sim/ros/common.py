"""What every multilift node shares: QoS, time stamps, message <-> model conversions and a
shutdown-safe `run_node` (topic names: multilift_sim.topics). This is ROS adapter code; the
physics never sees it.
"""
from __future__ import annotations

import faulthandler
import json
import os
import signal
import sys
import threading
import time
import traceback
from pathlib import Path
from typing import Callable, Iterable, NoReturn, Sequence

import numpy as np
import rclpy
from builtin_interfaces.msg import Time
from nav_msgs.msg import Odometry
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

from multilift_sim.kinematics import (euler_from_quaternion, quaternion_from_euler,  # noqa: F401
                                      rotation_matrix)

from multilift_sim.wire import msgvalues
from multilift_sim.ros.fastdds import use_fastdds_profile
from multilift_sim.wire.msgvalues import WORLD_FRAME, uav_frame  # noqa: F401

# Publishers keep their last messages for late joiners and our subscribers ask for them: a
# controller or recorder whose subscription matched a moment after t = 0 was published still
# gets it (discovery of each endpoint pair is independent; the lockstep would otherwise wait for
# an answer to a state the controller never saw).
PUBLISHER_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1000,
                           reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)
SUBSCRIBER_QOS = PUBLISHER_QOS


class StartupError(RuntimeError):
    """The graph did not come together in time; the message says what is missing."""


def stamp_from_ns(t_ns: int) -> Time:
    sec, nanosec = msgvalues.stamp(t_ns)
    return Time(sec=sec, nanosec=nanosec)


def ns_from_stamp(stamp: Time) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def fill_odometry(msg: Odometry, t_ns: int, child_frame: str, position: np.ndarray,
                  velocity_world: np.ndarray, orientation: np.ndarray | None,
                  body_velocity: np.ndarray | None, body_rates: np.ndarray | None) -> Odometry:
    """Odometry in `world`; twist in the child frame as nav_msgs/Odometry specifies (the
    values of msgvalues.odometry, which the headless bag packs too)."""
    msg.header.stamp = stamp_from_ns(t_ns)
    msg.header.frame_id = WORLD_FRAME
    msg.child_frame_id = child_frame
    position, orientation, linear, angular = msgvalues.odometry(
        position, velocity_world, orientation, body_velocity, body_rates)
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    v, w = msg.twist.twist.linear, msg.twist.twist.angular
    p.x, p.y, p.z = position
    q.x, q.y, q.z, q.w = orientation
    v.x, v.y, v.z = linear
    w.x, w.y, w.z = angular
    return msg


def odometry_arrays(msg: Odometry) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(position, velocity, euler, body_rates) of an Odometry: world position and velocity,
    ZYX Euler angles, body (FLU) angular velocity; the twist's linear part is rotated from the
    body frame to world."""
    p = msg.pose.pose.position
    q = msg.pose.pose.orientation
    euler = euler_from_quaternion((q.x, q.y, q.z, q.w))
    v = msg.twist.twist.linear
    w = msg.twist.twist.angular
    velocity = rotation_matrix(euler) @ np.array([v.x, v.y, v.z])
    return (np.array([p.x, p.y, p.z]), velocity, euler, np.array([w.x, w.y, w.z]))


def write_summary(directory: str, name: str, data: dict) -> None:
    """Leave this node's end-of-run figures as `<directory>/<name>.json` (no-op without one)."""
    if directory:
        path = Path(directory)
        path.mkdir(parents=True, exist_ok=True)
        (path / f'{name}.json').write_text(json.dumps(data, indent=1, sort_keys=True))


RECORDER_NODE = 'recorder'
STARTUP_TIMEOUT = 60.0  # wall seconds a node waits for the graph to come together [s]


def recorder_missing(node: Node, publishers) -> str | None:
    """The first of our publishers' topics the recorder does not subscribe to yet, or None.

    Counting subscriptions is not enough: a controller subscribing to the same topic would
    satisfy the count while the recorder is still starting, and the start of the run would be
    missing from the bag. So the recorder's own endpoint is looked for by node name.
    """
    for pub in publishers:
        infos = node.get_subscriptions_info_by_topic(pub.topic_name)
        if not any(info.node_name == RECORDER_NODE for info in infos):
            return f'the recorder to subscribe to {pub.topic_name}'
    return None


def recorder_hears(node: Node, topic: str) -> bool:
    """Whether the recorder subscribes to `topic` with a QoS that every publisher of it known
    now matches (a user's node publishing with the defaults included)."""
    from multilift_sim.ros.introspection import compatible
    readers = [i.qos_profile for i in node.get_subscriptions_info_by_topic(topic)
               if i.node_name == RECORDER_NODE]
    writers = [i.qos_profile for i in node.get_publishers_info_by_topic(topic)]
    return bool(readers) and all(any(compatible(w, r) for r in readers) for w in writers)


def controller_peers_missing(node: Node, command_publisher, record: bool) -> str | None:
    """What a controller node waits for before it answers: the simulator subscribed to its rotor
    commands and, when recording, the recorder subscribed to every topic it publishes."""
    if command_publisher.get_subscription_count() < 1:
        return f'the simulator to subscribe to {command_publisher.topic_name}'
    if not record:
        return None
    own = [p for p in node.publishers if p.topic_name not in ('/rosout', '/parameter_events')]
    return recorder_missing(node, own)


def serve_controllers(nodes: Sequence[Node], summary: Callable[[Node], tuple[str, dict]]) -> None:
    """Controller nodes' life, one node or several composed in one executor: wait for the
    peers of every one (`node.missing_peers`), answer states until stopped, then leave each
    node's `summary(node)` (name, figures) as `<summary_dir>/<name>.json`.

    No state is answered before: a controller answering while its participant had not yet
    discovered the recorder sent what the recorder never got (seen: a composed 3 s run whose
    bag had no controller message, the recorder found only as the run ended). The states
    that arrive meanwhile wait in the subscriptions (reliable, 1000 deep); the simulator waits
    `command_timeout` for the first answers."""
    def missing() -> str | None:
        for node in nodes:
            what = node.missing_peers()
            if what is not None:
                return what if len(nodes) == 1 else f'{what} ({node.get_name()})'
        return None

    wait_until(nodes[0], missing, STARTUP_TIMEOUT, spin=False)
    try:
        spin(nodes[0])
    finally:
        for node in nodes:
            write_summary(node.summary_dir, *summary(node))


def wait_until(node: Node, ready: Callable[[], str | None], timeout: float,
               spin: bool = True) -> None:
    """Spin until `ready()` returns None (it returns what is still missing), or raise. With
    `spin` False the node's callbacks wait too (what arrives waits in its subscriptions): the
    graph `ready()` reads is kept by rmw's own thread."""
    deadline = time.monotonic() + timeout
    missing = ready()
    while missing is not None:
        if time.monotonic() > deadline:
            raise StartupError(f'{node.get_name()}: gave up after {timeout:.0f} s waiting for '
                               f'{missing}')
        if spin:
            node.executor.spin_once(timeout_sec=0.05)
        else:
            time.sleep(0.05)
        missing = ready()


class Fatal(Exception):
    """A node must stop; the message is printed as one line and the exit code is 1."""


def make_executor():
    """rclpy's EventsExecutor (about 3x the message rate of the default executor on these
    machines), or the default one where it is missing (MULTILIFT_EXECUTOR=default forces it)."""
    if os.environ.get('MULTILIFT_EXECUTOR', 'events') == 'events':
        try:
            from rclpy.experimental import EventsExecutor
            return EventsExecutor()
        except ImportError:
            pass
    return SingleThreadedExecutor()


def spin(node: Node) -> None:
    """Spin in short slices so SIGINT and SIGTERM (raised as KeyboardInterrupt by `run_node`)
    are seen promptly whatever the executor."""
    while rclpy.ok():
        node.executor.spin_once(timeout_sec=0.1)


# How long a node waits for its messages to be acknowledged before it exits [s]: after a
# normal end the recorder may lag seconds behind on a loaded machine; when the run is being
# stopped (a peer died, Ctrl-C) a dead reader never acknowledges, so the wait is kept short.
FLUSH_TIMEOUT = 5.0
FLUSH_TIMEOUT_STOPPING = 1.5


# Discovery runs on each side of a writer-reader pair on its own: a reliable writer that has
# matched a reader sends to it, but a reader that has not yet matched the writer drops what it
# hears and asks again (from the writer's history) only once it has. A run that ends first
# loses the topic from the bag: seen once here, a 1 s run whose bag had none of the leader's
# rotor commands. When recording, a node therefore waits after its first messages until every
# subscriber acknowledged them (this long at most, then a warning names the topics).
FIRST_ACK_TIMEOUT = 2.0  # [s]


class RawPublishers:
    """A node's publishers by topic, for messages that are already CDR bytes
    (`multilift_sim.wire.tick_messages.Message`: (topic, bytes)): sent as they are.

    `confirm_first` [s]: after the first `send`, wait up to this long until every subscriber of
    every topic acknowledged it (FIRST_ACK_TIMEOUT when recording; 0: no wait)."""

    def __init__(self, *publishers, confirm_first: float = 0.0) -> None:
        self._by_topic = {pub.topic_name: pub for pub in publishers}
        self._confirm_within = confirm_first

    def send(self, messages: Iterable[tuple[str, bytes]]) -> None:
        """Publish each (topic, bytes) of `messages`, in order."""
        for topic, data in messages:
            self._by_topic[topic].publish(data)
        if self._confirm_within > 0.0:
            self._confirm()

    def _confirm(self) -> None:
        within, self._confirm_within = self._confirm_within, 0.0
        unconfirmed = wait_for_acknowledgements(self._by_topic.values(), within)
        if unconfirmed:
            print(f'warning: {", ".join(unconfirmed)}: not acknowledged by every subscriber '
                  f'{within:g} s after the first message (a reader that has not discovered '
                  'this node yet, such as the recorder, may miss the start of the run)',
                  file=sys.stderr, flush=True)


def wait_for_acknowledgements(publishers: Iterable, timeout: float) -> list[str]:
    """Wait up to `timeout` [s] in all until every subscriber of each publisher acknowledged
    what it sent; the topics still unacknowledged (the publishers the deadline left no time
    for included; none once the context is shut down: nothing to wait for then)."""
    deadline = time.monotonic() + timeout
    unacknowledged = []
    for pub in list(publishers):
        left = deadline - time.monotonic()
        try:
            if left <= 0 or not pub.wait_for_all_acked(Duration(seconds=left)):
                unacknowledged.append(pub.topic_name)
        except Exception:  # noqa: BLE001 - a context already shut down
            return []
    return unacknowledged


def _interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


# How long a node's teardown (executor, node, rclpy context) may take beyond the flush of its
# publishers [s]. Seen in CI: a follower whose run had finished, its summary written and its
# publishers flushed, never returned from the DDS teardown and ignored SIGINT and SIGTERM (a
# thread blocked in C code never runs Python's signal handlers) until the launcher's SIGKILL.
TEARDOWN_LIMIT = 5.0


class TeardownGuard:
    """Bounds a node's teardown: if it has not finished `limit` s after `arm`, the node's
    Python stacks go to stderr (its log) with a warning, and the process exits with the code it
    was going to return: the flush that starts the teardown is itself bounded, so what the node
    had to deliver was delivered (or given up on) by then.

    Two watchdogs, because a hang may or may not hold the GIL: a Python thread that can exit
    with the node's own code, and faulthandler's C thread (`limit` + 3 s, exit code 1) that
    runs even when the GIL is never released."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._done = threading.Event()

    def arm(self, code: int, limit: float) -> None:
        def watch() -> None:
            if self._done.wait(limit):
                return
            print(f'warning: {self.name}: teardown still running after {limit:g} s '
                  f'(exiting with {code}); where it hangs:', file=sys.stderr, flush=True)
            faulthandler.dump_traceback(file=sys.stderr, all_threads=True)
            sys.stderr.flush()
            os._exit(code)

        threading.Thread(target=watch, name='teardown-guard', daemon=True).start()
        faulthandler.dump_traceback_later(limit + 3.0, exit=True, file=sys.stderr)

    def disarm(self) -> None:
        self._done.set()
        faulthandler.cancel_dump_traceback_later()


def run_node(make_node: Callable[[], Node], body: Callable[[Node], None] | None = None,
             args: list[str] | None = None) -> NoReturn:
    """`run_nodes` of one node: `body(node)`, or the node spun."""
    run_nodes(lambda: [make_node()], None if body is None else lambda nodes: body(nodes[0]),
              args)


def run_nodes(make_nodes: Callable[[], Iterable[Node]],
              body: Callable[[list[Node]], None] | None = None,
              args: list[str] | None = None, name: str | None = None) -> NoReturn:
    """Create, run and shut down one node, or several composed in one process (one rclpy
    context, one executor), safely (SIGINT, SIGTERM, external shutdown), then end the process:
    a node process's entry point.

    Each node `make_nodes()` yields is added to one executor as it comes (`node.executor`),
    so a failure half-way tears down those made before it. `body(nodes)` runs the nodes' own
    loop if they have one; otherwise they are spun. Once every node's publishers are flushed,
    the teardown runs under a `TeardownGuard` (named `name`, by default the first node's), and
    the process ends with `os._exit`: the interpreter's finalization and the DDS library's
    static destructors, which would run in threads no watchdog reaches, have nothing left to do.
    Errors of kind Fatal, StartupError or ScenarioError print one line; exit code 1 (2 for a
    ScenarioError).
    """
    from multilift_sim.scenario import ScenarioError
    use_fastdds_profile()
    # our own SIGINT/SIGTERM handling: rclpy's would shut the context down at once, before the
    # publishers are flushed
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    signal.signal(signal.SIGINT, _interrupt)
    signal.signal(signal.SIGTERM, _interrupt)
    nodes: list[Node] = []
    code = 0
    flush_timeout = FLUSH_TIMEOUT
    executor = make_executor()
    guard = TeardownGuard(name or sys.argv[0].rsplit('/', 1)[-1] or 'node')
    try:
        for node in make_nodes():
            nodes.append(node)
            executor.add_node(node)
        if name is None:
            guard.name = nodes[0].get_name()
        if body is None:
            spin(nodes[0])
        else:
            body(nodes)
    except (KeyboardInterrupt, ExternalShutdownException):
        flush_timeout = FLUSH_TIMEOUT_STOPPING
    except (Fatal, StartupError, ScenarioError) as exc:
        print(f'error: {exc}', file=sys.stderr, flush=True)
        code = 1 if not isinstance(exc, ScenarioError) else 2
    except Exception as exc:  # noqa: BLE001 - a bug: its traceback, exit code 1, same teardown
        traceback.print_exc()
        # an `error:` line too, so a teardown cut short afterwards is not taken for a node that
        # had done its work (multilift_tools.launcher.Child.teardown_cut_short)
        print(f'error: {type(exc).__name__}: {exc}', file=sys.stderr, flush=True)
        code = 1
    finally:
        # a further SIGINT/SIGTERM would only break the teardown off half-way; the guard bounds it
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        guard.arm(code, flush_timeout + TEARDOWN_LIMIT)
        # every subscriber acknowledges the nodes' messages first: a reliable writer destroyed
        # before takes its unacknowledged history with it (a recorder lagging behind would lose
        # the last messages of the run)
        wait_for_acknowledgements([p for node in nodes for p in node.publishers], flush_timeout)
        # the executor lets go of the nodes' callbacks before the nodes' entities are destroyed
        try:
            executor.shutdown(timeout_sec=1.0)
        except Exception:  # noqa: BLE001 - shutting down anyway
            pass
        for node in nodes:
            try:
                node.destroy_node()
            except Exception:  # noqa: BLE001 - shutting down anyway
                pass
        rclpy.try_shutdown()
        del executor, nodes
        guard.disarm()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
