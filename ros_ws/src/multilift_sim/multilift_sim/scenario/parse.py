"""A scenario file's mapping -> `Scenario`, validated once: every section read with checks
(`reading.Section`), the vehicles (`vehicle`), the formation, gusts, wind, sensors, events,
control and mission, then what the rotors cannot lift at all, what the bodies cannot be or the
vehicles cannot fly (`limits`), and what only the Baumgarte DAE models refused under another
formulation."""
from __future__ import annotations

import dataclasses
import math
from typing import Any

from multilift_sim.wind import WIND_MODELS
from multilift_sim.wind.gusts import Gust
from multilift_sim.formation_geometry import hanging_payload, nominal_positions
from multilift_sim.cables import CABLE_MODELS, winch
from multilift_sim.formulations import FORMULATIONS, unsupported
from multilift_sim.payloads import PAYLOAD_TYPES
from multilift_sim.events import EVENT_KINDS
from multilift_sim.scenario.config import (FORMATION_GEOMETRIES,
                                           INPUT_SHAPERS,
                                           ControlConfig, EventConfig, FormationConfig,
                                           PayloadConfig,
                                           Scenario, ScenarioError,
                                           SimulationConfig, UavConfig,
                                           flies_a_period, one_period_rule)
from multilift_sim.scenario.controllers import (DEFAULT_FOLLOWER, follower_controllers,
                                                leader_controllers)
from multilift_sim.scenario.limits import check_limits
from multilift_sim.scenario import reorganize
from multilift_sim.scenario.part_files import scenario_parts
from multilift_sim.scenario.prescribed import (check_prescribed, finite_vector, read_trajectory,
                                               scenario_folder)
from multilift_sim.scenario.reading import Section
from multilift_sim.links import read_comms
from multilift_sim.scenario.sensor_sections import (check_payload_estimator, estimator_section,
                                                    payload_estimator_section, sensor_suite,
                                                    sensors_section)
from multilift_sim.scenario.world import check_start, read_world
from multilift_sim.scenario.vehicle import (SEED_INERTIA, inertia_source, inertia_warning,
                                            preset_values, vehicle_params)


