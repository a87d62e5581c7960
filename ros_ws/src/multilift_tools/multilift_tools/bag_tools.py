"""`multilift bag info|play|reindex DIR`: what `ros2 bag info|play|reindex` do, for our bags.

    bag info DIR                       duration, start and end, message count and type per topic,
                                       size: `ros2 bag info`'s layout (Jazzy)
    bag play DIR [--rate R] [--loop] [--topics T ...] [--start-offset S] [--delay S]
                 [--wait-for-subscribers] [--clock-rate HZ]
                                       publish the recorded messages with their recorded timing
    bag reindex DIR                    rebuild metadata.yaml and the MCAP summary of a bag whose
                                       recorder was killed

Bags are rosbag2 directories with one MCAP file (as `bag.BagWriter` and `ros2 bag record -s mcap`
write them); DIR may also be the `.mcap` file itself for info and play.

info: read from `metadata.yaml` as `ros2 bag info` does (bag size = every file in DIR, as
rcutils_calculate_directory_size); a bag without it (its recorder was killed) is read from the
MCAP's own summary or, in a file left torn, by scanning up to the torn end, with a note on
stderr. Times print in local time (set TZ); topics
are sorted by name (rosbag2's default). A bag without messages prints the epoch as its start.

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

reindex: `ros2 bag reindex` rebuilds metadata.yaml only; this also rewrites the MCAP (every message
of every complete chunk, `bag.recover`) so it has a summary, chunk and message indexes and the
`rosbag2` metadata record again. The file keeps its name; the data after the last complete chunk
(at most the recorder's flush period) is gone either way.

Exit codes: 0 done, 1 the bag cannot be read or played, 2 bad arguments, 130 play interrupted.
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Iterator

import yaml
from mcap.reader import make_reader
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader

from multilift_sim.bag import TORN_RECORD_ERRORS, BagError, recover
from multilift_sim.topics import CLOCK as CLOCK_TOPIC

PLAY_DEPTH = 100  # keep_last depth of the player's publishers (our nodes' PUBLISHER_QOS depth)
ACK_WAIT = 3.0  # [s] longest wait for reliable subscribers to acknowledge the last messages
WAIT_FOR_SUBSCRIBERS_MAX = 30.0  # [s] longest --wait-for-subscribers wait
SLEEP_SLICE = 0.05  # [s] longest sleep between checks of Ctrl-C
_NO_TIME = 2**63 - 1  # rosbag2's starting_time of a bag without messages [ns]


class BagToolError(RuntimeError):
    """A bag cannot be read, repaired or played; the message names the bag and the reason."""


# -- reading -------------------------------------------------------------------------------------
@dataclass
class TopicSummary:
    """One topic of a bag: name, `pkg/msg/Type`, message count and serialization format."""

    name: str
    type: str
    message_count: int
    serialization_format: str = 'cdr'
    offered_qos_profiles: list[dict[str, Any]] = field(default_factory=list)


@dataclass
class BagSummary:
    """What `ros2 bag info` shows; times [ns] since the epoch of the bag's clock."""

    directory: Path
    files: list[str]
    bag_size: int  # [B] every file in the directory
    storage_identifier: str
    ros_distro: str
    starting_time_ns: int
    duration_ns: int
    message_count: int
    topics: list[TopicSummary]
    source: str  # 'metadata.yaml', 'summary' (the MCAP's own) or 'scan' (read to the torn end)

    @property
    def end_time_ns(self) -> int:
        """Log time of the last message [ns]."""
        return self.starting_time_ns + self.duration_ns


def bag_directory(path: str | os.PathLike) -> Path:
    """The bag directory of `path` (a directory, or the `.mcap` file in one)."""
    path = Path(path)
    if path.is_file() and path.suffix == '.mcap':
        return path.parent
    if not path.is_dir():
        raise BagToolError(f'{path}: no such bag directory')
    return path


def mcap_file(directory: Path, metadata: dict[str, Any] | None = None) -> Path:
    """The bag's one MCAP file: the first of metadata.yaml's files, else the one `*.mcap`."""
    if metadata and metadata.get('relative_file_paths'):
        return directory / metadata['relative_file_paths'][0]
    files = sorted(directory.glob('*.mcap'))
    if len(files) != 1:
        raise BagToolError(f'{directory}: expected one .mcap file, found '
                           f'{len(files) or "none"} ({", ".join(f.name for f in files)})')
    return files[0]


