"""Estimators as registered parts (issue 33 item 2; docs/estimation.md): one module per
estimator, `ESTIMATORS` the registry (name -> module) that the scenario's `estimator:` (its
`model`; `none` or absent: no estimator), the run's arrays (`estimators.arrays`) and the
physics' tick (`physics.tick.measure`, through `estimation.estimated` and the
dispatcher generated from it) read.

An estimator runs on each UAV after its sensors (`multilift_sim.sensors`: those an estimator
reads keep their latest output first in their memory, `sensors.outputs`) and writes what the
controllers receive (the MEASURED_* slots: position, velocity, ZYX Euler angles, body rates)
from its estimate. A module declares:
- `NAME` (the scenario's `estimator.model`) and `UNITS` (its keys -> units);
- `parse(d) -> settings` its keys from the section; `needs(sensor_names) -> str` what it
  lacks of the scenario's sensors ('' none: the scenario's validation fails with it);
- `constants(settings, scenario, rows) -> (C,)` (rows: each sensor's row in the run's sensor
  arrays, by model name), `memory(settings, scenario) -> (M,)` one UAV's at the start;
- `estimate(constants, sensors, memory, tick, received)`, compiled: at control tick `tick`
  from that UAV's sensor memories sensors (K, Ms) into received (MEASURED_COLUMNS,); called
  again at one tick, the same result.
"""
from __future__ import annotations

from multilift_sim.estimators import ekf
from multilift_sim.registry import Registry

NONE = 'none'  # `estimator: none` (or no section): the controllers read their sensors' output


def _changed() -> None:
    from multilift_sim.estimators import estimation  # numba's side
    estimation.ESTIMATORS_DISPATCH.refresh()


ESTIMATORS = Registry('estimator', ('NAME', 'UNITS', 'parse', 'needs', 'constants', 'memory',
                                    'estimate'), (ekf,), changed=_changed)


def estimator_index(name: str) -> int:
    """The registry's index of estimator `name`: what the compiled dispatcher selects by."""
    return list(ESTIMATORS).index(name)