def scenario_of(data: Any, where: str) -> Scenario:
    top = Section(data, '', where)
    parts = scenario_parts(top)  # first: the rest may name what they register
    name = top.text('name')
    description = top.text('description', '')
    top.text('frame', 'world', choices=('world',))
    cable_model = top.text('cable_model', 'rigid', choices=tuple(CABLE_MODELS))
    cables = CABLE_MODELS[cable_model]
    # a slack cable may start with the payload above its UAV (it falls and snaps taut)
    release_limit = cables.RELEASE_LIMIT_DEG
    release_rule = f'must be within (-{release_limit:g}, {release_limit:g}) degrees' + (
        '' if release_limit > 90 else ' (beyond 90 needs cable_model: slack)')

    s = top.section('simulation')
    duration = s.positive('duration')
    physics_rate = s.positive('physics_rate')
    control_rate = s.number('control_rate', ..., lambda v: 0 < v <= physics_rate,
                            f'must be > 0 and <= physics_rate ({physics_rate})')
    if not flies_a_period(duration, control_rate):
        raise s.fail('duration', duration, one_period_rule(control_rate))
    ratio = physics_rate / control_rate
    if abs(ratio - round(ratio)) > 1e-9:
        raise s.fail('control_rate', control_rate,
                     f'must divide physics_rate ({physics_rate}) into a whole number of steps')
    sim = SimulationConfig(
        duration=duration, physics_rate=physics_rate, control_rate=control_rate,
        gravity=s.positive('gravity', 9.81),
        baumgarte_alpha=s.non_negative('baumgarte_alpha'),
        baumgarte_beta=s.non_negative('baumgarte_beta'),
        constraint_tolerance=s.positive('constraint_tolerance'),
        constraint_rate_tolerance=s.positive('constraint_rate_tolerance'),
        command_timeout=s.positive('command_timeout', 5.0),
        integrator=s.text('integrator', 'baumgarte', choices=tuple(FORMULATIONS)),
        substeps=s.number('substeps', 1, lambda v: v >= 1 and v == int(v),
                          'must be an integer >= 1'))
    s.done()
    sim = dataclasses.replace(sim, substeps=int(sim.substeps))

    v = top.section('vehicle')
    preset = preset_values(v)  # vehicle.preset: its values under the keys given
    base_vehicle = dataclasses.asdict(vehicle_params(v, preset))
    base_source = inertia_source(v, tuple(base_vehicle['inertia']),
                                 'given' if preset is None or v.has('inertia')
                                 else preset['inertia_source'])
    v.done()
    warnings = inertia_warning(where, 'vehicle.inertia', tuple(base_vehicle['inertia']),
                               base_source)

    # n comes from formation.n, or from the length of `uavs` (per-UAV overrides), or is 1
    n_formation = None
    if top.has('formation') and isinstance(top.data['formation'], dict) \
            and 'n' in top.data['formation']:
        n_formation = top.data['formation']['n']
        if isinstance(n_formation, bool) or not isinstance(n_formation, int) or n_formation < 1:
            raise ScenarioError(f'{where}: formation.n: {n_formation!r} must be an integer >= 1')
    uav_list = top.raw('uavs', None)
    if uav_list is None:
        uav_list = [{}] * (n_formation or 1)
    if not isinstance(uav_list, list) or not uav_list:
        raise ScenarioError(f'{where}: uavs: {uav_list!r} must be a non-empty list')
    if n_formation is not None and len(uav_list) != n_formation:
        raise ScenarioError(f'{where}: uavs: {len(uav_list)} entries but formation.n is '
                            f'{n_formation}')
    default_cable = top.positive('cable_length') if top.has('cable_length') else ...
    rope = cables.parse_cable(top)  # its `cable:` keys (an elastic rope's), else None
    uavs = []
    for i, entry in enumerate(uav_list):
        u = Section(entry, f'uavs[{i}]', where)
        vehicle = vehicle_params(u, base_vehicle)
        source = inertia_source(u, vehicle.inertia,
                                base_source if vehicle.inertia == SEED_INERTIA else 'given')
        if vehicle.inertia != tuple(base_vehicle['inertia']) or source != base_source:
            warnings += inertia_warning(where, u.key('inertia'), vehicle.inertia, source)
        if i > 0 and u.has('position'):
            raise u.fail('position', u.data['position'],
                         'is not allowed: follower positions come from the formation geometry')
        if u.has('position') and u.has('trajectory'):
            raise u.fail('position', u.data['position'], 'is not allowed with trajectory: '
                         'the file gives the start')
        length = u.positive('cable_length', default_cable)
        stiffness, damping = cables.parse_uav_cable(u, length, rope)
        reel = winch.parse_winch(u, length)
        uavs.append(UavConfig(vehicle=vehicle, cable_length=length,
                              position=u.vector('position', [0.0, 0.0, 0.0]),
                              yaw=u.number('yaw', 0.0),
                              attach_point=u.vector('attach_point', [0.0, 0.0, 0.0]),
                              cable_stiffness=stiffness, cable_damping=damping, winch=reel,
                              trajectory=read_trajectory(u, scenario_folder(where),
                                                         u.number('yaw', 0.0))))
        u.done()

    p = top.section('payload')
    payload_type = PAYLOAD_TYPES[p.text('type', 'point', choices=tuple(PAYLOAD_TYPES))]
    payload = PayloadConfig(mass=p.positive('mass'),
                            drag_coefficient=p.non_negative('drag_coefficient', 0.0),
                            alpha=math.radians(p.number('alpha_deg', 0.0,
                                                        lambda a: abs(a) < release_limit,
                                                        release_rule)),
                            beta=math.radians(p.number('beta_deg', 0.0, lambda a: abs(a) < 90,
                                                       'must be within (-90, 90) degrees')),
                            swing=math.radians(p.number('swing_deg', 0.0, lambda a: abs(a) < 90,
                                                        'must be within (-90, 90) degrees')),
                            initial_position=finite_vector(p, 'initial_position'),
                            initial_velocity=finite_vector(p, 'initial_velocity'),
                            radius=p.non_negative('radius', 0.0))
    swing = math.degrees(payload.swing)
    payload = payload_type.parse(p, payload, len(uavs))
    p.done()
    if len(uavs) > 1 and (payload.alpha or payload.beta):
        raise p.fail('alpha_deg', math.degrees(payload.alpha),
                     'release angles alpha/beta are for n = 1 (use swing_deg for n = 2)')
    if len(uavs) != 2 and payload.swing:
        raise p.fail('swing_deg', swing, 'a swing out of the UAVs-payload plane needs n = 2')

    formation = None
    if top.has('formation') or len(uavs) > 1:
        formation = _formation(top.section('formation'), len(uavs))

    gusts = []
    for i, entry in enumerate(top.sequence('gusts', [])):
        g = Section(entry, f'gusts[{i}]', where)
        direction = g.vector('direction')
        norm = math.sqrt(sum(c * c for c in direction))
        if norm == 0:
            raise g.fail('direction', list(direction), 'must not be zero')
        gusts.append(Gust(center=g.vector('center', length=2),
                          direction=tuple(c / norm for c in direction),
                          gradient_distance=g.positive('gradient_distance'),
                          reference_speed=g.non_negative('reference_speed')))
        g.done()

    events = _events(top, uavs, duration)
    w = top.section('wind', {})
    wind = w.vector('velocity', [0.0, 0.0, 0.0])  # steady, everywhere (issue 21)
    wind_models = []  # the registered models the section names (multilift_sim.wind)
    for model_name, model in WIND_MODELS.items():
        if w.has(model_name):
            d = w.section(model_name)
            wind_models.append((model_name, model.parse(d)))
            d.done()
    w.done()
    sensors = sensors_section(top.section('sensors'), sim) if top.has('sensors') else None
    suite = sensor_suite(top, sim)
    estimator = estimator_section(top, suite)
    payload_estimator = payload_estimator_section(top)

    c = top.section('control')
    mode = c.text('mode', choices=tuple(leader_controllers()))
    follower = c.text('follower', DEFAULT_FOLLOWER, choices=tuple(follower_controllers()))
    chosen = _controller_keys(c, leader_controllers()[mode], follower_controllers()[follower])
    gains_pos = c.section('position_gains')
    gains_att = c.section('attitude_gains')
    nonneg = dict(check=lambda x: x >= 0, rule='must be >= 0')
    control = ControlConfig(
        mode=mode, follower=follower, **chosen,
        position_kp=gains_pos.vector('kp', **nonneg), position_kd=gains_pos.vector('kd', **nonneg),
        position_ki=gains_pos.vector('ki', **nonneg),
        attitude_kp=gains_att.vector('kp', **nonneg), attitude_kd=gains_att.vector('kd', **nonneg),
        max_tilt=math.radians(c.number('max_tilt_deg', 30.0, lambda a: 0 < a < 90,
                                       'must be within (0, 90) degrees')),
        **_payload_feedback(c, mode))
    control = reorganize.control_of(c, formation, control)
    gains_pos.done()
    gains_att.done()
    c.done()

    from multilift_sim.missions import read_mission  # its parts import scenario's names
    mission = read_mission(top, uavs[0].position)
    world = read_world(top)
    comms = read_comms(top, sim.control_rate)
    if comms is not None and len(uavs) < 2:
        raise top.fail('comms', top.raw('comms'), 'links a leader to its followers: needs n >= 2')
    top.done()

    scenario = Scenario(name=name, description=description, source=where, simulation=sim,
                        uavs=tuple(uavs), payload=payload, gusts=tuple(gusts), control=control,
                        mission=mission,
                        formation=formation, warnings=tuple(warnings),
                        cable_model=cable_model, cable=rope, events=events, wind=tuple(wind),
                        wind_models=tuple(wind_models), sensors=sensors,
                        sensor_suite=suite, estimator=estimator,
                        payload_estimator=payload_estimator, parts=parts, world=world,
                        comms=comms)
    check_payload_estimator(top, scenario)
    _check_feasible(scenario)
    check_limits(scenario)
    check_prescribed(scenario)  # the files cover the run, the payload's start fits the cables
    # what the scenario uses beyond the seed's formation, each modelled by some formulations
    lagging = [i + 1 for i, u in enumerate(scenario.uavs)
               if u.vehicle.motor_time_constant > 0 or math.isfinite(u.vehicle.motor_rate_limit)]
    off_centre = [i for i, u in enumerate(scenario.uavs) if any(u.attach_point)]
    used = {feature: what for feature, what, uses in (
        ('wind', 'wind and vehicle.drag_coefficient',
         any(wind) or wind_models or any(u.vehicle.drag_coefficient for u in scenario.uavs)),
        ('events', 'events', events),
        ('lagging_rotors', f'vehicle.motor_time_constant / motor_rate_limit '
                           f'(uav{lagging[0] if lagging else 0})', lagging),
        ('attach_points', f'uavs[{off_centre[0] if off_centre else 0}].attach_point',
         off_centre),
        ('prescribed', f'uavs[{scenario.prescribed[0] if scenario.prescribed else 0}]'
                       '.trajectory', scenario.prescribed),
        ('winch', 'uavs[i].winch', any(u.winch for u in scenario.uavs))) if uses}
    used.update({feature: f'payload.type: {payload_type.NAME}'
                 for feature in sorted(payload_type.NEEDS)})
    used.update({feature: f'cable_model: {cable_model}' for feature in sorted(cables.NEEDS)})
    refused = unsupported(sim.integrator, used)
    if refused:
        raise ScenarioError(f'{where}: {refused}')
    if len(uavs) < payload_type.MIN_UAVS:
        raise ScenarioError(f'{where}: payload.type: {payload_type.NAME} needs n >= '
                            f'{payload_type.MIN_UAVS} UAVs')
    refused = cables.check(scenario) or winch.check(scenario)
    if refused:
        raise ScenarioError(f'{where}: {refused}')
    check_start(scenario)  # no body starts touching the world or another (world:)
    return scenario


