"""A scenario's vehicles: the `vehicle` section (shared) and each `uavs[i]`'s overrides, into
MultirotorParams; the seed's printed inertia and the warning for an inertia no rigid body has."""
from __future__ import annotations

import math
from typing import Any

from multilift_sim.vehicles import frame_types
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.scenario.reading import Section


VEHICLE_KEYS = ('mass', 'inertia', 'frame_type', 'arm_length', 'thrust_coefficient',
                'moment_coefficient', 'rotor_speed_min', 'rotor_speed_max',
                'motor_time_constant', 'motor_rate_limit', 'drag_coefficient', 'radius')


def preset_values(sec: Section) -> dict[str, Any] | None:
    """The `vehicle` section's `preset` (multilift_sim.vehicles.presets.VEHICLE_PRESETS): every
    vehicle key's value (the optional ones at their defaults) and `inertia_source`, or None
    without a preset."""
    from multilift_sim.vehicles.presets import VEHICLE_PRESETS
    name = sec.text('preset', None) if sec.has('preset') else None
    if name is None:
        return None
    if name not in VEHICLE_PRESETS:
        raise sec.fail('preset', name, f'must be one of {", ".join(VEHICLE_PRESETS)}')
    values = {'motor_time_constant': 0.0, 'motor_rate_limit': math.inf,
              'drag_coefficient': 0.0, 'inertia_source': 'given'}
    values.update(VEHICLE_PRESETS[name].VALUES)
    values['inertia'] = list(values['inertia'])
    return values


def vehicle_params(sec: Section, base: dict[str, Any] | None) -> MultirotorParams:
    """A MultirotorParams from `sec`, falling back to `base` (the shared `vehicle` section)."""
    def default(key: str) -> Any:
        return ... if base is None else base[key]
    mass = sec.positive('mass', default('mass'))
    inertia = sec.vector('inertia', default('inertia'), check=lambda v: v > 0, rule='must be > 0')
    frame_type = sec.text('frame_type', default('frame_type'), choices=frame_types())
    arm_length = sec.positive('arm_length', default('arm_length'))
    k_t = sec.positive('thrust_coefficient', default('thrust_coefficient'))
    k_d = sec.positive('moment_coefficient', default('moment_coefficient'))
    w_min = sec.non_negative('rotor_speed_min', default('rotor_speed_min'))
    w_max = sec.number('rotor_speed_max', default('rotor_speed_max'), lambda v: v > w_min,
                       f'must be > rotor_speed_min ({w_min})')
    # the rotors' actuators (physics.actuators): optional, the seed's instant rotors by default
    tau = sec.non_negative('motor_time_constant',
                           0.0 if base is None else base['motor_time_constant'])
    rate_default = math.inf if base is None else base['motor_rate_limit']
    rate = sec.raw('motor_rate_limit', None)
    rate = rate_default if rate is None else sec.positive('motor_rate_limit')
    drag = sec.non_negative('drag_coefficient',  # in the wind (issue 21); the seed's: none
                            0.0 if base is None else base['drag_coefficient'])
    radius = sec.non_negative('radius', 0.0 if base is None else base.get('radius', 0.0))
    return MultirotorParams(mass=mass, inertia=inertia, frame_type=frame_type,
                            arm_length=arm_length, thrust_coefficient=k_t,
                            moment_coefficient=k_d, rotor_speed_min=w_min, rotor_speed_max=w_max,
                            motor_time_constant=tau, motor_rate_limit=rate, drag_coefficient=drag,
                            radius=radius)


SEED_INERTIA = (0.957, 0.486, 0.355)  # seed Table 4.1 / 4.2 [kg m^2]
INERTIA_SOURCES = ('given', 'seed')


def inertia_source(sec: Section, inertia: tuple[float, ...], default: str = 'given') -> str:
    """`inertia_source: seed` says the inertia is the seed's printed diag(0.957, 0.486, 0.355),
    which breaks the triangle inequality of a rigid body, kept on purpose: no warning then.
    Any other inertia with it is an error."""
    source = sec.text('inertia_source', default, choices=INERTIA_SOURCES)
    if source == 'seed' and any(abs(x - y) > 1e-12 for x, y in zip(inertia, SEED_INERTIA)):
        raise sec.fail('inertia_source', source, f'says the inertia is the seed\'s '
                       f'{list(SEED_INERTIA)}, but it is {list(inertia)}')
    return source


def inertia_warning(where: str, key: str, inertia: tuple[float, ...],
                    source: str = 'given') -> list[str]:
    a, b, c = inertia
    if source == 'seed':  # the seed's printed value, a documented choice of the file
        return []
    if a + b < c or a + c < b or b + c < a:
        return [f'{where}: {key}: {list(inertia)} breaks the triangle inequality of a rigid '
                'body (the seed\'s own Table 4.1 value does); used as given']
    return []