def read_metadata(directory: Path) -> dict[str, Any] | None:
    """`rosbag2_bagfile_information` of DIR/metadata.yaml, or None if there is none."""
    path = directory / 'metadata.yaml'
    if not path.is_file():
        return None
    try:
        data = yaml.safe_load(path.read_text(encoding='utf-8'))
        return data['rosbag2_bagfile_information']
    except (yaml.YAMLError, TypeError, KeyError) as error:
        raise BagToolError(f'{path}: not a rosbag2 metadata file ({error})') from None


def _directory_size(directory: Path) -> int:
    return sum(p.stat().st_size for p in directory.iterdir() if p.is_file())


def _from_metadata(directory: Path, info: dict[str, Any]) -> BagSummary:
    topics = []
    for entry in info.get('topics_with_message_count') or []:
        meta = entry['topic_metadata']
        profiles = meta.get('offered_qos_profiles') or []
        if isinstance(profiles, str):  # metadata version < 9 kept a YAML string
            profiles = yaml.safe_load(profiles) or []
        topics.append(TopicSummary(meta['name'], meta['type'], int(entry['message_count']),
                                   meta.get('serialization_format', 'cdr'), profiles))
    return BagSummary(
        directory=directory, files=list(info.get('relative_file_paths') or []),
        bag_size=_directory_size(directory),
        storage_identifier=str(info.get('storage_identifier', '')),
        ros_distro=str(info.get('ros_distro') or ''),
        starting_time_ns=int(info['starting_time']['nanoseconds_since_epoch']),
        duration_ns=int(info['duration']['nanoseconds']),
        message_count=int(info['message_count']), topics=topics, source='metadata.yaml')


def _qos_profiles(channel: Channel) -> list[dict[str, Any]]:
    text = channel.metadata.get('offered_qos_profiles', '')
    try:
        data = yaml.safe_load(text) if text.strip() else []
    except yaml.YAMLError:
        return []
    return data if isinstance(data, list) else []


def _from_mcap(directory: Path, path: Path) -> BagSummary:
    """Summary of an MCAP: its summary section if it has one, else a scan to the torn end."""
    with open(path, 'rb') as stream:
        try:
            summary = make_reader(stream).get_summary()
        except TORN_RECORD_ERRORS:
            summary = None
        if summary is not None and summary.statistics is not None:
            stats = summary.statistics
            schemas = summary.schemas
            channels = summary.channels.values()
            counts = dict(stats.channel_message_counts)
            first, last, total, source = (stats.message_start_time, stats.message_end_time,
                                          stats.message_count, 'summary')
        else:
            stream.seek(0)
            schemas, found, counts = {}, {}, {}
            first, last, total, source = _NO_TIME, 0, 0, 'scan'
            try:
                for record in StreamReader(stream, validate_crcs=True).records:
                    if isinstance(record, Schema):
                        schemas[record.id] = record
                    elif isinstance(record, Channel):
                        found[record.id] = record
                    elif isinstance(record, Message):
                        counts[record.channel_id] = counts.get(record.channel_id, 0) + 1
                        first, last = min(first, record.log_time), max(last, record.log_time)
                        total += 1
            except TORN_RECORD_ERRORS:
                pass  # the torn tail of a file whose writer was killed
            channels = found.values()
    topics = [TopicSummary(c.topic, schemas[c.schema_id].name if c.schema_id in schemas else '',
                           counts.get(c.id, 0), c.message_encoding, _qos_profiles(c))
              for c in channels]
    if total == 0:
        first, last = _NO_TIME, _NO_TIME
    return BagSummary(directory=directory, files=[path.name], bag_size=_directory_size(directory),
                      storage_identifier='mcap', ros_distro='', starting_time_ns=first,
                      duration_ns=last - first, message_count=total, topics=topics,
                      source=source)


def read_summary(path: str | os.PathLike) -> BagSummary:
    """What `bag info` prints about the bag at `path`: metadata.yaml, else the MCAP itself."""
    directory = bag_directory(path)
    info = read_metadata(directory)
    if info is not None:
        return _from_metadata(directory, info)
    return _from_mcap(directory, mcap_file(directory))


