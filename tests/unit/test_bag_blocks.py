"""`BagWriter.write_block` (a block of ticks' messages as numpy columns, the MCAP records
packed at once) is `write_many` called tick by tick and group by group: the same MCAP file
byte for byte and the same metadata.yaml, over random blocks (topics present at every tick or
at some, groups empty at some ticks, sizes, chunk sizes that cut blocks anywhere, single
`write`s between blocks), and the mcap library's reader reads the messages back."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader

from multilift_sim.bag import BagError, BagWriter, Column

TOPICS = [f'/topic{i}' for i in range(6)]
GROUPS = [[0, 1, 2], [3, 4], [5]]  # each tick: three write_many calls of these topics


def _bag(directory: Path, chunk_size: int) -> BagWriter:
    writer = BagWriter(directory / 'bag', chunk_size=chunk_size)
    for topic in TOPICS:
        writer.add_topic(topic, 'std_msgs/msg/Float64')
    return writer


def _random_block(rng, count: int) -> list[list[Column]]:
    groups = []
    for topics in GROUPS:
        group = []
        for i in topics:
            size = int(rng.integers(1, 80))
            ticks = None if rng.random() < 0.5 else np.flatnonzero(rng.random(count) < 0.3)
            messages = count if ticks is None else len(ticks)
            group.append(Column(TOPICS[i], rng.integers(0, 256, (messages, size), np.uint8),
                                ticks))
        groups.append(group)
    return groups


def _tick_by_tick(writer: BagWriter, times: np.ndarray, groups: list[list[Column]]) -> None:
    for k, t in enumerate(times.tolist()):
        for group in groups:
            messages = []
            for column in group:
                ticks = list(range(len(times))) if column.ticks is None else \
                    column.ticks.tolist()
                if k in ticks:
                    messages.append((column.topic, column.data[ticks.index(k)].tobytes()))
            writer.write_many(messages, t)


def _messages(path: Path) -> list:
    with open(path, 'rb') as stream:
        return [(channel.topic, message.sequence, message.log_time, message.data)
                for _, channel, message in make_reader(stream).iter_messages()]


@pytest.mark.parametrize('seed', range(6))
def test_a_block_is_the_bag_of_write_many_tick_by_tick(tmp_path, seed):
    rng = np.random.default_rng(seed)
    for trial in range(4):
        chunk_size = int(rng.integers(100, 6000))
        blocks, singles = _bag(tmp_path / f'blocks{trial}', chunk_size), \
            _bag(tmp_path / f'singles{trial}', chunk_size)
        t0 = 0
        for _ in range(4):
            count = int(rng.integers(1, 50))
            times = t0 + np.sort(rng.integers(0, 10**9, count))
            t0 = int(times[-1])
            groups = _random_block(rng, count)
            if rng.random() < 0.5:  # a message written alone between two blocks
                for writer in (blocks, singles):
                    writer.write(TOPICS[2], b'alone', t0)
            blocks.write_block(times, groups)
            _tick_by_tick(singles, times, groups)
            assert blocks.unflushed_count == singles.unflushed_count
            assert blocks.message_count == singles.message_count
        blocks.close()
        singles.close()
        first = tmp_path / f'blocks{trial}' / 'bag'
        second = tmp_path / f'singles{trial}' / 'bag'
        assert (first / 'bag_0.mcap').read_bytes() == (second / 'bag_0.mcap').read_bytes()
        assert (first / 'metadata.yaml').read_text() == (second / 'metadata.yaml').read_text()
        assert len(_messages(first / 'bag_0.mcap')) == blocks.message_count


def test_a_block_s_misuse_is_reported(tmp_path):
    writer = _bag(tmp_path, 4096)
    data = np.zeros((3, 8), np.uint8)
    with pytest.raises(BagError, match='/nowhere was not added'):
        writer.write_block(np.arange(3), [[Column('/nowhere', data)]])
    with pytest.raises(BagError, match='two columns'):
        writer.write_block(np.arange(3), [[Column(TOPICS[0], data)], [Column(TOPICS[0], data)]])
    with pytest.raises(BagError, match='2 messages for 3 ticks'):
        writer.write_block(np.arange(3), [[Column(TOPICS[0], data[:2])]])
    with pytest.raises(BagError, match='must increase within 0 .. 2'):
        writer.write_block(np.arange(3), [[Column(TOPICS[0], data[:2], np.array([2, 1]))]])
    with pytest.raises(BagError, match='must increase within 0 .. 2'):
        writer.write_block(np.arange(3), [[Column(TOPICS[0], data[:1], np.array([3]))]])
    with pytest.raises(BagError, match='negative log time'):
        writer.write_block(np.arange(3) - 1, [[Column(TOPICS[0], data)]])
    writer.write_block(np.arange(3), [[Column(TOPICS[0], data[:0], np.arange(0))]])
    assert writer.message_count == 0
    writer.close()
