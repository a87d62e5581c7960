"""CDR (XCDR1, little endian) of the messages a run publishes and records, packed without rclpy.

Each packer compiles one `struct.Struct` for its message layout once (the frame names and the
sequence lengths of a run are fixed; `cdr_layout` builds it by CDR's rules), then packs a
message in one call from plain numbers: the values come from `wire.msgvalues`, the same
functions the rclpy builders of multilift_sim.ros.messages use. The scene's messages (/tf,
the markers) are `cdr_scene`'s.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from multilift_sim.wire.cdr_layout import ENCAPSULATION, Layout, header_layout
from multilift_sim.wire.msgvalues import WORLD_FRAME, stamp, stamps


class Clock:
    """rosgraph_msgs/Clock."""

    def __init__(self) -> None:
        layout = Layout()
        layout.primitive('i')
        layout.primitive('I')
        self.layout, self._struct = layout, layout.compile()

    def pack(self, t_ns: int) -> bytes:
        return self._struct.pack(ENCAPSULATION, *stamp(t_ns))

    def pack_rows(self, t_ns: np.ndarray) -> np.ndarray:
        """`pack` of K times [ns] (K,): the messages' bytes (K, size)."""
        return self.layout.pack_rows(ENCAPSULATION, *stamps(t_ns))


class Float64:
    """std_msgs/Float64 (no header: a bag's log time stamps it)."""

    def __init__(self) -> None:
        layout = Layout()
        layout.primitive('d')
        self.layout, self._struct = layout, layout.compile()

    def pack(self, value: float) -> bytes:
        return self._struct.pack(ENCAPSULATION, value)

    def pack_rows(self, values: np.ndarray) -> np.ndarray:
        """`pack` of K values (K,): the messages' bytes (K, size)."""
        return self.layout.pack_rows(ENCAPSULATION, values)


