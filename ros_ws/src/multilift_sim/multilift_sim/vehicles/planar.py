"""The seed's planar multirotors (Eq. 2.11-2.13): n_r rotors evenly around the centre on arms
of length l_r, "+" (rotor 1 at the front) or "x" (rotor 1 half a spacing clockwise of it), the
rotors' spins alternating from clockwise. Rotor numbering and spins: docs/conventions.md; the
seed's Table 2.1 print is garbled, so the geometry is built, not copied."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PlanarFrame:
    """n_rotors rotors on a circle of radius l_r, arm angles offset by xi_c [rad]."""
    NAME: str
    n_rotors: int
    arm_offset: float               # xi_c [rad]: "+" 0, "x" pi / n_r

    @property
    def SPINS(self) -> tuple[int, ...]:  # noqa: N802 (a frame's declared name)
        """+1 (clockwise seen from above) for odd k, -1 for even k."""
        return tuple(1 if k % 2 == 0 else -1 for k in range(self.n_rotors))

    def rotor_positions(self, arm_length: float) -> np.ndarray:
        """Rotor hubs [m], body FLU, (n_r, 3): rotor k (row k - 1) at arm angle xi_k =
        2 pi (k - 1) / n_r + xi_c measured clockwise seen from above, at
        l_r (cos xi_k, -sin xi_k, 0). Departure from the print: seed Eq. 2.11 writes
        2 pi i / n_r, which would put rotor 1 a full spacing past the front; k - 1 makes
        rotor 1 the front ("+") or front-right ("x") one, as the Q+ row of Table 2.1."""
        arm_angle = 2.0 * np.pi * np.arange(self.n_rotors) / self.n_rotors + self.arm_offset
        return arm_length * np.stack(
            [np.cos(arm_angle), -np.sin(arm_angle), np.zeros(self.n_rotors)], axis=1)


FRAMES = tuple(PlanarFrame(f'{name}_{layout}', n, 0.0 if layout == 'plus' else math.pi / n)
               for name, n in (('quad', 4), ('hexa', 6), ('octo', 8))
               for layout in ('plus', 'x'))
