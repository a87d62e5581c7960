#!/usr/bin/env python3
"""How close the payload's path on elastic ropes comes to the rigid cables' (issue 32 item 4):
`twin_lift` (the seed's §4.2 mission, 120 s) flown with `cable_model: elastic`, no rope damping,
for a sweep of axial stiffness EA [N] (k = EA / l_i), each with the sub-steps the validation
asks for; printed: the largest distance [m] between the payload's positions at the same tick
over the whole mission, and where it occurs.

Run: scripts/setup && source scripts/env.sh && python benchmarks/elastic_convergence.py
     [EA ...]
"""
from __future__ import annotations

import sys
import time

import numpy as np
import yaml

from multilift_control.headless import run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario.files import resolve

DEFAULT_EA = (1e5, 1e6, 1e7, 1e8)  # [N]


def twin_lift(axial_stiffness: float | None, duration: float | None = None):
    """twin_lift, its cables elastic of EA = axial_stiffness [N] (None: rigid, as shipped),
    with the sub-steps the validation names."""
    data = yaml.safe_load(resolve('twin_lift').read_text())
    if duration is not None:
        data['simulation']['duration'] = duration
    if axial_stiffness is None:
        return scenario_io.loads(yaml.safe_dump(data))
    data.update(cable_model='elastic', cable={'axial_stiffness': float(axial_stiffness)})
    try:
        return scenario_io.loads(yaml.safe_dump(data))
    except scenario_io.ScenarioError as exc:  # the sub-steps it names
        data['simulation']['substeps'] = int(str(exc).split('substeps >= ')[1].split(' ')[0])
        return scenario_io.loads(yaml.safe_dump(data))


def payload_path(scenario) -> np.ndarray:
    """The payload's position at every tick, (ticks + 1, 3) [m], world."""
    layout = StateLayout(scenario.n_uavs)
    path = []
    run_headless(scenario, on_tick=lambda sim, *_: path.append(
        layout.payload_position(sim.state).copy()))
    return np.array(path)


def deviation(axial_stiffness: float, rigid: np.ndarray, duration: float | None = None
              ) -> tuple[float, float, int]:
    """(max_t |r_p,elastic - r_p,rigid| [m], the time of it [s], sub-steps)."""
    scenario = twin_lift(axial_stiffness, duration)
    gap = np.linalg.norm(payload_path(scenario) - rigid, axis=1)
    return (float(gap.max()), float(np.argmax(gap)) / scenario.simulation.control_rate,
            scenario.simulation.substeps)


def main() -> None:
    values = [float(v) for v in sys.argv[1:]] or DEFAULT_EA
    rigid = payload_path(twin_lift(None))
    print(f'{"EA [N]":>10} {"k [N/m]":>10} {"substeps":>8} {"max gap [m]":>12} {"at [s]":>7} '
          f'{"wall [s]":>8}')
    for value in values:
        start = time.perf_counter()
        gap, when, substeps = deviation(value, rigid)
        print(f'{value:10.3g} {value / 10.26:10.3g} {substeps:8d} {gap:12.3e} {when:7.2f} '
              f'{time.perf_counter() - start:8.2f}', flush=True)


if __name__ == '__main__':
    main()
