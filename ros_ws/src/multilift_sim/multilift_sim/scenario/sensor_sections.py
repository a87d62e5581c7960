"""The scenario's sensor sections, validated once: `sensors:` (what the controllers receive,
docs/sensors.md), the sensors of their own sections named as their models (`imu:`, `mocap:`)
and `estimator:`, `payload_estimator:` (docs/estimation.md)."""
from __future__ import annotations

from multilift_sim.estimators import ESTIMATORS, NONE as NONE_ESTIMATOR
from multilift_sim.payload_estimators import PAYLOAD_ESTIMATORS
from multilift_sim.scenario.config import EstimatorConfig, SensorConfig, SimulationConfig
from multilift_sim.scenario.reading import Section
from multilift_sim.sensors import DEFAULT_MODEL, SENSOR_MODELS


def _rate(d: Section, sim: SimulationConfig, default: float) -> float:
    """A sensor's `rate` [Hz], which must divide the control rate (so the physics rate)."""
    control_rate = sim.control_rate
    rate = d.number('rate', default, lambda v: 0 < v <= control_rate,
                    f'must be > 0 and <= simulation.control_rate ({control_rate:g})')
    ratio = control_rate / rate
    if abs(ratio - round(ratio)) > 1e-9:
        raise d.fail('rate', rate, f'must divide simulation.control_rate ({control_rate:g}) '
                     'into a whole number of ticks')
    return rate


def sensors_section(d: Section, sim: SimulationConfig) -> SensorConfig:
    """The `sensors:` section, validated: its model (default DEFAULT_MODEL, one of the
    registry's), the rate (default the control rate, which it must divide) and the seed, which
    every model has, then the model's own keys (its `parse`), nothing else."""
    model = d.text('model', DEFAULT_MODEL, choices=tuple(SENSOR_MODELS))
    rate = _rate(d, sim, sim.control_rate)
    config = SensorConfig(model=model, rate=rate, seed=d.count('seed', 0),
                          settings=SENSOR_MODELS[model].parse(d))
    d.done()
    return config


def sensor_suite(top: Section, sim: SimulationConfig) -> tuple[SensorConfig, ...]:
    """The sensors of their own sections, each named as its model (`imu:`, `mocap:`; any
    registered model but `sensors:`'s default), in the registry's order: its rate (default
    its preset's, else the control rate) and seed, then its keys; a model with
    `with_simulation` given the simulation's (its interval, gravity, latency in ticks)."""
    suite = []
    for name, model in SENSOR_MODELS.items():
        if name == DEFAULT_MODEL or not top.has(name):
            continue
        d = top.section(name)
        preset = (model.preset_values(d) if hasattr(model, 'preset_values') else {})
        rate = _rate(d, sim, preset.get('rate', sim.control_rate))
        every = int(round(sim.control_rate / rate))
        settings = model.parse(d)
        if hasattr(model, 'with_simulation'):
            settings = model.with_simulation(settings, sim, every)
        suite.append(SensorConfig(model=name, rate=rate, seed=d.count('seed', 0),
                                  settings=settings))
        d.done()
    return tuple(suite)


def _named_part(top: Section, key: str, registry) -> tuple[str, Section]:
    """(its name, its section) of `key:` (a name, or a section with `model:` and its keys)
    among `none` and the registry's."""
    if isinstance(top.raw(key), str):
        name = top.text(key, choices=(NONE_ESTIMATOR, *registry))
        return name, Section({}, top.key(key), top.where)
    d = top.section(key)
    return d.text('model', choices=(NONE_ESTIMATOR, *registry)), d


def estimator_section(top: Section, suite: tuple[SensorConfig, ...]) -> EstimatorConfig | None:
    """`estimator:` (a name, or a section with `model:` and its keys): None for `none` or no
    section; an estimator lacking a sensor it reads fails in one line."""
    if not top.has('estimator'):
        return None
    name, d = _named_part(top, 'estimator', ESTIMATORS)
    if name == NONE_ESTIMATOR:
        d.done()
        return None
    part = ESTIMATORS[name]
    missing = part.needs(tuple(c.model for c in suite))
    if missing:
        raise top.fail('estimator', name, missing)
    config = EstimatorConfig(model=name, settings=part.parse(d))
    d.done()
    return config


def payload_estimator_section(top: Section) -> EstimatorConfig | None:
    """`payload_estimator:` (a name, or a section with `model:` and its keys; issue 33 item 3):
    None for `none` or no section. What it needs of the scenario: `check_payload_estimator`."""
    if not top.has('payload_estimator'):
        return None
    name, d = _named_part(top, 'payload_estimator', PAYLOAD_ESTIMATORS)
    config = None if name == NONE_ESTIMATOR else EstimatorConfig(
        model=name, settings=PAYLOAD_ESTIMATORS[name].parse(d))
    d.done()
    return config


def check_payload_estimator(top: Section, scenario) -> None:
    """A payload estimator lacking what it reads of the scenario (its `needs`) fails in one
    line."""
    config = scenario.payload_estimator
    if config is None:
        return
    missing = PAYLOAD_ESTIMATORS[config.model].needs(scenario)
    if missing:
        raise top.fail('payload_estimator', config.model, missing)
