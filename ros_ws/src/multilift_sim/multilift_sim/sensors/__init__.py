"""Sensor models as registered parts (issue 31): one module per model, `SENSOR_MODELS` the
registry (name -> module) that the scenario's validation (`sensors.model`, each model's keys),
the run's arrays (`sensors.arrays`), the physics' tick (`physics.tick.measure`, through
`sensing.sensed_states` and the dispatcher generated from it), the units table and the
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
  signature of every model: at control tick `tick`, from UAV truth (SENSED_COLUMNS,: its
  measured state, then its cable's direction and tension, physics.layout SENSED_*) its
  output into received (MEASURED_COLUMNS,): what the controllers read (left as it is, a model
  passes the state through); `draws` (samples, D) and `memory` (M,) that UAV's. It may be
  called more than once at a tick (a snapshot read twice) and must then give the same result.

What it adds to the messages: with any `sensors:` every /uav{i}/measured_odom carries what the
controllers received, and the summary's `seeds` the section's `seed` (`topics`,
`schedules.run_seeds`), whatever the model.

`register` adds one (a test's toy model, at test time: `registered`; a file a scenario names
under `parts:`, in every process that reads it: `multilift_sim.parts`); the compiled dispatcher
follows (`sensing.SENSORS`).
"""
from __future__ import annotations

from types import ModuleType

from multilift_sim.registry import Registry
from multilift_sim.sensors import cable_sensor, gnss, imu, measured_state, mocap

DEFAULT_MODEL = measured_state.NAME  # `sensors:` without `model:`
COMMON_KEYS = {'model': '', 'rate': 'Hz', 'seed': ''}  # every model's, with their units


def key_units() -> dict[str, str]:
    """Every key `sensors:` may hold under the registry as it is, with its unit ('' none; a
    key two models share has one unit)."""
    units = dict(COMMON_KEYS)
    for model in SENSOR_MODELS.values():
        units.update(model.UNITS)
    return units


def _check(model: ModuleType) -> None:
    """A new model's keys are its own or another's in the same units."""
    units = key_units()
    clash = sorted(key for key, unit in model.UNITS.items()
                   if key in COMMON_KEYS or units.get(key, unit) != unit)
    if clash:
        raise ValueError(f'sensor model {model.NAME!r}: keys {clash} are common or another '
                         'model\'s in other units')


def _changed() -> None:
    from multilift_sim.sensors import sensing  # numba's side, loaded only when models change
    sensing.SENSORS.refresh()


SENSOR_MODELS = Registry('sensor model',
                         ('NAME', 'UNITS', 'parse', 'constants', 'memory', 'draws', 'measure'),
                         (measured_state, imu, mocap, gnss, cable_sensor), changed=_changed,
                         check=_check)
register, unregister, registered = (SENSOR_MODELS.register, SENSOR_MODELS.unregister,
                                    SENSOR_MODELS.registered)


def model_index(name: str) -> int:
    """The registry's index of model `name`: what the compiled dispatcher selects by."""
    return list(SENSOR_MODELS).index(name)
