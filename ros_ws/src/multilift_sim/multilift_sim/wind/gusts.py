"""Aerodynamic disturbances on the payload: quadratic drag (seed Eq. 2.53) and discrete
1-cosine gusts (seed Eq. 2.55). World frame (z up), SI units.

Departure from the print: Eq. 2.53 writes the drag with the payload's inertial velocity; we use
the air-relative velocity ``v_rel = v_p - w`` (w the gust velocity at the payload), which is how
a gust acts on the payload at all, and equals the print in still air.
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class Gust:
    """A stationary 1-cosine gust (seed Eq. 2.55) centred on a vertical line.

    center: (x, y) of the gust centre [m], world frame.
    direction: unit vector of the gust velocity, world frame (e.g. (0, 0, 1) vertical up).
    gradient_distance: H [m], the horizontal radius beyond which the gust is zero.
    reference_speed: U_ref [m/s], the gust speed at the centre.
    """

    center: tuple[float, float]
    direction: tuple[float, float, float]
    gradient_distance: float
    reference_speed: float

    def __post_init__(self) -> None:
        center = tuple(float(c) for c in self.center)
        direction = tuple(float(c) for c in self.direction)
        if len(center) != 2 or not all(math.isfinite(c) for c in center):
            raise ValueError(f'Gust.center must be a finite (x, y) [m], got {self.center!r}')
        if len(direction) != 3 or abs(math.hypot(*direction) - 1.0) > 1e-9:
            raise ValueError(f'Gust.direction must be a unit 3-vector, got {self.direction!r}')
        if not (math.isfinite(self.gradient_distance) and self.gradient_distance > 0):
            raise ValueError(f'Gust.gradient_distance must be finite and > 0 [m], got '
                             f'{self.gradient_distance!r}')
        if not math.isfinite(self.reference_speed):
            raise ValueError(f'Gust.reference_speed must be finite [m/s], got '
                             f'{self.reference_speed!r}')
        object.__setattr__(self, 'center', center)
        object.__setattr__(self, 'direction', direction)

    def speed(self, position: ArrayLike) -> float:
        """Gust speed U [m/s] at a world position [m] (seed Eq. 2.55).

        r is the horizontal distance from the centre; the height does not matter.
        """
        x, y = float(position[0]), float(position[1])
        radius = math.hypot(x - self.center[0], y - self.center[1])
        if radius > self.gradient_distance:
            return 0.0
        return 0.5 * self.reference_speed * (1.0 + math.cos(math.pi * radius
                                                             / self.gradient_distance))


def gust_velocity(gusts: Iterable[Gust], position: ArrayLike) -> np.ndarray:
    """Air velocity w [m/s] at a world position [m], the sum of every gust; shape (3,)."""
    velocity = np.zeros(3)
    for gust in gusts:
        speed = gust.speed(position)
        if speed != 0.0:
            velocity += speed * np.asarray(gust.direction)
    return velocity


def payload_drag(payload_velocity: ArrayLike, air_velocity: ArrayLike,
                 drag_coefficient: float) -> np.ndarray:
    """Quadratic drag on the payload [N] (seed Eq. 2.53 with air-relative velocity), shape (3,).

    ``d_p = -c_pd v_rel |v_rel|`` with ``v_rel = v_p - w``; payload_velocity v_p and
    air_velocity w [m/s] in the world frame, drag_coefficient c_pd [N s^2/m^2] (it lumps
    1/2 rho C_D A, so the seed's "-" unit is really kg/m).
    """
    relative = np.asarray(payload_velocity, dtype=float) - np.asarray(air_velocity, dtype=float)
    return -drag_coefficient * math.sqrt(float(relative @ relative)) * relative
