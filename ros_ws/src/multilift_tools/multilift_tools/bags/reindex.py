"""`reindex`: a bag rebuilt in place from what its MCAP holds.

reindex: `ros2 bag reindex` rebuilds metadata.yaml only; this also rewrites the MCAP (every message
of every complete chunk, `bag.recover`) so it has a summary, chunk and message indexes and the
`rosbag2` metadata record again. The file keeps its name; the data after the last complete chunk
(at most the recorder's flush period) is gone either way.
"""
from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

from multilift_sim.bag import BagError, recover
from multilift_tools.bags.summary import (BagToolError, bag_directory, mcap_file, read_metadata,
                                         read_summary)


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
