"""Sensor models as registered parts (issue 31): one module per model, `SENSOR_MODELS` the
registry (name -> module) that the scenario's validation (`sensors.model`, each model's keys),
the run's arrays (`sensors.arrays`), the physics' tick (`physics.tick.measure`, through
`sensing.sensed_states` and the dispatcher `compiled` generates), the units table and the
summary read; nothing else names a model. docs/extending.md, "A sensor model", adds one.

What a sensor model does: from the true measured state of a UAV (seed Eq. 2.7: position and
velocity [m, m/s] world, ZYX Euler angles [rad], body rates [rad/s] FLU; physics.layout
MEASURED_*) and the run's seeded random stream, what that UAV's controllers read, at its own
rate (`rate`, a divisor of the control rate: a sample every `every` control ticks). A model's
module declares:
- `NAME`, the scenario's `sensors.model`, and `UNITS`, its keys besides the common `model`,
  `rate` [Hz] and `seed` (read for every model by `scenario.parse`), each -> its unit
  (`units.unit_of`; a key two models share has one unit);
- `parse(d) -> settings`: its keys read from `d` (the `sensors:` section's
  `scenario.reading.Section`: `d.non_negative`, `d.number`, `d.count`, `d.vector`, `d.fail` for
  a one-line error naming the key) as a frozen object, `scenario.SensorConfig.settings`;
- its slots, named once in its module: `constants(settings, every) -> (C,)` the row its
  `measure` reads (`every`: control ticks between two samples), `memory(settings) -> (M,)` one
  UAV's memory at the run's start (its held last output, its bias state, a delay line: what
  `measure` keeps from tick to tick), `draws(settings, n_uavs, samples, dt, rng) -> (n_uavs,
  samples, D)` every sample's random numbers drawn from `rng` (numpy.random.Generator seeded
  with `sensors.seed`) in a fixed order before the run (`samples`: one at tick 0 and every
  `every` ticks to the end; `dt` [s] between two), as the turbulence is drawn: one seed, one
  series, in every path;
- `measure(constants, draws, memory, tick, truth, received)`: compiled (`kernels.jit`), the one
  signature of every model: at control tick `tick`, from UAV truth (MEASURED_COLUMNS,) its
  output into received (MEASURED_COLUMNS,): what the controllers read (left as it is, a model
  passes the state through); `draws` (samples, D) and `memory` (M,) that UAV's. It may be
  called more than once at a tick (a snapshot read twice) and must then give the same result.

What it adds to the messages: with any `sensors:` every /uav{i}/measured_odom carries what the
controllers received, and the summary's `seeds` the section's `seed` (`topics`,
`schedules.run_seeds`), whatever the model.

`register` adds one (a test's toy model, at test time: `registered`; a file a scenario names
under `parts:`, in every process that reads it: `multilift_sim.parts`); the compiled dispatcher
follows (`compiled.refresh`).
"""
from __future__ import annotations

import contextlib
from types import ModuleType
from typing import Iterator

from multilift_sim.sensors import measured_state

SHIPPED: tuple[ModuleType, ...] = (measured_state,)
SENSOR_MODELS: dict[str, ModuleType] = {model.NAME: model for model in SHIPPED}
DEFAULT_MODEL = measured_state.NAME  # `sensors:` without `model:`
REQUIRED = ('NAME', 'UNITS', 'parse', 'constants', 'memory', 'draws', 'measure')
COMMON_KEYS = {'model': '', 'rate': 'Hz', 'seed': ''}  # every model's, with their units


def model_index(name: str) -> int:
    """The registry's index of model `name`: what the compiled dispatcher selects by."""
    return list(SENSOR_MODELS).index(name)


def key_units() -> dict[str, str]:
    """Every key `sensors:` may hold under the registry as it is, with its unit ('' none; a
    key two models share has one unit)."""
    units = dict(COMMON_KEYS)
    for model in SENSOR_MODELS.values():
        units.update(model.UNITS)
    return units


def register(model: ModuleType) -> None:
    """Add a sensor model (a module, or any object, with REQUIRED's names) after the others."""
    missing = [name for name in REQUIRED if not hasattr(model, name)]
    if missing:
        raise ValueError(f'sensor model {model!r} lacks {", ".join(missing)}')
    if model.NAME in SENSOR_MODELS:
        raise ValueError(f'sensor model {model.NAME!r} is registered already')
    units = key_units()
    clash = sorted(key for key, unit in model.UNITS.items()
                   if key in COMMON_KEYS or units.get(key, unit) != unit)
    if clash:
        raise ValueError(f'sensor model {model.NAME!r}: keys {clash} are common or another '
                         'model\'s in other units')
    SENSOR_MODELS[model.NAME] = model
    _changed()


def unregister(name: str) -> None:
    """Remove model `name` (one `register` added)."""
    if any(model.NAME == name for model in SHIPPED):
        raise ValueError(f'sensor model {name!r} ships with multilift_sim')
    del SENSOR_MODELS[name]
    _changed()


@contextlib.contextmanager
def registered(model: ModuleType) -> Iterator[ModuleType]:
    """`model` registered for the block (a test's toy model)."""
    register(model)
    try:
        yield model
    finally:
        unregister(model.NAME)


def _changed() -> None:
    from multilift_sim.sensors import compiled  # numba's side, loaded only when models change
    compiled.refresh()
