"""Fast DDS's stale shared-memory files (multilift_sim.ros.shared_memory): the sets whose lock no
process holds are removed, held ones and other files never. The locks are held by this process
through other open file descriptions (flock conflicts between them as between processes)."""
from __future__ import annotations

import fcntl
import os

import pytest

from multilift_sim.ros.shared_memory import remove_stale_files, stale_locks

LIVE_SEGMENT = 'fastrtps_0123456789abcdef'
DEAD_SEGMENT = 'fastrtps_fedcba9876543210'
LIVE_PORT = 'fastrtps_port7411'
DEAD_PORT = 'fastrtps_port7413'
SHARED_PORT = 'fastrtps_port7415'   # listeners in several processes hold its `_sl` lock shared
OTHERS = ['sem.mp-abc123', 'lttng-ust-wait-6', 'fastrtps_notasegment', 'fastrtps_port_el']


@pytest.fixture
def shm(tmp_path):
    """A /dev/shm stand-in with live and dead Fast DDS file sets; the live locks are held until
    the test ends."""
    files = [LIVE_SEGMENT, f'{LIVE_SEGMENT}_el', DEAD_SEGMENT, f'{DEAD_SEGMENT}_el',
             LIVE_PORT, f'{LIVE_PORT}_el', f'sem.{LIVE_PORT}_mutex',
             DEAD_PORT, f'{DEAD_PORT}_el', f'sem.{DEAD_PORT}_mutex',
             SHARED_PORT, f'{SHARED_PORT}_el', f'{SHARED_PORT}_sl', f'sem.{SHARED_PORT}_mutex',
             *OTHERS]
    for name in files:
        (tmp_path / name).write_bytes(b'')
    held = []
    for name, mode in ((f'{LIVE_SEGMENT}_el', fcntl.LOCK_EX), (f'{LIVE_PORT}_el', fcntl.LOCK_EX),
                       (f'{SHARED_PORT}_sl', fcntl.LOCK_SH)):
        fd = os.open(tmp_path / name, os.O_RDONLY)
        fcntl.flock(fd, mode | fcntl.LOCK_NB)
        held.append(fd)
    yield tmp_path
    for fd in held:
        os.close(fd)


def test_only_the_sets_nobody_holds_are_stale(shm):
    assert [p.name for p in stale_locks(shm)] == [f'{DEAD_SEGMENT}_el', f'{DEAD_PORT}_el']


def test_stale_sets_are_removed_whole_and_the_rest_is_kept(shm):
    found = remove_stale_files(shm)
    assert (found.segments_removed, found.ports_removed) == (1, 1)
    left = sorted(p.name for p in shm.iterdir())
    for name in (DEAD_SEGMENT, DEAD_PORT):
        assert not any(f.startswith(name) or f == f'sem.{name}_mutex' for f in left), left
    for name in (LIVE_SEGMENT, f'{LIVE_SEGMENT}_el', LIVE_PORT, f'sem.{LIVE_PORT}_mutex',
                 SHARED_PORT, f'{SHARED_PORT}_el', f'{SHARED_PORT}_sl', *OTHERS):
        assert name in left
    assert found.in_use == 4   # the live segment's lock, the live port's, the shared port's two
    assert 'removed 1 stale Fast DDS segment(s) and 1 port(s)' in str(found)


def test_once_the_holder_is_gone_the_set_is_stale(tmp_path):
    for name in ('fastrtps_port9001', 'fastrtps_port9001_el'):
        (tmp_path / name).write_bytes(b'')
    fd = os.open(tmp_path / 'fastrtps_port9001_el', os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    assert stale_locks(tmp_path) == []
    os.close(fd)   # the holder ends (a killed process's locks go with it)
    assert stale_locks(tmp_path) == [tmp_path / 'fastrtps_port9001_el']


def test_a_missing_directory_is_nothing_to_remove(tmp_path):
    assert stale_locks(tmp_path / 'none') == []
    found = remove_stale_files(tmp_path / 'none')
    assert (found.segments_removed, found.ports_removed, found.in_use) == (0, 0, 0)


def test_a_set_with_two_stale_locks_is_one_set(tmp_path):
    for name in ('fastrtps_port9003', 'fastrtps_port9003_el', 'fastrtps_port9003_sl',
                 'sem.fastrtps_port9003_mutex'):
        (tmp_path / name).write_bytes(b'')
    found = remove_stale_files(tmp_path)
    assert (found.segments_removed, found.ports_removed, found.in_use) == (0, 1, 0)
    assert list(tmp_path.iterdir()) == []
