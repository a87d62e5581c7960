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

from types import ModuleType
from typing import Any

from multilift_sim.registry import Registry
from multilift_sim.wind import turbulence


def _check_name(model: Any) -> None:
    if model.NAME == 'velocity':  # the steady wind's key
        raise ValueError("wind model 'velocity' is wind.velocity's key")


SHIPPED: tuple[ModuleType, ...] = (turbulence,)
WIND_MODELS = Registry('wind model', ('NAME', 'UNITS', 'parse', 'series'), SHIPPED,
                       check=_check_name)
register, unregister, registered = (WIND_MODELS.register, WIND_MODELS.unregister,
                                    WIND_MODELS.registered)
