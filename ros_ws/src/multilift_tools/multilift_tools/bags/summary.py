"""A bag's summary (`read_summary`) and its text as `ros2 bag info` prints it (`format_info`).

info: read from `metadata.yaml` as `ros2 bag info` does (bag size = every file in DIR, as
rcutils_calculate_directory_size); a bag without it (its recorder was killed) is read from the
MCAP's own summary or, in a file left torn, by scanning up to the torn end, with a note on
stderr. Times print in local time (set TZ); topics
are sorted by name (rosbag2's default). A bag without messages prints the epoch as its start.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from mcap.reader import make_reader
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader

from multilift_sim.bag import TORN_RECORD_ERRORS

_NO_TIME = 2**63 - 1  # rosbag2's starting_time of a bag without messages [ns]


class BagToolError(RuntimeError):
    """A bag cannot be read, repaired or played; the message names the bag and the reason."""


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