def _controller_keys(c: Section, leader: Any, follower: Any) -> dict[str, Any]:
    """The chosen leader's and follower's own keys in `control:` (their KEYS, read by their
    `parse` into ControlConfig fields: scenario.controllers), and a one-line error for a key
    of a controller the scenario did not choose. Without its key, constant_rotor_speed is
    None (the leader's default)."""
    fields: dict[str, Any] = {'constant_rotor_speed': None}
    values: list[tuple[str, Any]] = []
    for part in (leader, follower):
        if part.KEYS:
            read = dict(part.parse(c))
            values += list(read.pop('values', ()))
            fields.update(read)
    chosen = set(leader.KEYS) | set(follower.KEYS)
    for kind, registry in (('mode', leader_controllers()), ('follower', follower_controllers())):
        for other in registry.values():
            for key in set(other.KEYS) - chosen:
                if c.has(key):
                    raise c.fail(key, c.raw(key), f'is a key of control.{kind}: {other.NAME}')
    return dict(fields, values=tuple(values))


def _payload_feedback(c: Section, mode: str) -> dict[str, float]:
    """`control.payload_feedback` (issue 20; not in the seed): the leader's swing feedback
    gains swing_stiffness k_s [1/s^2] and swing_damping k_d [1/s] with its acceleration_limit
    [m/s^2] (multilift_control.laws.swing), and input_shaping (the mission's corners shaped at
    the payload's pendulum period, multilift_control.mission); all off (the default) the seed's
    law."""
    feedback = c.section('payload_feedback', {})
    gains = {name: feedback.number(name, 0.0) for name in ('swing_stiffness', 'swing_damping')}
    for name, gain in gains.items():
        if gain != 0 and mode != 'cascade':
            raise feedback.fail(name, gain, f'needs control.mode: cascade (a leader that '
                                f'tracks the mission), not {mode!r}')
    gains['swing_limit'] = (feedback.positive('acceleration_limit')
                            if feedback.has('acceleration_limit') else math.inf)
    shaping = feedback.text('input_shaping', 'none', choices=tuple(INPUT_SHAPERS))
    if shaping != 'none' and mode != 'cascade':
        raise feedback.fail('input_shaping', shaping, f'needs control.mode: cascade, not '
                            f'{mode!r}')
    feedback.done()
    return {**gains, 'input_shaping': shaping}


