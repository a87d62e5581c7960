"""A message's own time [ns] for the Foxglove bridge: where a stamp sits in a message's CDR
bytes (`stamp_offset`: a first field std_msgs/Header or builtin_interfaces/Time, or the first
element of a sequence of such messages), the stamp read there (`cdr_stamp`), and the time of a
message without one (`stamp_ns`: the latest /clock time, or wall time).
"""
from __future__ import annotations

import struct


def stamp_ns(clock_ns: int | None, sim_time: bool, wall_ns: int) -> int:
    """Time [ns] of a message without a stamp of its own: the latest /clock time (0 before the
    first one) when stamping with simulated time, else wall time."""
    if sim_time:
        return clock_ns or 0
    return wall_ns


def stamp_offset(msg_type: type) -> tuple[int, bool] | None:
    """Where a message's own time is in its CDR bytes: (offset of `sec`, whether it is the first
    element of a sequence) for a message whose first field is a std_msgs/Header or a
    builtin_interfaces/Time, or a sequence of such messages; None without one."""
    from multilift_sim.ros.introspection import import_message_type
    fields = list(msg_type.get_fields_and_field_types().values())
    if not fields:
        return None
    first = fields[0]
    if first in ('std_msgs/Header', 'builtin_interfaces/Time'):
        return 4, False
    if first.startswith('sequence<') and '/' in first:
        element = first[len('sequence<'):].rstrip('>').split(',')[0]
        package, name = element.split('/')
        try:
            inner = import_message_type(f'{package}/msg/{name}')
        except ValueError:
            return None
        if stamp_offset(inner) == (4, False):
            return 8, True
    return None


def cdr_stamp(data: bytes, where: tuple[int, bool] | None) -> int | None:
    """The stamp [ns] at `where` (`stamp_offset`) in CDR `data`, or None (none there)."""
    if where is None or len(data) < where[0] + 8:
        return None
    order = '<' if data[1] & 1 else '>'
    offset, in_sequence = where
    if in_sequence and struct.unpack_from(order + 'I', data, 4)[0] == 0:
        return None
    sec, nanosec = struct.unpack_from(order + 'iI', data, offset)
    return sec * 1_000_000_000 + nanosec
