"""CDR (XCDR1, little endian) as our packers write it: the encapsulation header and `Layout`,
a message's `struct.Struct` built field by field. The bytes are rclpy's `serialize_message`
output with the padding zeroed (rclpy leaves it uninitialised):

- a 4-byte encapsulation header `00 01 00 00` (CDR, little endian), then the message;
- every primitive aligned to its own size, counted from the end of that header;
- a string is a uint32 length including the NUL, its bytes, the NUL;
- a sequence is a uint32 count, then its elements (aligned from the first element);
- no padding after the last field.
"""
from __future__ import annotations

import struct

ENCAPSULATION = b'\x00\x01\x00\x00'


class Layout:
    """Builds a struct format for a CDR message field by field, tracking alignment; `pad`
    lists the (offset, length) of every padding run in the packed bytes (header included)."""

    def __init__(self) -> None:
        self._fmt = ['<4s']
        self._offset = 0  # from the end of the encapsulation header
        self.pad: list[tuple[int, int]] = []

    def _align(self, size: int) -> None:
        gap = -self._offset % size
        if gap:
            self._fmt.append(f'{gap}x')
            self.pad.append((4 + self._offset, gap))
            self._offset += gap

    def primitive(self, code: str, count: int = 1) -> None:
        """`count` values of struct code `code` (i, I, d, f, ?, B): count args."""
        self._field(code, count, f'{count}{code}')

    def zeros(self, code: str, count: int = 1) -> None:
        """`count` values of `code` that are always zero: no args."""
        self._field(code, count, f'{struct.calcsize(code) * count}x')

    def _field(self, code: str, count: int, fmt: str) -> None:
        """`count` values of `code`, aligned to its size, as the struct format `fmt`."""
        size = struct.calcsize(code)
        if count:
            self._align(size)
            self._fmt.append(fmt)
            self._offset += size * count

    def string(self, text: str) -> bytes:
        """A string field whose value is `text` (fixed for the layout): args (length, bytes);
        returns the bytes to pass."""
        data = text.encode('utf-8')
        self.primitive('I')
        self._fmt.append(f'{len(data) + 1}s')  # struct pads with the NUL
        self._offset += len(data) + 1
        return data

    def header(self, frame: str) -> bytes:
        """std_msgs/Header: args (sec, nanosec, length, frame bytes)."""
        self.primitive('i')
        self.primitive('I')
        return self.string(frame)

    def compile(self) -> struct.Struct:
        return struct.Struct(''.join(self._fmt))


def header_layout(frame: str) -> tuple[Layout, tuple]:
    """A new layout that starts with std_msgs/Header of `frame`, and the frame's args (length,
    bytes) for its packer."""
    layout = Layout()
    data = layout.header(frame)
    return layout, (len(data) + 1, data)
