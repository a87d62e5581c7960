"""The units of every run statistic (the columns of a `sweep` table, `statistics.summary_row`)
and of every scenario key a sweep can vary (dotted keys as in the YAML: `payload.mass`,
`uavs[1].cable_length`, `sensors.position_noise`): one table, read by `plot-sweep`'s axis
labels, the run summary and the README's sweep columns.

`unit_of(name)` takes a column or a key, indexed or not (`uavs[2].cable_length`,
`mission.segments[0].velocity`), or a per-UAV / per-cable statistic column (`uav2_saturated_time`,
`cable1_slack_time`, `saturated_time[2]`); a name not in the table is a `KeyError`, so a new
statistic or key without a unit fails the tests (tests/unit/test_units.py). `NO_UNIT` ('') is
the unit of counts, indices, ratios, names and text. SI units, world frame; angles given in
degrees where the key says `_deg`.
"""
from __future__ import annotations

import re

from multilift_sim.estimators import ESTIMATORS
from multilift_sim.links.radio import UNITS as LINK_UNITS
from multilift_sim.payload_estimators import PAYLOAD_ESTIMATORS
from multilift_sim.sensors import COMMON_KEYS, SENSOR_MODELS, key_units
from multilift_sim.wind import WIND_MODELS

NO_UNIT = ''

# the sweep table's columns other than the parameters, in the order of the table
# (campaign.table.table_columns): the run's statistics from statistics.summary_row
STATISTIC_UNITS: dict[str, str] = {
    'simulated_time': 's',            # time flown
    'max_abs_g': 'm^2',               # largest |g_i| of a taut cable (constraint residual)
    'max_abs_g_dot': 'm^2/s',         # largest |g_i_dot|
    'max_rotor_speed': 'rad/s',       # over every UAV's rotors
    'saturated_time': 's',            # summed over the UAVs
    'least_thrust_margin': NO_UNIT,   # 1 - u_T / u_T,max, the least over the UAVs and ticks
    'min_tension': 'N',
    'max_tension': 'N',
    'payload_swing_max': 'm',         # horizontal, from the payload's rest place
    'payload_swing_rms': 'm',
    'max_gust_speed': 'm/s',          # met by the payload
    'slack_time': 's',                # summed over the cables
    'compressed_time': 's',           # a rigid cable pushing (T_i < 0)
    'tracking_error_max': 'm',        # the leader against the mission reference
    'tracking_error_rms': 'm',
    # |g_vc| rows of the followers: m for a linear geometry's rows, m^2 for a distance row
    'formation_error_max': 'm or m^2',
    'formation_error_mean': 'm or m^2',
    'least_clearance': 'm',           # of every kind (`world:`, physics.clearance); none: None
    # per cable in the summary, over the cables in a sweep row; None in a run without them
    'max_stretch': 'm',               # elastic ropes' and chain links' L_i - l_i
    'peak_tension': 'N',              # elastic ropes' and elastic chains' at the UAV
    'max_sag': 'm',                   # a chain's inner node's largest distance from its chord
    'shortest_cable': 'm',            # a winch's reeled length, least and largest
    'longest_cable': 'm',
}

TABLE_UNITS: dict[str, str] = {
    'run': NO_UNIT, 'seed': NO_UNIT, 'status': NO_UNIT, 'message': NO_UNIT, 'bag': NO_UNIT,
    'wall_time': 's',                 # the run's own flight, `campaign.runs`
}

# the keys of `vehicle:`, which each `uavs[i]` entry may override
VEHICLE_UNITS: dict[str, str] = {
    'mass': 'kg', 'inertia': 'kg m^2', 'inertia_source': NO_UNIT, 'frame_type': NO_UNIT,
    'arm_length': 'm', 'thrust_coefficient': 'N s^2/rad^2', 'moment_coefficient': 'N m s^2/rad^2',
    'rotor_speed_min': 'rad/s', 'rotor_speed_max': 'rad/s', 'motor_time_constant': 's',
    'motor_rate_limit': 'rad/s^2', 'drag_coefficient': 'N s^2/m^2', 'radius': 'm',
}

