"""rosbag2 (Jazzy) bag directories with MCAP storage, written without rclpy or rosbag2.

A bag is a directory `DIR/` holding `DIR/<name>_0.mcap` (`<name>` = the directory's base name)
and, once the bag is closed, `DIR/metadata.yaml` (rosbag2 metadata version 9), laid out as
`ros2 bag record -s mcap` writes them:

- MCAP header profile `ros2`; one schema per type, named `pkg/msg/Type`, encoding `ros2msg`,
  data = the full message definition (`msgdefs.message_definition`); one channel per topic,
  message encoding `cdr`, channel metadata `offered_qos_profiles` (YAML string) and
  `topic_type_hash`; a metadata record `rosbag2` with `serialized_metadata` at close.
- Messages go into compressed chunks (zstd by default, lz4 or none on request) of about
  `chunk_size` bytes [B]. The file is written without a user-space buffer, so every finished chunk
  is on disk at once: if the process dies, the MCAP stays readable up to the last finished chunk
  (readers fall back to scanning a file without summary). `flush()` finishes the chunk in progress.
- Compression is MCAP chunk compression (a storage option, as rosbag2's `zstd_fast` preset), so
  `metadata.yaml` keeps `compression_format: ""`, `compression_mode: ""` as rosbag2 writes then.

Times are nanoseconds [ns] on whatever clock the caller stamps `log_time_ns` with.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from mcap.exceptions import McapError
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

from multilift_sim.bag import metadata_yaml
from multilift_sim.bag.mcap_records import DirectFile, MessageAppender
from multilift_sim.wire import msgdefs

try:
    from zstandard import ZstdError
except ImportError:  # no zstd support installed: mcap raises UnsupportedCompressionError
    ZstdError = McapError

DEFAULT_CHUNK_SIZE = 256 * 1024  # [B] uncompressed
METADATA_VERSION = 9
ROS_DISTRO = 'jazzy'
STORAGE_IDENTIFIER = 'mcap'
MESSAGE_ENCODING = 'cdr'
LIBRARY = f'multilift bag.py ({LIBRARY_IDENTIFIER})'
_NO_TIME = 2**63 - 1  # rosbag2's starting_time of a bag without messages [ns]
# What reading the torn end of an MCAP file can raise: a record cut short (EndOfFile, struct),
# a bad CRC, or garbage where a record should start (e.g. blocks a crash left zero-filled).
TORN_RECORD_ERRORS = (McapError, struct.error, EOFError, ValueError, ZstdError)
_COMPRESSION = {'zstd': CompressionType.ZSTD, 'lz4': CompressionType.LZ4,
                'none': CompressionType.NONE}


class BagError(RuntimeError):
    """A bag could not be created or written; the message says which bag and why."""


@dataclass
class _Topic:
    name: str
    type_name: str
    qos_profiles: list[dict[str, Any]]
    type_description_hash: str
    channel_id: int
    message_count: int = 0

    def metadata(self) -> dict[str, Any]:
        return {
            'topic_metadata': {
                'name': self.name,
                'type': self.type_name,
                'serialization_format': MESSAGE_ENCODING,
                'offered_qos_profiles': self.qos_profiles,
                'type_description_hash': self.type_description_hash,
            },
            'message_count': self.message_count,
        }


@dataclass(frozen=True)
class Column:
    """One topic's messages in a block of K ticks (`BagWriter.write_block`): at most one a
    tick, all of one size."""
    topic: str
    data: np.ndarray                 # (m, size) uint8: each message's CDR bytes
    ticks: np.ndarray | None = None  # (m,) increasing: the ticks that have one; None: all K


class BagWriter:
    """Writes one rosbag2 bag directory with MCAP storage (see the module docstring).

    `directory` must not exist or be empty, as `ros2 bag record` demands. `compression` is
    'zstd', 'lz4' or 'none'; `chunk_size` [B] the uncompressed size at which a chunk is finished;
    `custom_data` string pairs for `metadata.yaml`'s `custom_data`; `file_name` the MCAP file's
    name (default `<directory name>_0.mcap`, as rosbag2 names it).
    """

    def __init__(self, directory: str | os.PathLike, *, compression: str = 'zstd',
                 chunk_size: int = DEFAULT_CHUNK_SIZE,
                 custom_data: dict[str, str] | None = None,
                 file_name: str | None = None) -> None:
        self.directory = Path(directory)
        if self.directory.exists() and (
                not self.directory.is_dir() or any(self.directory.iterdir())):
            raise BagError(f"bag directory '{self.directory}' already exists and is not empty; "
                           'give a new directory (ros2 bag record refuses it too)')
        if compression not in _COMPRESSION:
            raise BagError(f'compression {compression!r} is not one of {sorted(_COMPRESSION)}')
        if chunk_size <= 0:
            raise BagError(f'chunk_size must be positive, got {chunk_size} B')
        self.file_name = file_name or f'{self.directory.resolve().name}_0.mcap'
        if Path(self.file_name).name != self.file_name or not self.file_name.endswith('.mcap'):
            raise BagError(f'file_name {self.file_name!r} must be a plain name ending in .mcap')
        self.directory.mkdir(parents=True, exist_ok=True)
        self.mcap_path = self.directory / self.file_name
        self.custom_data = dict(custom_data or {})
        self._file = DirectFile(self.mcap_path)
        self._writer = Writer(self._file, chunk_size=chunk_size,
                              compression=_COMPRESSION[compression], enable_crcs=True)
        self._writer.start(profile='ros2', library=LIBRARY)
        self._messages = MessageAppender(self._writer)
        self._topics: dict[str, _Topic] = {}
        self._schema_ids: dict[str, int] = {}
        self._start_ns = _NO_TIME
        self._end_ns = 0
        self._message_count = 0
        self._unflushed = 0
        self._closed = False

    # -- writing ---------------------------------------------------------------------------
    def add_topic(self, name: str, type_name: str, qos_yaml: str = '',
                  type_description_hash: str | None = None,
                  message_definition: str | None = None) -> None:
        """Declare topic `name` of type `pkg/msg/Type` before its first `write`.

        `qos_yaml` is the publishers' offered QoS as rosbag2 stores it (`metadata_yaml.qos_yaml`;
        '' = unknown). The schema text and type hash are looked up on AMENT_PREFIX_PATH unless
        given. Declaring a topic again with the same type is a no-op.
        """
        self._check_open()
        if name in self._topics:
            if self._topics[name].type_name != type_name:
                raise BagError(f'topic {name} is already in bag {self.directory} with type '
                               f'{self._topics[name].type_name}, not {type_name}')
            return
        try:
            msgdefs.split_type_name(type_name)
            profiles = metadata_yaml.parse_qos_yaml(qos_yaml)
            if type_name not in self._schema_ids:
                text = (message_definition if message_definition is not None
                        else msgdefs.message_definition(type_name))
                self._schema_ids[type_name] = self._writer.register_schema(
                    type_name, msgdefs.SCHEMA_ENCODING, text.encode('utf-8'))
            if type_description_hash is None:
                type_description_hash = msgdefs.type_description_hash(type_name)
        except (msgdefs.MessageDefinitionError, ValueError) as error:
            raise BagError(f'cannot add topic {name} to bag {self.directory}: {error}') from None
        channel_id = self._writer.register_channel(
            name, MESSAGE_ENCODING, self._schema_ids[type_name],
            {'offered_qos_profiles': metadata_yaml.dump(profiles),
             'topic_type_hash': type_description_hash})
        self._topics[name] = _Topic(name, type_name, profiles, type_description_hash, channel_id)

    def write(self, topic: str, data: bytes, log_time_ns: int,
              publish_time_ns: int | None = None) -> None:
        """Append one CDR-serialized message of `topic`, received at `log_time_ns` [ns]."""
        self.write_many([(topic, data)], log_time_ns, publish_time_ns)

    def write_many(self, messages: Sequence[tuple[str, bytes]], log_time_ns: int,
                   publish_time_ns: int | None = None) -> None:
        """`write` of each (topic, CDR bytes), all received at `log_time_ns` [ns], in order,
        packed together (a headless tick's messages: about a fifth of the cost of a write
        each); a chunk is finished after them, not between them."""
        self._check_open()
        entries = [self._topics.get(topic) for topic, _ in messages]
        if None in entries:
            topic = messages[entries.index(None)][0]
            raise BagError(f'topic {topic} was not added to bag {self.directory}; '
                           'call add_topic first')
        if not entries:
            return
        if log_time_ns < 0:
            raise BagError(f'negative log time {log_time_ns} ns for a message of '
                           f'{messages[0][0]}')
        records = []
        for entry, (_, data) in zip(entries, messages):
            records.append((entry.channel_id, entry.message_count, data))
            entry.message_count += 1
        writes_before = self._file.writes
        self._messages.add_many(records, log_time_ns,
                                log_time_ns if publish_time_ns is None else publish_time_ns)
        self._message_count += len(records)
        self._start_ns = min(self._start_ns, log_time_ns)
        self._end_ns = max(self._end_ns, log_time_ns)
        self._unflushed = (0 if self._file.writes != writes_before
                           else self._unflushed + len(records))

    def write_block(self, log_times_ns: np.ndarray, groups: Sequence[Sequence[Column]]) -> None:
        """The bag `write_many` gives called for every tick k of a block and every group in
        turn, with the group's messages at tick k (its columns' in order) logged and published
        at log_times_ns[k] [ns] (a group without any at k writes nothing), packed with numpy
        a block at a time (`MessageAppender.add_block`; tests/unit/test_bag_blocks.py holds
        the files equal). A topic is in at most one column of a block."""
        self._check_open()
        log_times = np.asarray(log_times_ns, dtype=np.int64)
        count, columns, column_groups, entries = len(log_times), [], [], []
        for group, group_columns in enumerate(groups):
            for column in group_columns:
                entry = self._topics.get(column.topic)
                if entry is None:
                    raise BagError(f'topic {column.topic} was not added to bag '
                                   f'{self.directory}; call add_topic first')
                if entry in entries:
                    raise BagError(f'topic {column.topic} is in two columns of a block')
                messages = count if column.ticks is None else len(column.ticks)
                if column.ticks is not None and len(column.ticks) and (
                        column.ticks[0] < 0 or column.ticks[-1] >= count
                        or np.any(np.diff(column.ticks) <= 0)):
                    raise BagError(f'{column.topic}: its ticks must increase within 0 .. '
                                   f'{count - 1}')
                if column.data.ndim != 2 or len(column.data) != messages:
                    raise BagError(f'{column.topic}: {len(column.data)} messages for '
                                   f'{messages} ticks')
                columns.append((entry.channel_id, entry.message_count,
                                np.ascontiguousarray(column.data, dtype=np.uint8),
                                column.ticks))
                column_groups.append(group)
                entries.append(entry)
        if not columns or not count:
            return
        if log_times.min() < 0:
            raise BagError(f'negative log time {log_times.min()} ns in a block')
        times = log_times.astype(np.uint64)
        self._unflushed = self._messages.add_block(times, times, columns, column_groups)
        for entry, (_, _, data, _) in zip(entries, columns):
            entry.message_count += len(data)
            self._message_count += len(data)
        present = np.zeros(count, bool)
        for _, _, data, ticks in columns:
            present[slice(None) if ticks is None else ticks] = True
        if present.any():
            self._start_ns = min(self._start_ns, int(log_times[present].min()))
            self._end_ns = max(self._end_ns, int(log_times[present].max()))

    def flush(self) -> None:
        """Finish the chunk in progress so every message written so far is on disk."""
        self._check_open()
        if self._unflushed:
            self._writer.flush()
            self._unflushed = 0

    def close(self) -> None:
        """Finish the MCAP (summary, `rosbag2` metadata record) and write `metadata.yaml`.

        Idempotent: a second call does nothing.
        """
        if self._closed:
            return
        self._closed = True
        try:
            info = self.metadata()
            self._writer.add_metadata('rosbag2', {'serialized_metadata': metadata_yaml.dump(info)})
            self._writer.finish()
        finally:
            self._file.close()
        text = metadata_yaml.dump({'rosbag2_bagfile_information': info}) + '\n'
        tmp = self.directory / 'metadata.yaml.tmp'
        tmp.write_text(text, encoding='utf-8')
        tmp.replace(self.directory / 'metadata.yaml')

    # -- state -----------------------------------------------------------------------------
    @property
    def message_count(self) -> int:
        """Messages written so far."""
        return self._message_count

    @property
    def unflushed_count(self) -> int:
        """Messages in the chunk in progress (not yet on disk)."""
        return self._unflushed

    @property
    def topics(self) -> dict[str, str]:
        """Topic name -> type name of the topics added so far."""
        return {name: t.type_name for name, t in self._topics.items()}

    @property
    def closed(self) -> bool:
        """Whether `close()` was called."""
        return self._closed

    def metadata(self) -> dict[str, Any]:
        """The `rosbag2_bagfile_information` map as it stands now (times in [ns])."""
        duration = self._end_ns - self._start_ns if self._message_count else 0
        file_info = {'path': self.file_name,
                     'starting_time': {'nanoseconds_since_epoch': self._start_ns},
                     'duration': {'nanoseconds': duration},
                     'message_count': self._message_count}
        return {
            'version': METADATA_VERSION,
            'storage_identifier': STORAGE_IDENTIFIER,
            'duration': {'nanoseconds': duration},
            'starting_time': {'nanoseconds_since_epoch': self._start_ns},
            'message_count': self._message_count,
            'topics_with_message_count': [t.metadata() for t in self._topics.values()],
            'compression_format': '',
            'compression_mode': '',
            'relative_file_paths': [self.file_name],
            'files': [file_info],
            'custom_data': dict(self.custom_data) or None,
            'ros_distro': ROS_DISTRO,
        }

    def _check_open(self) -> None:
        if self._closed:
            raise BagError(f'bag {self.directory} is closed')

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def recover(directory: str | os.PathLike, output: str | os.PathLike, *,
            file_name: str | None = None, custom_data: dict[str, str] | None = None) -> int:
    """Copy what is readable of a bag whose recorder died into a new, closed bag `output`.

    Reads `directory`'s MCAP file front to back (as `ros2 bag reindex` and `mcap recover` do) and
    keeps every message of every complete chunk; a torn record at the end ends the copy. Topics,
    schemas, QoS and type hashes come from the MCAP's own schema and channel records, so the
    message packages need not be installed. `file_name` and `custom_data` are passed to the
    output's BagWriter. Returns the number of messages recovered.
    """
    files = sorted(Path(directory).glob('*.mcap'))
    if not files:
        raise BagError(f'no .mcap file in {directory}')
    schemas: dict[int, Schema] = {}
    topics: dict[int, str] = {}
    count = 0
    with open(files[0], 'rb') as stream, BagWriter(output, file_name=file_name,
                                                   custom_data=custom_data) as out:
        try:
            for record in StreamReader(stream, validate_crcs=True).records:
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    schema = schemas[record.schema_id]
                    out.add_topic(record.topic, schema.name,
                                  record.metadata.get('offered_qos_profiles', ''),
                                  record.metadata.get('topic_type_hash', ''),
                                  schema.data.decode('utf-8'))
                    topics[record.id] = record.topic
                elif isinstance(record, Message):
                    out.write(topics[record.channel_id], record.data, record.log_time,
                              record.publish_time)
                    count += 1
        except TORN_RECORD_ERRORS:
            pass  # the torn tail of a file whose writer was killed
    return count