class Odometry:
    """nav_msgs/Odometry with zero covariances, frame `frame`, child `child`; with `covariance`
    its covariances given (`pack_row`'s 85 numbers in the message's order: an estimate,
    estimators.published)."""

    def __init__(self, child: str, frame: str = WORLD_FRAME, covariance: bool = False) -> None:
        layout, self._frame = header_layout(frame)
        child_data = layout.string(child)
        self._frame += (len(child_data) + 1, child_data)
        covariances = layout.primitive if covariance else layout.zeros
        layout.primitive('d', 7)    # pose: position, orientation
        covariances('d', 36)        # pose covariance
        layout.primitive('d', 6)    # twist: linear, angular
        covariances('d', 36)        # twist covariance
        self.layout, self._struct = layout, layout.compile()

    def pack(self, t_ns: int, position: Sequence[float], orientation: Sequence[float],
             linear: Sequence[float], angular: Sequence[float]) -> bytes:
        """From msgvalues.odometry's four tuples."""
        return self._struct.pack(ENCAPSULATION, *stamp(t_ns), *self._frame, *position,
                                 *orientation, *linear, *angular)

    def pack_row(self, t_ns: int, row: Sequence[float]) -> bytes:
        """From the 13 numbers of `pack`'s four tuples in a row (with `covariance`, 85)."""
        return self._struct.pack(ENCAPSULATION, *stamp(t_ns), *self._frame, *row)

    def pack_rows(self, t_ns: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """`pack_row` of K times (K,) and rows (K, 13) (or (K, 85)): the bytes (K, size)."""
        return self.layout.pack_rows(ENCAPSULATION, *stamps(t_ns), *self._frame, rows)


class _Stamped:
    """A header then `floats` float64 fields (Vector3Stamped, AttitudeSetpoint,
    TrackingReference)."""

    def __init__(self, floats: int, frame: str) -> None:
        layout, self._frame = header_layout(frame)
        layout.primitive('d', floats)
        self.layout, self._struct = layout, layout.compile()

    def pack(self, t_ns: int, *values: float) -> bytes:
        return self._struct.pack(ENCAPSULATION, *stamp(t_ns), *self._frame, *values)

    def pack_rows(self, t_ns: np.ndarray, values: np.ndarray) -> np.ndarray:
        """`pack` of K times (K,) and the values of each (K, floats): the bytes (K, size)."""
        return self.layout.pack_rows(ENCAPSULATION, *stamps(t_ns), *self._frame, values)


class Vector3Stamped(_Stamped):
    """geometry_msgs/Vector3Stamped: pack(t_ns, x, y, z)."""

    def __init__(self, frame: str = WORLD_FRAME) -> None:
        super().__init__(3, frame)


class AttitudeSetpoint(_Stamped):
    """multilift_msgs/AttitudeSetpoint: pack(t_ns, roll, pitch, yaw, thrust)."""

    def __init__(self, frame: str) -> None:
        super().__init__(4, frame)


class TrackingReference(_Stamped):
    """multilift_msgs/TrackingReference: pack(t_ns, position (3), velocity (3),
    acceleration (3))."""

    def __init__(self, frame: str = WORLD_FRAME) -> None:
        super().__init__(9, frame)


class FloatSequences:
    """A header then float64[] fields of fixed lengths `lengths` (FormationState: tension, g,
    g_dot; VirtualConstraintError: error, error_rate): pack(t_ns, *sequences)."""

    def __init__(self, lengths: Sequence[int], frame: str = WORLD_FRAME) -> None:
        layout, self._frame = header_layout(frame)
        for length in lengths:
            layout.primitive('I')
            layout.primitive('d', length)
        self._lengths = tuple(lengths)
        self.layout, self._struct = layout, layout.compile()

    def pack(self, t_ns: int, *sequences: Sequence[float]) -> bytes:
        return self._struct.pack(*self._arguments(t_ns, sequences))

    def pack_rows(self, t_ns: np.ndarray, *sequences: np.ndarray) -> np.ndarray:
        """`pack` of K times (K,) and each sequence's K rows (K, length): bytes (K, size)."""
        return self.layout.pack_rows(*self._arguments(t_ns, sequences, rows=True))

    def _arguments(self, t_ns, sequences: Sequence, rows: bool = False) -> list:
        """`pack`'s arguments; with `rows`, of K messages (`pack_rows`'s columns)."""
        args = [ENCAPSULATION, *(stamps(t_ns) if rows else stamp(t_ns)), *self._frame]
        for length, values in zip(self._lengths, sequences, strict=True):
            given = values.shape[1] if rows else len(values)
            if given != length:
                raise ValueError(f'a sequence of {given} values for a layout of {length}')
            args.append(length)
            if rows:
                args.append(values)
            else:
                args.extend(values)
        return args


class FormationState(FloatSequences):
    """multilift_msgs/FormationState of n cables: pack(t_ns, tension, g, g_dot, taut)."""

    def __init__(self, n: int, frame: str = WORLD_FRAME) -> None:
        super().__init__((n, n, n), frame)
        self.layout.primitive('I')
        self.layout.primitive('?', n)
        self._struct = self.layout.compile()
        self._n = n

    def pack(self, t_ns: int, tension: Sequence[float], g: Sequence[float],
             g_dot: Sequence[float], taut: Sequence[bool]) -> bytes:
        if len(taut) != self._n:
            raise ValueError(f'{len(taut)} taut flags for {self._n} cables')
        args = self._arguments(t_ns, (tension, g, g_dot))
        return self._struct.pack(*args, self._n, *(bool(v) for v in taut))

    def pack_rows(self, t_ns: np.ndarray, tension: np.ndarray, g: np.ndarray,
                  g_dot: np.ndarray, taut: np.ndarray) -> np.ndarray:
        """`pack` of K times (K,) and K rows (K, n) of each: the bytes (K, size)."""
        args = self._arguments(t_ns, (tension, g, g_dot), rows=True)
        return self.layout.pack_rows(*args, self._n, np.asarray(taut, dtype=bool))


class FormationEvent:
    """multilift_msgs/FormationEvent: pack(t_ns, *msgvalues.formation_event(row)). Its strings
    differ from event to event, so each message compiles its own layout (events are rare;
    `layout`: the last one)."""

    def __init__(self, frame: str = WORLD_FRAME) -> None:
        self._frame = frame

    def pack(self, t_ns: int, kind: str, uav: int, rotor: int, value: float,
             scheduled_time: float, description: str) -> bytes:
        layout, frame = header_layout(self._frame)
        kind_bytes = layout.string(kind)
        layout.primitive('I', 2)
        layout.primitive('d', 2)
        text = layout.string(description)
        self.layout = layout
        return layout.compile().pack(ENCAPSULATION, *stamp(t_ns), *frame, len(kind_bytes) + 1,
                                     kind_bytes, uav, rotor, value, scheduled_time,
                                     len(text) + 1, text)


def formation_state(n: int) -> FormationState:
    """multilift_msgs/FormationState of n cables."""
    return FormationState(n)


def virtual_constraint_error(m: int) -> FloatSequences:
    """multilift_msgs/VirtualConstraintError of m constraints."""
    return FloatSequences((m, m))


class FormationSnapshot:
    """multilift_msgs/FormationSnapshot of UAVs with `rotor_counts` rotors:
    pack(t_ns, *msgvalues.formation_snapshot(...)), the previous rotor speeds empty at t = 0
    or one per rotor."""

    def __init__(self, rotor_counts: Sequence[int], frame: str = WORLD_FRAME) -> None:
        n = len(rotor_counts)
        self._counts = tuple(int(c) for c in rotor_counts)
        self._rows = 3 * n
        self._structs = {}
        for previous in (0, sum(self._counts)):
            layout, self._frame = header_layout(frame)
            for _ in range(4):                 # position, velocity, euler, body_rates
                layout.primitive('I')
                layout.primitive('d', 3 * n)
            layout.primitive('d', 6)           # payload position, velocity (float64[3] each)
            layout.primitive('I')
            layout.primitive('I', n)           # rotor_count
            layout.primitive('I')
            layout.primitive('d', previous)    # previous_rotor_speeds
            self._structs[previous] = (layout, layout.compile())

    def layout(self, previous: int) -> Layout:
        return self._structs[previous][0]

    def pack(self, t_ns: int, position: Sequence[float], velocity: Sequence[float],
             euler: Sequence[float], body_rates: Sequence[float],
             payload_position: Sequence[float], payload_velocity: Sequence[float],
             previous: Sequence[float]) -> bytes:
        rows = self._rows
        for values in (position, velocity, euler, body_rates):
            if len(values) != rows:
                raise ValueError(f'{len(values)} values for {rows} (3 per UAV)')
        # one conversion to Python floats (unpacking numpy arrays element by element is slow)
        return self.pack_row(t_ns, np.concatenate((position, velocity, euler, body_rates,
                                                   payload_position, payload_velocity,
                                                   previous)).tolist(), len(previous))

    def pack_row(self, t_ns: int, row: Sequence[float], previous: int) -> bytes:
        """`pack` of its numbers in one row (position, velocity, euler, body_rates, payload
        position, payload velocity, then the `previous` rotor speeds)."""
        entry = self._structs.get(previous)
        if entry is None:
            raise ValueError(f'{previous} previous rotor speeds for rotor counts '
                             f'{self._counts}')
        r = rows = self._rows
        if len(row) != 4 * rows + 6 + previous:
            raise ValueError(f'{len(row)} values for {rows} per field (3 per UAV), 6 of the '
                             f'payload and {previous} rotor speeds')
        return entry[1].pack(ENCAPSULATION, *stamp(t_ns), *self._frame, r, *row[:r],
                             r, *row[r:2 * r], r, *row[2 * r:3 * r], r, *row[3 * r:4 * r],
                             *row[4 * r:4 * r + 6], len(self._counts), *self._counts,
                             previous, *row[4 * r + 6:])

    def pack_rows(self, t_ns: np.ndarray, rows: np.ndarray, previous: int) -> np.ndarray:
        """`pack_row` of K times (K,) and rows (K, 12 n + 6 + previous): bytes (K, size)."""
        layout = self._structs[previous][0]
        r = self._rows
        if rows.shape[1] != 4 * r + 6 + previous:
            raise ValueError(f'{rows.shape[1]} values for {r} per field (3 per UAV), 6 of the '
                             f'payload and {previous} rotor speeds')
        return layout.pack_rows(ENCAPSULATION, *stamps(t_ns), *self._frame, r, rows[:, :r],
                                r, rows[:, r:2 * r], r, rows[:, 2 * r:3 * r], r,
                                rows[:, 3 * r:4 * r], rows[:, 4 * r:4 * r + 6],
                                len(self._counts), *self._counts, previous,
                                rows[:, 4 * r + 6:])

    def unpack(self, data: bytes) -> tuple[int, np.ndarray, np.ndarray, np.ndarray,
                                           np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The inverse of `pack` for this formation: (t_ns, position, velocity, euler,
        body_rates (3n,) each, payload position, payload velocity (3,), previous rotor
        speeds (every rotor's, or empty at t = 0)); ValueError when `data` is not such a
        message (another formation's: other UAV or rotor counts)."""
        for _, packer in self._structs.values():
            if len(data) == packer.size:
                values = packer.unpack(data)
                break
        else:
            raise ValueError(f'a FormationSnapshot of {len(data)} bytes is not one of '
                             f'{len(self._counts)} UAVs with {self._counts} rotors')
        if values[0] != ENCAPSULATION:
            raise ValueError(f'a FormationSnapshot with encapsulation {values[0]!r} '
                             '(expected CDR little endian)')
        k, rows, arrays = 5, self._rows, []
        for name in ('position', 'velocity', 'euler', 'body_rates'):
            if values[k] != rows:
                raise ValueError(f'FormationSnapshot.{name} has {values[k]} values where '
                                 f'{len(self._counts)} UAVs have {rows}')
            arrays.append(np.array(values[k + 1:k + 1 + rows]))
            k += 1 + rows
        arrays += [np.array(values[k:k + 3]), np.array(values[k + 3:k + 6])]
        k += 6
        counts = values[k + 1:k + 1 + values[k]]
        if counts != self._counts:
            raise ValueError(f'FormationSnapshot.rotor_count {list(counts)} where this '
                             f'formation has {list(self._counts)}')
        k += 1 + values[k]
        if values[k] != len(values) - k - 1:
            raise ValueError(f'FormationSnapshot.previous_rotor_speeds has {values[k]} values '
                             f'where this formation has {len(values) - k - 1}')
        arrays.append(np.array(values[k + 1:]))
        return (values[1] * 1_000_000_000 + values[2], *arrays)


class RotorCommand:
    """multilift_msgs/RotorCommand of `n_rotors` rotors: pack(t_ns, speeds, saturated)."""

    def __init__(self, n_rotors: int, frame: str) -> None:
        layout, self._frame = header_layout(frame)
        layout.primitive('I')
        layout.primitive('d', n_rotors)
        layout.primitive('I')
        layout.primitive('?', n_rotors)
        self._n = n_rotors
        self.layout, self._struct = layout, layout.compile()

    def pack(self, t_ns: int, speeds: Sequence[float], saturated: Sequence[bool]) -> bytes:
        return self._struct.pack(ENCAPSULATION, *stamp(t_ns), *self._frame, self._n, *speeds,
                                 self._n, *saturated)

    def pack_rows(self, t_ns: np.ndarray, speeds: np.ndarray, saturated: np.ndarray
                  ) -> np.ndarray:
        """`pack` of K times (K,), speeds and saturation (K, n_rotors): bytes (K, size)."""
        return self.layout.pack_rows(ENCAPSULATION, *stamps(t_ns), *self._frame, self._n,
                                     speeds, self._n, np.asarray(saturated, dtype=bool))
