"""What the recorder decides without ROS: topic specs, which topics to record, log time base.

Log time (the MCAP `log_time` of each message, [ns]): rosbag2 stamps a message with the time it
was received. Our simulation runs in lockstep on simulated time, usually faster than real time, so
receive *wall* times would compress or stretch the run arbitrarily and differ from run to run. The
recorder therefore stamps each message with the simulated time of the latest `/clock` message
*sent* before it (both carry their sender's source timestamp, wall time on this machine): what
ROS time with `use_sim_time` read in the sender when it published, whenever the recorder gets
around to the message (it reads in rounds). In a lockstep run that is the message's own tick.
`LogTime` decides the base once, for the whole bag, so log times never jump between clocks:

- `sim`: simulated time. Messages sent before the first `/clock` message the recorder knows of
  (latched startup messages) get log time 0, as ROS time with `use_sim_time` is 0 until the
  first `/clock`. A message without a send time gets the latest `/clock` received.
- `wall`: wall time (`time.time_ns()`, since the Unix epoch) at receipt, as rosbag2 does.
- `auto` (default): `sim` if `/clock` has a publisher or has sent a message when the first message
  to record arrives, else `wall`.
"""

from __future__ import annotations

import bisect
import time
from typing import Callable

from multilift_sim.wire.msgdefs import MessageDefinitionError, split_type_name
from multilift_sim.topics import CLOCK

EXCLUDED_TOPICS = frozenset({'/rosout', '/parameter_events'})
CLOCK_TOPIC = CLOCK  # what the recorder's time source follows
TIME_SOURCES = ('auto', 'sim', 'wall')
CLOCK_MEMORY = 10_000  # /clock messages kept for stamping by send time (at least this many)


def parse_topic_spec(spec: str) -> tuple[str, str]:
    """`'/topic|pkg/msg/Type'` -> `('/topic', 'pkg/msg/Type')`, checked."""
    topic, sep, type_name = (part.strip() for part in spec.partition('|'))
    if not sep or not topic.startswith('/') or not type_name:
        raise ValueError(f"topic spec {spec!r} is not of the form '/topic|pkg/msg/Type'")
    try:
        package, namespace, name = split_type_name(type_name)
    except MessageDefinitionError as error:
        raise ValueError(f'topic spec {spec!r}: {error}') from None
    return topic, f'{package}/{namespace}/{name}'


def is_recordable(topic: str) -> bool:
    """Whether `--all` recording takes `topic`: not /rosout, /parameter_events nor hidden."""
    return topic not in EXCLUDED_TOPICS and not any(
        part.startswith('_') for part in topic.split('/'))


class LogTime:
    """The log time base of one bag; see the module docstring.

    `mode` is 'auto', 'sim' or 'wall'; `wall_ns` returns wall time [ns].
    """

    def __init__(self, mode: str = 'auto', wall_ns: Callable[[], int] = time.time_ns) -> None:
        if mode not in TIME_SOURCES:
            raise ValueError(f'time source {mode!r} is not one of {TIME_SOURCES}')
        self.mode = mode
        self.base: str | None = None if mode == 'auto' else mode
        self.clock_ns: int | None = None
        self._wall_ns = wall_ns
        # the /clock messages received, in send order: send times [ns] and simulated times [ns]
        self._sent: list[int] = []
        self._clocks: list[int] = []
        self._forgotten: int | None = None  # the newest clock dropped from the lists

    def on_clock(self, ns: int, sent_ns: int | None = None) -> None:
        """A `/clock` message with simulated time `ns` [ns], sent at `sent_ns` (wall) [ns]."""
        self.clock_ns = ns
        if sent_ns is None:
            return
        if self._sent and sent_ns < self._sent[-1]:  # out of order: keep the lists sorted
            at = bisect.bisect_right(self._sent, sent_ns)
            self._sent.insert(at, sent_ns)
            self._clocks.insert(at, ns)
        else:
            self._sent.append(sent_ns)
            self._clocks.append(ns)
        if len(self._sent) > 2 * CLOCK_MEMORY:
            self._forgotten = self._clocks[-CLOCK_MEMORY - 1]
            del self._sent[:-CLOCK_MEMORY], self._clocks[:-CLOCK_MEMORY]

    def decide(self, clock_published: Callable[[], bool]) -> str:
        """The base of this bag, 'sim' or 'wall', decided at the first message.

        `clock_published()` tells whether /clock has a publisher; asked only in 'auto' mode, for
        the first message.
        """
        if self.base is None:
            self.base = 'sim' if self.clock_ns is not None or clock_published() else 'wall'
        return self.base

    def settled(self, sent_ns: int) -> bool:
        """Whether the sim log time of a message sent at `sent_ns` is final: a /clock sent after
        it was received, so none sent before it is still on its way (one reliable writer
        delivers in order)."""
        return bool(self._sent) and self._sent[-1] > sent_ns

    def stamp(self, clock_published: Callable[[], bool], sent_ns: int | None = None) -> int:
        """Log time [ns] of a message sent at `sent_ns` (wall) [ns], None: arriving now (see
        `decide` for `clock_published`)."""
        if self.decide(clock_published) == 'wall':
            return self._wall_ns()
        if sent_ns is None or not self._sent:
            return self.clock_ns or 0
        at = bisect.bisect_right(self._sent, sent_ns)
        if at:
            return self._clocks[at - 1]
        return self._forgotten or 0
