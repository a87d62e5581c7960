"""The MCAP file below the mcap library's Writer, as BagWriter writes it: a file without a
user-space buffer (every finished chunk on disk at once) and Message records packed in one
call each (`MessageAppender`, the library's bookkeeping; the bytes the library writes), or a
block of ticks' records packed at once (`MessageAppender.add_block`, numpy; the same bytes).
"""
from __future__ import annotations

import itertools
import os
import struct
from pathlib import Path
from typing import Sequence

import numpy as np
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
# the same record header as a numpy record type (its fields in _MESSAGE_RECORD's order)
MESSAGE_HEADER = np.dtype([(name, '<' + code) for name, code in zip(
    ('opcode', 'length', 'channel', 'sequence', 'log_time', 'publish_time'),
    _MESSAGE_RECORD.format.lstrip('<'))])
assert MESSAGE_HEADER.itemsize == _MESSAGE_RECORD.size


# an MCAP MessageIndex record up to its (log time, offset) pairs: opcode, record length,
# channel id, the pairs' length [B] (MCAP spec, "Message Index")
_MESSAGE_INDEX_HEADER = struct.Struct('<BQHI')


class _MessageIndex(MessageIndex):
    """mcap's MessageIndex in one write, its (log time, offset) pairs packed at once: the
    same bytes as the library's two 8-byte writes per message (most of a long bag's close). Pairs
    come one by one (`records`, as the library's) or as arrays (`add_pairs`), kept in order."""

    def __init__(self, channel_id: int, records: list) -> None:
        super().__init__(channel_id=channel_id, records=records)
        self.blocks: list[np.ndarray] = []  # (m, 2) uint64 each, before `records`

    def add_pairs(self, pairs: np.ndarray) -> None:
        """Append (log time, offset) pairs (m, 2) after those given so far."""
        if self.records:
            self.blocks.append(np.array(self.records, dtype=np.uint64))
            self.records = []
        self.blocks.append(pairs)

    def write(self, stream) -> None:
        body = b''.join([block.astype('<u8', copy=False).tobytes() for block in self.blocks]
                        + [struct.pack(f'<{2 * len(self.records)}Q',
                                       *itertools.chain.from_iterable(self.records))])
        length = _MESSAGE_INDEX_HEADER.size - 1 - 8 + len(body)  # after opcode and length
        stream.write(_MESSAGE_INDEX_HEADER.pack(Opcode.MESSAGE_INDEX, length, self.channel_id,
                                                len(body)) + body)


# a column of a block (`MessageAppender.add_block`): (channel id, the sequence of its first
# message, its messages' data (m, size) uint8, the ticks that have one (m,) or None: all)
BlockColumn = tuple[int, int, np.ndarray, np.ndarray | None]


