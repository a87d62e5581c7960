#!/usr/bin/env python3
"""Wall time of the formation DAE alone: RK4 at dt = 1 ms, rotor speeds held at hover, the
Table 4.2 vehicle, payload drag and the two Sec. 4.2 gusts on, for n = 1, 3 and 10 UAVs with
the physics compiled and uncompiled (MULTILIFT_KERNEL=jit, python), one `step` call per RK4
step. Prints wall seconds per simulated second and the wall time of a 120 s single-lift run at
1 kHz (compiled).

Run: source scripts/env.sh && python benchmarks/formation_dynamics.py
"""
from __future__ import annotations

import math
import os
import platform
import time

import numpy as np

from multilift_sim.wind.gusts import Gust
from multilift_sim.dynamics import FormationModel
from multilift_sim.formation_params import FormationParams
from multilift_sim.multirotor import MultirotorParams

DT = 1e-3
UAV = MultirotorParams(mass=2.5, inertia=(0.957, 0.486, 0.355), frame_type='quad_x',
                       arm_length=0.2, thrust_coefficient=1.83e-6, moment_coefficient=1.85e-7,
                       rotor_speed_min=0.0, rotor_speed_max=2100.0)
GUSTS = (Gust(center=(-4.0, 6.0), direction=(0.0, -1.0, 0.0), gradient_distance=2.0,
              reference_speed=3.0),
         Gust(center=(-12.0, 6.0), direction=(1.0, 0.0, 0.0), gradient_distance=2.0,
              reference_speed=3.0))


def formation(n: int) -> tuple[FormationModel, np.ndarray, list[np.ndarray]]:
    """n UAVs on a cone of 10.26 m cables above a 0.8 kg payload, released at rest."""
    model = FormationModel(FormationParams(
        uavs=(UAV,) * n, cable_lengths=(10.26,) * n, payload_mass=0.8,
        payload_drag_coefficient=0.12, gusts=GUSTS, baumgarte_alpha=20.0, baumgarte_beta=20.0))
    cone = math.radians(20.0) if n > 1 else math.radians(10.0)
    azimuths = 2 * math.pi * np.arange(n) / n
    directions = np.stack([math.sin(cone) * np.cos(azimuths), math.sin(cone) * np.sin(azimuths),
                           np.full(n, math.cos(cone))], axis=1)
    payload = np.array([-4.0, 5.0, 2.0])
    x = model.layout.pack(payload + 10.26 * directions, np.zeros((n, 3)), payload)
    hover = math.sqrt((UAV.mass + 0.8 / n) * 9.81 / (4 * UAV.thrust_coefficient))
    return model, x, [np.full(4, hover)] * n


def wall_per_simulated_second(n: int, seconds: float, kernel: str = 'jit') -> float:
    os.environ['MULTILIFT_KERNEL'] = kernel
    model, x, speeds = formation(n)
    model.step(0.0, x, speeds, DT)  # compile or load
    steps = int(round(seconds / DT))
    start = time.perf_counter()
    for k in range(steps):
        x = model.step(k * DT, x, speeds, DT)
    elapsed = time.perf_counter() - start
    assert np.all(np.isfinite(x))
    return elapsed / seconds


def main() -> None:
    print(f'{platform.processor() or platform.machine()}, Python {platform.python_version()}, '
          f'numpy {np.__version__}; RK4, dt = {DT * 1e3:g} ms')
    for n in (1, 3, 10):
        for kernel in ('jit', 'python'):
            seconds = 5.0 if kernel == 'jit' else 0.5
            print(f'n = {n:2d}, MULTILIFT_KERNEL={kernel:6s}: '
                  f'{wall_per_simulated_second(n, seconds, kernel):.3f} wall s per simulated s')
    start = time.perf_counter()
    wall_per_simulated_second(1, 120.0)
    print(f'single lift, 120 s at 1 kHz: {time.perf_counter() - start:.1f} s wall')


if __name__ == '__main__':
    main()