# -- info ----------------------------------------------------------------------------------------
def _format_duration(ns: int) -> tuple[str, str, str]:
    """(date, time of day, seconds) of `ns` [ns] as rosbag2's format_duration (local time)."""
    seconds, fraction = divmod(ns, 1_000_000_000)
    local = time.localtime(seconds)
    date = time.strftime('%b ', local) + f'{local.tm_mday:2d}' + time.strftime(' %Y', local)
    return date, time.strftime('%H:%M:%S', local) + f'.{fraction:09d}', f'{seconds}.{fraction:09d}'


def _format_time_point(ns: int) -> str:
    date, clock, seconds = _format_duration(ns)
    return f'{date} {clock} ({seconds})'


def format_file_size(size: int) -> str:
    """`size` [B] as rosbag2 prints it: B, KiB, MiB, GiB, TiB; one decimal above bytes."""
    value, index = float(size), 0
    units = ('B', 'KiB', 'MiB', 'GiB', 'TiB')
    while value >= 1024 and index < 4:
        value /= 1024
        index += 1
    return f'{value:.{0 if index == 0 else 1}f} {units[index]}'


def format_info(summary: BagSummary) -> str:
    """The text `ros2 bag info` (Jazzy, rosbag2_py format_bag_meta_data) prints for `summary`,
    including its leading empty line and final newline."""
    pad = ' ' * 19
    start = 0 if summary.message_count == 0 else summary.starting_time_ns
    duration = 0 if summary.message_count == 0 else summary.duration_ns
    lines = ['', 'Files:             ' + (summary.files[0] if summary.files else '')]
    lines += [pad + name for name in summary.files[1:]]
    lines += [f'Bag size:          {format_file_size(summary.bag_size)}',
              f'Storage id:        {summary.storage_identifier}',
              f'ROS Distro:        {summary.ros_distro or "unknown"}',
              f'Duration:          {_format_duration(duration)[2]}s',
              f'Start:             {_format_time_point(start)}',
              f'End:               {_format_time_point(start + duration)}',
              f'Messages:          {summary.message_count}']
    topics = sorted(summary.topics, key=lambda t: t.name)
    rows = [f'Topic: {t.name} | Type: {t.type} | Count: {t.message_count} | '
            f'Serialization Format: {t.serialization_format}' for t in topics]
    lines.append('Topic information: ' + (rows[0] if rows else ''))
    lines += [pad + row for row in rows[1:]]
    lines += ['Service:           0', 'Service information: ']
    return '\n'.join(lines) + '\n'


def _info(args: argparse.Namespace) -> int:
    summary = read_summary(args.bag)
    if summary.source != 'metadata.yaml':
        how = 'its summary' if summary.source == 'summary' else 'scanned to its torn end'
        print(f'note: {summary.directory} has no metadata.yaml (was its recorder killed?); read '
              f'from the MCAP file ({how}); `multilift bag reindex {summary.directory}` repairs '
              'the bag', file=sys.stderr)
    print(format_info(summary))
    return 0


# -- reindex -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ReindexResult:
    """What `reindex` did: messages kept, file sizes before and after [B], time range [ns]."""

    mcap_path: Path
    messages: int
    size_before: int
    size_after: int
    starting_time_ns: int
    duration_ns: int


def reindex(path: str | os.PathLike) -> ReindexResult:
    """Rewrite the bag at `path` in place from what its MCAP holds: MCAP summary and indexes,
    `rosbag2` metadata record and metadata.yaml (see the module docstring).

    The new MCAP is written beside the bag and renamed over the old one, then metadata.yaml is
    replaced, so an interrupted reindex leaves either bag, never half of one. The custom_data of
    an existing metadata.yaml is kept.
    """
    directory = bag_directory(path)
    info = read_metadata(directory)
    source = mcap_file(directory, info)
    if not source.is_file():
        raise BagToolError(f'{directory}: the bag file {source.name} is missing')
    custom = dict((info or {}).get('custom_data') or {})
    work = Path(tempfile.mkdtemp(prefix=f'.{directory.name}.reindex-', dir=directory.parent))
    try:
        out = work / 'bag'
        try:
            count = recover(directory, out, file_name=source.name, custom_data=custom or None)
        except BagError as error:
            raise BagToolError(f'{directory}: cannot reindex: {error}') from None
        size_before = source.stat().st_size
        os.replace(out / source.name, source)
        os.replace(out / 'metadata.yaml', directory / 'metadata.yaml')
    finally:
        shutil.rmtree(work, ignore_errors=True)
    summary = read_summary(directory)
    return ReindexResult(source, count, size_before, source.stat().st_size,
                         summary.starting_time_ns, summary.duration_ns)


