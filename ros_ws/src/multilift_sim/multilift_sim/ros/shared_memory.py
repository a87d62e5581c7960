"""Fast DDS's shared-memory files left by processes that were killed.

Fast DDS (rmw_fastrtps, the default RMW) gives each participant a segment and each of its
listening ports files in /dev/shm; a process that exits normally removes them, a killed one
leaves them. Each file set has a lock file (`..._el`, `..._sl`) that the owning process holds
(flock) while it lives, so a set whose lock nobody holds is stale: what Fast DDS's own
`fastdds shm clean` removes, and the only thing removed here (a live participant's files are
never touched, whoever runs it).

Stale files have cost runs here their topics (a recorder that never heard a follower, a bridge
that received none of a run's messages; the same tests passed once the files were gone), so
`multilift run` and `multilift foxglove` remove them before they start nodes, and the tests
before they start any.
"""
from __future__ import annotations

import fcntl
import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path

SHM_DIR = Path('/dev/shm')
# a participant's segment `fastrtps_<16 hex>` and its lock `..._el` / `..._sl`
_SEGMENT_LOCK = re.compile(r'^fastrtps_[0-9a-z]{16}(_el|_sl)$')
# a port `fastrtps_port<N>`, its lock, and its mutex `sem.fastrtps_port<N>_mutex`
_PORT_LOCK = re.compile(r'^fastrtps_port\d{1,5}(_el|_sl)$')


@dataclass(frozen=True)
class StaleFiles:
    """What `remove_stale_files` found: file sets removed and file sets still in use."""
    segments_removed: int
    ports_removed: int
    in_use: int

    def __str__(self) -> str:
        return (f'removed {self.segments_removed} stale Fast DDS segment(s) and '
                f'{self.ports_removed} port(s) left by killed processes '
                f'({self.in_use} in use by live ones)')


def _locked(path: Path) -> bool:
    """Whether a live process holds `path`'s flock (shared or exclusive)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except FileNotFoundError:
        return False
    except OSError:  # not ours to open: treat as in use, never remove it
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return True
    finally:
        os.close(fd)  # closing releases the lock taken for the test
    return False


def _remove(*paths: Path) -> None:
    for path in paths:
        try:
            path.unlink()
        except OSError:  # gone already (another cleaner, its owner's exit) or not ours
            pass


def stale_locks(shm_dir: Path = SHM_DIR) -> list[Path]:
    """The lock files of Fast DDS file sets in `shm_dir` that no live process holds."""
    return [shm_dir / name for name in _names(shm_dir)
            if (_SEGMENT_LOCK.match(name) or _PORT_LOCK.match(name))
            # a file set may have both an exclusive and a shared lock: stale when neither is held
            and not any(_locked(shm_dir / f'{name[:-3]}{kind}') for kind in ('_el', '_sl'))]


def remove_stale_files(shm_dir: Path = SHM_DIR) -> StaleFiles:
    """Remove the Fast DDS file sets in `shm_dir` whose lock no live process holds: a segment
    with its lock, a port with its lock and its mutex."""
    segments = ports = 0
    # one file set per name, however many of its locks (`_el`, `_sl`) were found stale
    for data in sorted({lock.name[:-3] for lock in stale_locks(shm_dir)}):
        _remove(shm_dir / data, shm_dir / f'{data}_el', shm_dir / f'{data}_sl')
        if data.startswith('fastrtps_port'):
            _remove(shm_dir / f'sem.{data}_mutex')
            ports += 1
        else:
            segments += 1
    in_use = sum(1 for name in _names(shm_dir)
                 if _SEGMENT_LOCK.match(name) or _PORT_LOCK.match(name))
    return StaleFiles(segments, ports, in_use)


def _names(shm_dir: Path) -> list[str]:
    try:
        return sorted(os.listdir(shm_dir))
    except OSError:  # no /dev/shm: nothing Fast DDS could have left
        return []


def remove_before_start() -> None:
    """What `multilift run` and `multilift foxglove` do before they start a participant:
    `remove_stale_files`, with a note on stderr when there were any."""
    found = remove_stale_files()
    if found.segments_removed or found.ports_removed:
        print(f'note: {found}', file=sys.stderr)
