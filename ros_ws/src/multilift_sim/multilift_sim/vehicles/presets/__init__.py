"""Vehicle presets as registered parts (issue 34 item 4): `VEHICLE_PRESETS` (the scenario's
`vehicle.preset` -> its module) is the one registry validation reads
(`scenario.vehicle.vehicle_params`): the preset's values fill every `vehicle` key the scenario
does not give; a key given overrides the preset. Without `preset` every key is given, as before.

A preset (a module, or any object, with these names) declares:
- `NAME`: the scenario's `vehicle.preset`;
- `VALUES`: the `vehicle` keys (`scenario.VEHICLE_KEYS`, SI units) -> values; optionally
  `inertia_source` (`seed`: the seed's printed inertia kept on purpose).
Shipped: `table_4_2` (the seed's Table 4.2 vehicle, as every shipped scenario writes it out) and
`crazyflie_2_1` (Bitcraze's Crazyflie 2.1, its sources in its module).
"""
from __future__ import annotations

from types import ModuleType

from multilift_sim.registry import Registry
from multilift_sim.vehicles.presets import crazyflie_2_1, table_4_2

SHIPPED: tuple[ModuleType, ...] = (table_4_2, crazyflie_2_1)
VEHICLE_PRESETS = Registry('vehicle preset', ('NAME', 'VALUES'), SHIPPED)
register, unregister, registered = (VEHICLE_PRESETS.register, VEHICLE_PRESETS.unregister,
                                    VEHICLE_PRESETS.registered)