def _patterns(present: np.ndarray, sparse: list[bool]) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of `present` (ticks, columns) and each tick's, as np.unique(axis=0)
    gives them, keyed by the `sparse` columns alone (the others are present at every tick)."""
    varying = np.flatnonzero(sparse)
    if len(varying) > 62:  # no 64-bit key
        patterns, which = np.unique(present, axis=0, return_inverse=True)
        return patterns, which.reshape(-1)
    keys = present[:, varying].astype(np.int64) @ (1 << np.arange(len(varying), dtype=np.int64))
    _, first, which = np.unique(keys, return_index=True, return_inverse=True)
    return present[first], which.reshape(-1)


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
        self._chunk_size = writer._Writer__chunk_size                # noqa: SLF001

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

    def add_block(self, log_times: np.ndarray, publish_times: np.ndarray,
                  columns: Sequence[BlockColumn], groups: Sequence[int]) -> int:
        """`add_many` of every tick k of a block (log_times, publish_times (K,) [ns]) and every
        group of columns in turn (`groups[c]`: column c's group, nondecreasing): the messages
        of the group's columns that have one at k, in column order, logged at log_times[k]; a
        group without any at k writes nothing. The same bytes, packed with numpy: each
        column's records at once, each tick's as a row of the ticks with the same columns
        (one row type per such pattern), a chunk finished at the first group end past
        `chunk_size`, as `add_many` one group at a time. Returns the chunk's message count."""
        count, widths = len(log_times), []
        present = np.zeros((count, len(columns)), bool)
        rows, offsets, ticks_of = [], [], []
        for c, (channel, sequence, data, ticks) in enumerate(columns):
            ticks = np.arange(count) if ticks is None else np.asarray(ticks)
            present[ticks, c] = True
            record = np.empty(len(ticks), [('header', MESSAGE_HEADER),
                                           ('data', np.uint8, (data.shape[1],))])
            header = record['header']
            header['opcode'] = Opcode.MESSAGE
            header['length'] = _MESSAGE_FIELDS + data.shape[1]
            header['channel'] = channel
            header['sequence'] = sequence + np.arange(len(ticks))
            header['log_time'] = log_times[ticks]
            header['publish_time'] = publish_times[ticks]
            record['data'] = data
            rows.append(record.view(np.uint8).reshape(len(ticks), record.dtype.itemsize))
            widths.append(record.dtype.itemsize)
            ticks_of.append(ticks)
        if not present.any():
            return self._chunk.num_messages
        patterns, which = _patterns(present, [ticks is not None for *_, ticks in columns])
        sizes = patterns * np.array(widths)               # (P, C) each column's bytes a tick
        within = np.cumsum(sizes, axis=1) - sizes        # (P, C) where it starts in the tick
        starts = np.concatenate(([0], np.cumsum(sizes.sum(axis=1)[which])))
        # each tick's group ends, in writing order, and the tick of each
        groups = np.asarray(groups)
        last = np.flatnonzero(np.r_[groups[1:] != groups[:-1], True])  # each group's last column
        ends = starts[:-1, None] + np.cumsum(sizes, axis=1)[which][:, last]
        nonempty = np.add.reduceat(patterns.astype(int), np.r_[0, last[:-1] + 1],
                                   axis=1)[which] > 0
        end_ticks = np.broadcast_to(np.arange(count)[:, None], ends.shape)[nonempty]
        ends = ends[nonempty]
        pairs = []  # each column's (log time, offset in the block) pairs
        for c, ticks in enumerate(ticks_of):
            offsets.append(starts[ticks] + within[which[ticks], c])
            pairs.append(np.stack((log_times[ticks].astype(np.int64), offsets[-1]), axis=1))
        stream = self._stream(rows, present, patterns, which, sizes)
        position, done = 0, 0
        while done < len(ends):
            room = max(position + self._chunk_size - self._chunk.count, position)
            cut = int(np.searchsorted(ends, room, side='right'))
            stop = min(cut, len(ends) - 1)
            self._append(stream, position, int(ends[stop]), log_times[end_ticks[done:stop + 1]],
                         columns, offsets, pairs)
            position, done = int(ends[stop]), stop + 1
            self._maybe_finish_chunk()  # past chunk_size at the cut
        return self._chunk.num_messages

    @staticmethod
    def _stream(rows: list, present: np.ndarray, patterns: np.ndarray, which: np.ndarray,
                sizes: np.ndarray) -> bytes:
        """The block's records in writing order: per pattern of columns its ticks' rows
        (column after column), then the rows joined tick by tick."""
        positions = np.cumsum(present, axis=0) - 1  # each column's row of each tick
        blocks = []
        for p, pattern in enumerate(patterns):
            ticks = np.flatnonzero(which == p)
            parts = [rows[c] if len(rows[c]) == len(ticks) else rows[c][positions[ticks, c]]
                     for c in np.flatnonzero(pattern)]
            blocks.append(memoryview(np.concatenate(parts, axis=1).reshape(-1)) if parts
                          else memoryview(b''))
        if len(blocks) == 1:
            return blocks[0]
        width, rank = sizes.sum(axis=1).tolist(), [0] * len(blocks)
        pieces = []
        for p in which.tolist():
            pieces.append(blocks[p][rank[p] * width[p]:(rank[p] + 1) * width[p]])
            rank[p] += 1
        return memoryview(b''.join(pieces))

    def _append(self, stream, start: int, stop: int, group_times: np.ndarray,
                columns: Sequence[BlockColumn], offsets: list, pairs: list) -> None:
        """Write the block's bytes start .. stop (whole groups logged at `group_times`) into
        the chunk in progress, with the bookkeeping `add_many` does for their messages."""
        stats, chunk = self._statistics, self._chunk
        base = chunk.count
        first, last = int(group_times.min()), int(group_times.max())
        spans = []
        for c, at in enumerate(offsets):
            low, high = np.searchsorted(at, (start, stop))
            if high > low:
                spans.append((int(at[low]), c, int(low), int(high)))
        spans.sort()
        messages = sum(high - low for _, _, low, high in spans)
        stats.message_start_time = first if stats.message_count == 0 \
            else min(first, stats.message_start_time)
        stats.message_end_time = max(last, stats.message_end_time)
        stats.message_count += messages
        chunk.message_start_time = first if chunk.num_messages == 0 \
            else min(chunk.message_start_time, first)
        chunk.message_end_time = max(chunk.message_end_time, last)
        chunk.num_messages += messages
        indices = chunk.message_indices
        for _, c, low, high in spans:
            channel = columns[c][0]
            stats.channel_message_counts[channel] += high - low
            index = indices.get(channel)
            if index is None:
                index = indices[channel] = _MessageIndex(channel_id=channel, records=[])
            index.add_pairs((pairs[c][low:high] + (0, base - start)).astype('<u8'))
        chunk.record_writer.write(stream[start:stop])