# an elastic rope's keys (`cable:` and `uavs[i].cable:`, multilift_sim.cables.elastic)
ROPE_UNITS = {'stiffness': 'N/m', 'axial_stiffness': 'N', 'damping': 'N s/m'}
# a heavy cable's keys (`cable:`, multilift_sim.cables.chain)
CHAIN_UNITS = {'links': '', 'mass_per_length': 'kg/m', 'drag_coefficient': '',
               'diameter': 'm'}
# a winch's keys (`uavs[i].winch`, multilift_sim.cables.winch)
WINCH_UNITS = {'rate_limit': 'm/s', 'acceleration_limit': 'm/s^2', 'min_length': 'm',
               'max_length': 'm'}

GAINS = {'position_gains.kp': '1/s^2', 'position_gains.kd': '1/s', 'position_gains.ki': '1/s^3',
         'attitude_gains.kp': '1/s^2', 'attitude_gains.kd': '1/s'}

# scenario keys (the YAML's, `scenario.parse`), list indices as []
SCENARIO_UNITS: dict[str, str] = {
    # lists of mappings set whole (`--set gusts=[]`): no one unit
    'uavs': NO_UNIT, 'gusts': NO_UNIT, 'events': NO_UNIT, 'mission.segments': NO_UNIT,
    'name': NO_UNIT, 'description': NO_UNIT, 'frame': NO_UNIT, 'cable_model': NO_UNIT,
    'cable_length': 'm',
    'simulation.duration': 's', 'simulation.physics_rate': 'Hz', 'simulation.control_rate': 'Hz',
    'simulation.gravity': 'm/s^2', 'simulation.baumgarte_alpha': '1/s',
    'simulation.baumgarte_beta': '1/s', 'simulation.constraint_tolerance': 'm^2',
    'simulation.constraint_rate_tolerance': 'm^2/s', 'simulation.command_timeout': 's',
    'simulation.integrator': NO_UNIT, 'simulation.substeps': NO_UNIT,
    **{f'{where}cable.{k}': u for where in ('', 'uavs[].') for k, u in ROPE_UNITS.items()},
    **{f'cable.{k}': u for k, u in CHAIN_UNITS.items()},
    **{f'vehicle.{k}': u for k, u in VEHICLE_UNITS.items()},
    **{f'uavs[].{k}': u for k, u in VEHICLE_UNITS.items()},
    'uavs[].cable_length': 'm', 'uavs[].position': 'm', 'uavs[].yaw': 'rad',
    'uavs[].attach_point': 'm', 'uavs[].trajectory': NO_UNIT,
    **{f'uavs[].winch.{k}': u for k, u in WINCH_UNITS.items()},
    'payload.type': NO_UNIT, 'payload.mass': 'kg', 'payload.drag_coefficient': 'kg/m',
    'payload.alpha_deg': 'deg', 'payload.beta_deg': 'deg', 'payload.swing_deg': 'deg',
    'payload.shape': NO_UNIT, 'payload.size': 'm', 'payload.inertia': 'kg m^2',
    'payload.attach_points': 'm', 'payload.initial_position': 'm',
    'payload.initial_velocity': 'm/s', 'payload.radius': 'm',
    'world.ground': 'm', 'world.on_contact': NO_UNIT, 'world.obstacles': NO_UNIT,
    'world.obstacles[].type': NO_UNIT, 'world.obstacles[].name': NO_UNIT,
    'world.obstacles[].center': 'm', 'world.obstacles[].size': 'm',
    'world.obstacles[].radius': 'm', 'world.obstacles[].height': 'm',
    'world.obstacles[].yaw': 'rad',
    'gusts[].center': 'm', 'gusts[].direction': NO_UNIT, 'gusts[].gradient_distance': 'm',
    'gusts[].reference_speed': 'm/s',
    'wind.velocity': 'm/s',  # a wind model's keys: its UNITS (multilift_sim.wind)
    'formation.n': NO_UNIT, 'formation.geometry': NO_UNIT, 'formation.offsets': 'm',
    'formation.distance': 'm', 'formation.half_angle_deg': 'deg', 'formation.alpha_vc': '1/s',
    'formation.beta_vc': '1/s', 'formation.reorganize': NO_UNIT, 'formation.min_spacing': 'm',
    'formation.max_spread': 'm', 'formation.max_offset_rate': 'm/s',
    'formation.thrust_margin_floor': NO_UNIT,  # a share of the largest thrust
    'formation.start_places': 'm',  # each follower's [x, y] from the leader at the start
    'control.mode': NO_UNIT, 'control.follower': NO_UNIT,
    'control.constant_rotor_speed': 'rad/s',
    **{f'control.{k}': u for k, u in GAINS.items()},
    'control.max_tilt_deg': 'deg',
    'control.payload_feedback.swing_stiffness': '1/s^2',
    'control.payload_feedback.swing_damping': '1/s',
    'control.payload_feedback.acceleration_limit': 'm/s^2',
    'control.payload_feedback.input_shaping': NO_UNIT,
    'mission.start': 'm', 'mission.reference_filter_time': 's',
    'mission.segments[].velocity': 'm/s', 'mission.segments[].duration': 's',
    'mission.segments[].until': 's',
    'vehicle.preset': NO_UNIT, 'mission.type': NO_UNIT, 'mission.tracks': NO_UNIT,
    'mission.file': NO_UNIT,
    'mission.waypoints': NO_UNIT, 'mission.waypoints[].time': 's',
    'mission.waypoints[].position': 'm', 'mission.waypoints[].yaw': 'rad',
    'events[].time': 's', 'events[].type': NO_UNIT, 'events[].uav': NO_UNIT,
    'events[].rotor': NO_UNIT, 'events[].effectiveness': NO_UNIT, 'events[].duration': 's',
    'events[].velocity': 'm/s', 'events[].rate': 'm/s',
    **LINK_UNITS,
}

