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

import numpy as np

ENCAPSULATION = b'\x00\x01\x00\x00'
# the numpy type of each struct code a layout's arguments use (little endian, as the format's '<')
_DTYPES = {'d': '<f8', 'f': '<f4', 'i': '<i4', 'I': '<u4', '?': '?', 'B': 'u1'}


class Layout:
    """Builds a struct format for a CDR message field by field, tracking alignment; `pad`
    lists the (offset, length) of every padding run in the packed bytes (header included)."""

    def __init__(self) -> None:
        self._fmt = ['<4s']
        self._offset = 0  # from the end of the encapsulation header
        self.pad: list[tuple[int, int]] = []
        # per argument of `pack`, in order: (its offset in the packed bytes, its struct code)
        self._args: list[tuple[int, str]] = [(0, '4s')]
        self._compiled: struct.Struct | None = None

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
            if not fmt.endswith('x'):
                self._args += [(4 + self._offset + size * k, code) for k in range(count)]
            self._offset += size * count

    def string(self, text: str) -> bytes:
        """A string field whose value is `text` (fixed for the layout): args (length, bytes);
        returns the bytes to pass."""
        data = text.encode('utf-8')
        self.primitive('I')
        self._fmt.append(f'{len(data) + 1}s')  # struct pads with the NUL
        self._args.append((4 + self._offset, f'{len(data) + 1}s'))
        self._offset += len(data) + 1
        return data

    def header(self, frame: str) -> bytes:
        """std_msgs/Header: args (sec, nanosec, length, frame bytes)."""
        self.primitive('i')
        self.primitive('I')
        return self.string(frame)

    def compile(self) -> struct.Struct:
        self._compiled = struct.Struct(''.join(self._fmt))
        return self._compiled

    def pack_rows(self, *args) -> np.ndarray:
        """K messages at once, (K, size) uint8 with the padding zeroed: `args` as the compiled
        struct's `pack` takes them, except that any run of them may be a column, an array of
        one value per message (K,) or of K rows of consecutive arguments (K, w). Row k is
        `pack` of the arguments with each column's row k in its place (tests/unit/test_cdr.py)."""
        plain, columns = [], []
        for arg in args:
            if isinstance(arg, np.ndarray):
                width = 1 if arg.ndim == 1 else arg.shape[1]
                columns.append((len(plain), width, arg))
                plain += [False if self._args[len(plain) + k][1] == '?' else 0
                          for k in range(width)]
            else:
                plain.append(arg)
        if self._compiled is None:
            self.compile()
        template = self._compiled.pack(*plain)
        count = len(columns[0][2])
        out = np.empty((count, len(template)), np.uint8)
        out[:] = np.frombuffer(template, np.uint8)
        for first, width, values in columns:
            values = values.reshape(count, width)
            for start, stop in self._runs(first, first + width):
                offset, code = self._args[start]
                dtype = np.dtype(_DTYPES[code])
                np.ndarray((count, stop - start), dtype, out, offset,
                           (out.shape[1], dtype.itemsize))[...] = values[:, start - first:
                                                                         stop - first]
        return out

    def _runs(self, first: int, stop: int) -> list[tuple[int, int]]:
        """The arguments first .. stop - 1 as runs [start, end) of one code packed
        back to back (a run is one strided view of the packed rows)."""
        runs, start = [], first
        for k in range(first + 1, stop + 1):
            if k == stop or self._args[k][1] != self._args[start][1] or self._args[k][0] != \
                    self._args[k - 1][0] + struct.calcsize(self._args[k - 1][1]):
                runs.append((start, k))
                start = k
        return runs


def header_layout(frame: str) -> tuple[Layout, tuple]:
    """A new layout that starts with std_msgs/Header of `frame`, and the frame's args (length,
    bytes) for its packer."""
    layout = Layout()
    data = layout.header(frame)
    return layout, (len(data) + 1, data)