def _reindex(args: argparse.Namespace) -> int:
    result = reindex(args.bag)
    span = (f'{result.starting_time_ns * 1e-9:.3f} .. '
            f'{(result.starting_time_ns + result.duration_ns) * 1e-9:.3f} s'
            if result.messages else 'no messages')
    print(f'reindexed {result.mcap_path}: {result.messages} messages ({span}), '
          f'{format_file_size(result.size_before)} -> {format_file_size(result.size_after)}; '
          f'metadata.yaml written')
    return 0


# -- play ----------------------------------------------------------------------------------------
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
        while True:
            lonely = [name for name, pub in self.publishers.items()
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


def _play(args: argparse.Namespace) -> int:
    if not args.rate > 0:
        print(f'bag play: --rate must be > 0, got {args.rate:g}', file=sys.stderr)
        return 2
    if args.start_offset < 0 or args.delay < 0 or args.clock_rate < 0:
        print('bag play: --start-offset, --delay and --clock-rate must be >= 0', file=sys.stderr)
        return 2
    import rclpy
    from rclpy.signals import SignalHandlerOptions
    options = PlayOptions(rate=args.rate, loop=args.loop,
                          topics=tuple(args.topics) if args.topics else None,
                          start_offset=args.start_offset, delay=args.delay,
                          wait_for_subscribers=args.wait_for_subscribers,
                          clock_rate=args.clock_rate)
    stop = _Stop()
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    player = BagPlayer(args.bag, options, stop,
                       log=lambda text: print(text, file=sys.stderr, flush=True))
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    try:
        finished = player.run()
    finally:
        player.close()
        rclpy.try_shutdown()
    print(f'bag play: {player.published} messages published'
          + ('' if finished else ' (interrupted)'), file=sys.stderr)
    return 0 if finished else 130


# -- command line --------------------------------------------------------------------------------
def build_parser() -> argparse.ArgumentParser:
    """The `multilift bag` argument parser."""
    parser = argparse.ArgumentParser(prog='multilift bag', description=__doc__.split('\n')[0],
                                     epilog='See the bag_tools module docstring for details.')
    verbs = parser.add_subparsers(dest='verb', required=True)
    info = verbs.add_parser('info', help='print a summary of a bag, as ros2 bag info')
    info.add_argument('bag', help='bag directory (or its .mcap file)')
    play = verbs.add_parser('play', help='publish a bag with its recorded timing')
    play.add_argument('bag', help='bag directory (or its .mcap file)')
    play.add_argument('-r', '--rate', type=float, default=1.0,
                      help='playback speed factor (default 1)')
    play.add_argument('-l', '--loop', action='store_true', help='start over at the end')
    play.add_argument('--topics', nargs='+', metavar='TOPIC', help='play only these topics')
    play.add_argument('--start-offset', type=float, default=0.0, metavar='S',
                      help='skip the first S seconds of the bag')
    play.add_argument('-d', '--delay', type=float, default=0.0, metavar='S',
                      help='wait S wall seconds after creating the publishers')
    play.add_argument('--wait-for-subscribers', action='store_true',
                      help='wait (up to 30 s) until every topic has a subscriber')
    play.add_argument('--clock-rate', type=float, default=100.0, metavar='HZ',
                      help='rate of the generated /clock when /clock is not played from the '
                           'bag (default 100; 0: none)')
    reindex_parser = verbs.add_parser(
        'reindex', help='rebuild metadata.yaml and the MCAP summary of a killed recording')
    reindex_parser.add_argument('bag', help='bag directory')
    return parser


def bag_main(argv: list[str]) -> int:
    """`bag info|play|reindex ...` (argv without the word `bag`); returns the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    try:
        return {'info': _info, 'play': _play, 'reindex': _reindex}[args.verb](args)
    except BagToolError as error:
        print(f'bag {args.verb}: {error}', file=sys.stderr)
        return 1


if __name__ == '__main__':
    sys.exit(bag_main(sys.argv[1:]))
