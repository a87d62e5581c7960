"""The registered sensor models compiled into the one tick: their dispatcher
`measure_sensor(model, constants, draws, memory, tick, truth, received)`, one branch per model
calling its module's `measure`, generated from the registry (`multilift_sim.part_dispatch`:
the file under numba's cache folder, the cache folder of a registry with other models, the
loaded callers recompiled), which `sensing.sensed_states` calls by its global
`measure_sensor`.
"""
from __future__ import annotations

from typing import Callable

from multilift_sim import part_dispatch
from multilift_sim import sensors as registry

SENSORS = part_dispatch.add(part_dispatch.GeneratedDispatcher(
    label='sensors', function='measure_sensor', selector='model',
    arguments='constants, draws, memory, tick, truth, received', step='measure',
    caller_module='multilift_sim.sensors.sensing', caller='sensed_states',
    parts=lambda: registry.SENSOR_MODELS, shipped=lambda: registry.SHIPPED))


def dispatcher() -> Callable:
    """The registry's compiled `measure_sensor`."""
    return SENSORS.compiled()


def refresh() -> None:
    """After the registry changed (`sensors.register`): see `part_dispatch.refresh`."""
    part_dispatch.refresh(SENSORS)
