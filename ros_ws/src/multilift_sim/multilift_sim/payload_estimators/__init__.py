"""Payload estimators as registered parts (issue 33 item 3; docs/estimation.md): one module per
estimator, `PAYLOAD_ESTIMATORS` the registry (name -> module) that the scenario's
`payload_estimator:` (its `model`; `none` or absent: none), the run's arrays
(`payload_estimators.arrays`) and the physics' tick (`physics.tick.measure`, through
`estimators.estimation.estimated` and the dispatcher generated from it) read.

A payload estimator runs after the UAVs' estimator (`multilift_sim.estimators`) and estimates
the payload's position and velocity from what the UAVs know: their estimates and their
sensors (a cable sensor's direction and tension). A module declares:
- `NAME` (the scenario's `payload_estimator.model`) and `UNITS` (its keys -> units);
- `parse(d) -> settings` its keys; `needs(scenario) -> str` what it lacks of the scenario
  ('' none: the scenario's validation fails with it, one line);
- `constants(settings, scenario, rows) -> (C,)` (rows: each sensor's row in the run's sensor
  arrays, by model name), `memory(settings, scenario) -> (M,)` the formation's at the start,
  its estimate as /payload/estimate carries it first (`estimators.published` slots);
- `estimate(constants, sensors, estimates, memory, tick)`, compiled: at control tick `tick`
  from every UAV's sensor memories sensors (K, n, Ms) and estimates (n, Me: each UAV's
  estimator memory, its published estimate first) into memory; called again at one tick,
  the same result.
"""
from __future__ import annotations

from multilift_sim.payload_estimators import cable_geometry
from multilift_sim.registry import Registry

NONE = 'none'  # `payload_estimator: none` (or no section): the controllers read the payload


def _changed() -> None:
    from multilift_sim.estimators import estimation  # numba's side
    estimation.PAYLOAD_ESTIMATORS_DISPATCH.refresh()


PAYLOAD_ESTIMATORS = Registry('payload estimator', ('NAME', 'UNITS', 'parse', 'needs',
                                                    'constants', 'memory', 'estimate'),
                              (cable_geometry,), changed=_changed)


def payload_estimator_index(name: str) -> int:
    """The registry's index of payload estimator `name`: what the dispatcher selects by."""
    return list(PAYLOAD_ESTIMATORS).index(name)
