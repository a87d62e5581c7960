"""The MCAP file below the mcap library's Writer, as BagWriter writes it: a file without a
user-space buffer (every finished chunk on disk at once) and Message records packed in one
call each (`MessageAppender`, the library's bookkeeping; the bytes the library writes).
"""
from __future__ import annotations

import itertools
import os
import struct
from pathlib import Path

from mcap.opcode import Opcode
from mcap.records import MessageIndex
from mcap.writer import Writer


class DirectFile:
    """A write-only file without user-space buffer: each `write` reaches the OS at once."""

    def __init__(self, path: Path) -> None:
        self._fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        self._position = 0
        self.writes = 0

    def write(self, data: bytes) -> int:
        view = memoryview(data)
        while view:
            done = os.write(self._fd, view)
            view = view[done:]
        self._position += len(data)
        self.writes += 1
        return len(data)

    def tell(self) -> int:
        return self._position

    def flush(self) -> None:
        """Nothing is buffered here; kept for the mcap Writer's stream interface."""

    def close(self) -> None:
        if self._fd >= 0:
            os.fsync(self._fd)
            os.close(self._fd)
            self._fd = -1


# an MCAP Message record up to its data: opcode 0x05, record length, channel id, sequence,
# log time, publish time (MCAP spec, "Message")
_MESSAGE_RECORD = struct.Struct('<BQHIQQ')
_MESSAGE_FIELDS = 2 + 4 + 8 + 8  # [B] the record's length without its data


class _MessageIndex(MessageIndex):
    """mcap's MessageIndex written with one pack of its (log time, offset) pairs: the same
    bytes as the library's two 8-byte writes per message (most of a long bag's close)."""

    def write(self, stream) -> None:
        stream.start_record(Opcode.MESSAGE_INDEX)
        stream.write2(self.channel_id)
        stream.write4(len(self.records) * 16)
        stream.write(struct.pack(f'<{2 * len(self.records)}Q',
                                 *itertools.chain.from_iterable(self.records)))
        stream.finish_record()


class MessageAppender:
    """`Writer.add_message` of the pinned mcap library (requirements.txt) with the record
    packed in one call: the library builds a Message object and writes it field by field
    (about 15 us a message here, most of a headless bag's cost). The same bookkeeping: the
    file's statistics, the chunk's time range and message index, the chunk finished past
    `chunk_size`; tests/unit/test_bag.py holds the file byte-equal to the library's."""

    def __init__(self, writer: Writer) -> None:
        self._statistics = writer._Writer__statistics          # noqa: SLF001 - see above
        self._chunk = writer._Writer__chunk_builder            # noqa: SLF001
        self._maybe_finish_chunk = writer._Writer__maybe_finalize_chunk  # noqa: SLF001

    def add_many(self, messages: list[tuple[int, int, bytes]], log_time: int,
                 publish_time: int) -> None:
        """`Writer.add_message` of each (channel id, sequence, data), all logged at
        `log_time`, in one write to the chunk and one chunk-size check after them (a chunk
        may pass `chunk_size` by these messages; one message at a time is the library's)."""
        stats, chunk = self._statistics, self._chunk
        if stats.message_count == 0:
            stats.message_start_time = log_time
        else:
            stats.message_start_time = min(log_time, stats.message_start_time)
        stats.message_end_time = max(log_time, stats.message_end_time)
        stats.message_count += len(messages)
        if chunk.num_messages == 0:
            chunk.message_start_time = log_time
        else:
            chunk.message_start_time = min(chunk.message_start_time, log_time)
        chunk.message_end_time = max(chunk.message_end_time, log_time)
        chunk.num_messages += len(messages)
        counts, indices = stats.channel_message_counts, chunk.message_indices
        records = chunk.record_writer
        offset, parts = records.count, []
        for channel_id, sequence, data in messages:
            counts[channel_id] += 1
            index = indices.get(channel_id)
            if index is None:
                index = indices[channel_id] = _MessageIndex(channel_id=channel_id, records=[])
            index.records.append((log_time, offset))
            parts.append(_MESSAGE_RECORD.pack(0x05, _MESSAGE_FIELDS + len(data), channel_id,
                                              sequence, log_time, publish_time))
            parts.append(data)
            offset += _MESSAGE_RECORD.size + len(data)
        records.write(b''.join(parts))
        self._maybe_finish_chunk()  # past the Writer's chunk_size
