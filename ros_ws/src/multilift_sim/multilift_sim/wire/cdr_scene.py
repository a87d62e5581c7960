"""CDR of the scene's messages, packed without rclpy as `cdr`'s packers are: /tf (every
frame's transform) and /visualization/markers (the formation drawn, `wire.scene`'s specs).
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from multilift_sim.wire.cdr_layout import ENCAPSULATION, Layout
from multilift_sim.wire.msgvalues import WORLD_FRAME, stamp, stamps
from multilift_sim.wire.scene import MarkerSpec


class TFMessage:
    """tf2_msgs/TFMessage of one TransformStamped per child frame, each from `frame` (or from
    its entry of `parents`): pack(t_ns, translations, rotations), one (x, y, z) and one
    (x, y, z, w) per child."""

    def __init__(self, children: Sequence[str], frame: str = WORLD_FRAME,
                 parents: Sequence[str] | None = None) -> None:
        layout = Layout()
        layout.primitive('I')
        self._names = []
        for k, child in enumerate(children):
            frame_data = layout.header(frame if parents is None else parents[k])
            child_data = layout.string(child)
            layout.primitive('d', 7)
            self._names.append((len(frame_data) + 1, frame_data, len(child_data) + 1,
                                child_data))
        self.layout, self._struct = layout, layout.compile()

    def pack(self, t_ns: int, translations: Sequence[Sequence[float]],
             rotations: Sequence[Sequence[float]]) -> bytes:
        sec, nanosec = stamp(t_ns)
        args = [ENCAPSULATION, len(self._names)]
        for (flen, fdata, clen, cdata), translation, rotation in zip(
                self._names, translations, rotations, strict=True):
            args += (sec, nanosec, flen, fdata, clen, cdata, *translation, *rotation)
        return self._struct.pack(*args)

    def pack_rows(self, t_ns: np.ndarray, translations: np.ndarray, rotations: np.ndarray
                  ) -> np.ndarray:
        """`pack` of K times (K,), translations (K, children, 3) and rotations (K, children,
        4): the messages' bytes (K, size)."""
        sec, nanosec = stamps(t_ns)
        args = [ENCAPSULATION, len(self._names)]
        for k, (flen, fdata, clen, cdata) in enumerate(self._names):
            args += (sec, nanosec, flen, fdata, clen, cdata, translations[:, k],
                     rotations[:, k])
        return self.layout.pack_rows(*args)


class MarkerArray:
    """visualization_msgs/MarkerArray of `specs` (scene.MarkerSpec; their names, types and
    point counts fix the layout, their other values are read at every `pack`), frame `frame`."""

    def __init__(self, specs: Sequence[MarkerSpec], frame: str = WORLD_FRAME) -> None:
        layout = Layout()
        layout.primitive('I')
        self._specs = list(specs)
        self._constant = []  # per marker: (frame length, frame, ns length, ns, id, type, action)
        for spec in self._specs:
            frame_data = layout.header(frame)
            ns_data = layout.string(spec.ns)
            layout.primitive('i', 3)           # id, type, action
            layout.primitive('d', 10)          # pose (7), scale (3)
            layout.primitive('f', 4)           # color
            layout.zeros('i', 2)               # lifetime
            layout.zeros('?')                  # frame_locked
            layout.primitive('I')              # points
            layout.primitive('d', 3 * len(spec.points))
            layout.zeros('I')                  # colors: empty
            layout.string('')                  # texture_resource
            layout.zeros('i', 2)               # texture.header.stamp
            layout.string('')                  # texture.header.frame_id
            layout.string('')                  # texture.format
            layout.zeros('I')                  # texture.data: empty
            layout.zeros('I')                  # uv_coordinates: empty
            layout.string('')                  # text
            layout.string('')                  # mesh_resource
            layout.string('')                  # mesh_file.filename
            layout.zeros('I')                  # mesh_file.data: empty
            layout.zeros('?')                  # mesh_use_embedded_materials
            self._constant.append((len(frame_data) + 1, frame_data, len(ns_data) + 1, ns_data))
        self.layout, self._struct = layout, layout.compile()

    def pack(self, t_ns: int) -> bytes:
        """The array of the specs' current values, every marker stamped t_ns."""
        sec, nanosec = stamp(t_ns)
        args = [ENCAPSULATION, len(self._specs)]
        empty = (1, b'')
        for spec, (flen, fdata, nlen, ndata) in zip(self._specs, self._constant):
            args += (sec, nanosec, flen, fdata, nlen, ndata, spec.id, spec.type, spec.action,
                     *spec.position, *spec.orientation, *spec.scale, *spec.color,
                     len(spec.points))
            for point in spec.points:
                args += point
            args += empty  # texture_resource
            args += empty  # texture.header.frame_id
            args += empty  # texture.format
            args += empty  # text
            args += empty  # mesh_resource
            args += empty  # mesh_file.filename
        return self._struct.pack(*args)