def _events(top: Section, uavs: list[UavConfig], duration: float) -> tuple[EventConfig, ...]:
    """The `events:` list, validated (each key of its type, nothing else) and in time order."""
    events: list[EventConfig] = []
    for k, entry in enumerate(top.sequence('events', [])):
        e = Section(entry, f'events[{k}]', top.where)
        time = e.number('time', ..., lambda v: 0 <= v < duration,
                        f'must be >= 0 and before the run\'s end ({duration:g} s)')
        kind = e.text('type', choices=tuple(EVENT_KINDS))
        # its own keys, by its registered module (multilift_sim.events)
        event = EventConfig(time=time, type=kind, **EVENT_KINDS[kind].parse(e, uavs, events))
        e.done()
        events.append(event)
    return tuple(sorted(events, key=lambda event: event.time))


def _formation(f: Section, n: int) -> FormationConfig:
    f.raw('n', n)  # checked with the UAV list
    geometry = f.text('geometry', choices=FORMATION_GEOMETRIES)
    offsets: list[tuple[float, ...]] = []
    if geometry == 'linear':
        raw = f.raw('offsets')
        if not isinstance(raw, list) or len(raw) != n - 1:
            raise f.fail('offsets', raw, f'must list one [dx, dy, dz] per follower ({n - 1})')
        holder = Section({str(k): v for k, v in enumerate(raw)}, f.key('offsets'), f.where)
        offsets = [holder.vector(str(k)) for k in range(n - 1)]
        holder.done()
    needs_distance = geometry in ('distance', 'v', 'circle')
    distance = f.positive('distance') if needs_distance else 0.0
    half_angle = 0.0
    if geometry == 'v':
        half_angle = math.radians(f.number('half_angle_deg', ..., lambda a: 0 < a < 90,
                                           'must be within (0, 90) degrees'))
    if geometry == 'circle' and n < 3:
        raise f.fail('geometry', geometry, 'needs n >= 3')
    config = FormationConfig(geometry=geometry, offsets=tuple(offsets), distance=distance,
                             half_angle=half_angle, alpha_vc=f.non_negative('alpha_vc'),
                             beta_vc=f.non_negative('beta_vc'),
                             **reorganize.parse(f, n, geometry))
    f.done()
    return config


