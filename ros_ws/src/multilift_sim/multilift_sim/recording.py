"""What the recorder decides without ROS: topic specs, which topics to record, log time base.

Log time (the MCAP `log_time` of each message, [ns]): rosbag2 stamps a message with the time it
was received. Our simulation runs in lockstep on simulated time, usually faster than real time, so
receive *wall* times would compress or stretch the run arbitrarily and differ from run to run. The
recorder therefore stamps each message with the simulated time of the latest `/clock` message it
has received, which is deterministic up to one simulation step (the exact time of a message is its
`header.stamp`). `LogTime` decides the base once, for the whole bag, so log times never jump
between clocks:

- `sim`: simulated time. Messages that arrive before the first `/clock` message (latched startup
  messages) get log time 0, as ROS time with `use_sim_time` is 0 until the first `/clock`.
- `wall`: wall time (`time.time_ns()`, since the Unix epoch) at receipt, as rosbag2 does.
- `auto` (default): `sim` if `/clock` has a publisher or has sent a message when the first message
  to record arrives, else `wall`.
"""

from __future__ import annotations

import time
from typing import Callable

from multilift_sim.msgdefs import MessageDefinitionError, split_type_name
from multilift_sim.topics import CLOCK

EXCLUDED_TOPICS = frozenset({'/rosout', '/parameter_events'})
CLOCK_TOPIC = CLOCK  # what the recorder's time source follows
TIME_SOURCES = ('auto', 'sim', 'wall')


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

    def on_clock(self, ns: int) -> None:
        """A `/clock` message with simulated time `ns` [ns] arrived."""
        self.clock_ns = ns

    def stamp(self, clock_published: Callable[[], bool]) -> int:
        """Log time [ns] of a message arriving now.

        `clock_published()` tells whether /clock has a publisher; asked only in 'auto' mode, for
        the first message.
        """
        if self.base is None:
            self.base = 'sim' if self.clock_ns is not None or clock_published() else 'wall'
        if self.base == 'wall':
            return self._wall_ns()
        return self.clock_ns or 0