UNITS: dict[str, str] = {**TABLE_UNITS, **STATISTIC_UNITS, **SCENARIO_UNITS}

_INDEX = re.compile(r'\[\d+\]')
_WIND_KEY = re.compile(r'^wind\.(\w+)\.(\w+)(?:\[\])?$')  # wind.<model>.<key>
# a statistic of one UAV, cable or follower: uav2_saturated_time, cable1.slack_time, ...
_PER_PART = re.compile(r'^(?:uav|cable|follower)\d+[._](.+)$')


def unit_of(name: str) -> str:
    """The unit of a sweep column or scenario key (`NO_UNIT` for counts, names and ratios);
    KeyError for one the table does not know."""
    key = _INDEX.sub('[]', name)
    if key in UNITS:
        return UNITS[key]
    section, _, sensor_key = key.partition('.')
    if section == 'sensors' and sensor_key in key_units():  # the registered models' keys
        return key_units()[sensor_key]
    own = ({**COMMON_KEYS, **SENSOR_MODELS[section].UNITS} if section in SENSOR_MODELS
           else {})  # a sensor of its own section (`imu:`, `mocap:`)
    if sensor_key in own:
        return own[sensor_key]
    if key in ('estimator', 'estimator.model'):
        return NO_UNIT
    if section == 'estimator' and any(sensor_key in e.UNITS for e in ESTIMATORS.values()):
        return next(e.UNITS[sensor_key] for e in ESTIMATORS.values() if sensor_key in e.UNITS)
    if key in ('payload_estimator', 'payload_estimator.model'):
        return NO_UNIT
    if section == 'payload_estimator' and any(sensor_key in e.UNITS
                                              for e in PAYLOAD_ESTIMATORS.values()):
        return next(e.UNITS[sensor_key] for e in PAYLOAD_ESTIMATORS.values()
                    if sensor_key in e.UNITS)
    if key.endswith('[]') and key[:-2] in UNITS:    # one component of a vector key
        return UNITS[key[:-2]]
    model = _WIND_KEY.match(key)
    if model and model.group(1) in WIND_MODELS and model.group(2) in \
            WIND_MODELS[model.group(1)].UNITS:
        return WIND_MODELS[model.group(1)].UNITS[model.group(2)]
    part = _PER_PART.match(name)
    if part and _INDEX.sub('', part.group(1)) in STATISTIC_UNITS:
        return STATISTIC_UNITS[_INDEX.sub('', part.group(1))]
    stripped = _INDEX.sub('', name)
    if stripped != name and stripped in STATISTIC_UNITS:     # saturated_time[2]
        return STATISTIC_UNITS[stripped]
    raise KeyError(f'{name}: no unit in multilift_sim.units (add the column or key to its '
                   'table)')


def label(name: str) -> str:
    """`name [unit]`, or the name alone when it has no unit or the table does not know it."""
    try:
        unit = unit_of(name)
    except KeyError:
        return name
    return f'{name} [{unit}]' if unit else name