def _check_feasible(scenario: Scenario) -> None:
    """Reject what the rotors cannot lift at all."""
    lift = sum(u.vehicle.max_thrust for u in scenario.uavs)
    weight = scenario.total_weight()
    if weight >= lift:
        raise ScenarioError(
            f'{scenario.source}: payload.mass: {scenario.payload.mass} kg is too heavy: the '
            f'formation weighs {weight:.2f} N but its rotors lift at most {lift:.2f} N')
    f = scenario.formation
    if f is not None and scenario.n_uavs > 1:
        uavs = nominal_positions(f.geometry, scenario.n_uavs, scenario.uavs[0].position,
                                 f.offsets, f.distance, f.half_angle)
        try:
            hanging_payload(uavs, [u.cable_length for u in scenario.uavs],
                            scenario.payload.attach_points)
            from multilift_sim.start import formation_start, start_attitudes  # Scenario
            if f.start_places:
                reorganize.check_start_places(scenario)
                uavs, _ = formation_start(scenario)
            reorganize.check_start(scenario.source, f, uavs)
            if reorganize.starts_at_rest(scenario):
                start_attitudes(scenario)  # the rotors hold every UAV at rest there
        except ScenarioError:
            raise
        except ValueError as exc:
            raise ScenarioError(f'{scenario.source}: formation: {exc}') from None
        reorganize.check_payload(scenario)
