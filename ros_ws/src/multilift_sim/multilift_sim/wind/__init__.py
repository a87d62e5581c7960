"""The air: the seed's 1-cosine gusts at places (`gusts`, Eq. 2.53-2.55, in the DAE) and wind
models as registered parts (issue 31). `WIND_MODELS` (the name of a subsection of the
scenario's `wind:` -> its module) is the one registry that validation, the units table, the
run's wind series (`schedules.wind_series`: the physics holds each control period's sample on
top of the steady `wind.velocity`) and the summary's seeds read; nothing else names a model.
docs/extending.md, "A wind model", adds one.

A model (a module, or any object, with these names) declares:
- `NAME`: its subsection of `wind:` (e.g. `wind.turbulence`);
- `UNITS`: each of its keys -> its unit (`multilift_sim.units` reads it);
- `parse(section) -> config`: its keys read from the section (`scenario.reading.Section`,
  one-line errors naming the key), as a frozen, picklable value;
- `series(config, scenario, samples, dt) -> (samples, 3)`: the air's velocity [m/s], world,
  uniform in space, at `samples` control ticks dt [s] apart (each held over its period);
- optionally `seed(config) -> int`: the seed its draws come from (the summary records it).
"""
from __future__ import annotations

import contextlib
from types import ModuleType
from typing import Any, Iterator

from multilift_sim.wind import turbulence

REQUIRED = ('NAME', 'UNITS', 'parse', 'series')
SHIPPED: tuple[ModuleType, ...] = (turbulence,)
WIND_MODELS: dict[str, Any] = {model.NAME: model for model in SHIPPED}


def register(model: Any) -> None:
    """Add a wind model (an object with REQUIRED's names)."""
    missing = [name for name in REQUIRED if not hasattr(model, name)]
    if missing:
        raise ValueError(f'wind model {model!r} lacks {", ".join(missing)}')
    if model.NAME in WIND_MODELS or model.NAME == 'velocity':
        raise ValueError(f'wind model {model.NAME!r} is registered already')
    WIND_MODELS[model.NAME] = model


def unregister(name: str) -> None:
    """Remove model `name` (one `register` added)."""
    if any(model.NAME == name for model in SHIPPED):
        raise ValueError(f'wind model {name!r} ships with multilift_sim')
    del WIND_MODELS[name]


@contextlib.contextmanager
def registered(model: Any) -> Iterator[Any]:
    """`model` registered for the block (a test's toy model)."""
    register(model)
    try:
        yield model
    finally:
        unregister(model.NAME)
