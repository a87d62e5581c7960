"""Scenario files: YAML in `scenarios/`, loaded and validated once into frozen dataclasses.

Every scenario is written in the world frame (z up, REP-103 SI units). A bad value is one
`ScenarioError` whose message names the file, the key, the value and the rule; the command line
turns it into a single line on stderr and exit code 2.
"""
from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import yaml

from multilift_sim.allocation import FRAME_TYPES
from multilift_sim.disturbances import Gust
from multilift_sim.dynamics import FormationParams
from multilift_sim.formation_geometry import hanging_payload, nominal_positions
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.formulations import FORMULATIONS, SLACK_FORMULATIONS
from multilift_sim.physics.layout import EVENT_KINDS, SENSED_QUANTITIES


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message says where and why."""


CONTROL_MODES = ('cascade', 'constant_rotor_speed')
CABLE_MODELS = ('rigid', 'slack')  # the seed's two-way rod; pulls only (multilift_sim.slack)
FORMATION_GEOMETRIES = ('linear', 'distance', 'v', 'circle')  # seed Table 3.1


@dataclass(frozen=True)
class SimulationConfig:
    duration: float                  # t_max [s]
    physics_rate: float              # RK4 steps per second [Hz]
    control_rate: float              # control ticks per second [Hz]; divides physics_rate
    gravity: float                   # [m/s^2]
    baumgarte_alpha: float           # alpha_f of seed Eq. 2.59 [1/s]
    baumgarte_beta: float            # beta_f of seed Eq. 2.59 [1/s]
    constraint_tolerance: float      # eps_g of Algorithm 1 [m^2]
    constraint_rate_tolerance: float  # eps_gdot of Algorithm 1 [m^2/s]
    command_timeout: float           # wall time the simulator waits for a rotor command [s]
    integrator: str = 'baumgarte'    # 'baumgarte' (Eq. 2.59-2.70) or 'nullspace' (Eq. 2.71-2.72)

    @property
    def physics_steps_per_tick(self) -> int:
        return int(round(self.physics_rate / self.control_rate))

    @property
    def control_period(self) -> float:
        """Time between control ticks [s]."""
        return 1.0 / self.control_rate

    @property
    def tick_count(self) -> int:
        """Number of control periods in the run."""
        return int(round(self.duration * self.control_rate))


@dataclass(frozen=True)
class UavConfig:
    vehicle: MultirotorParams
    cable_length: float              # l_i [m]
    position: tuple[float, float, float]  # initial position, world [m]
    yaw: float                       # initial yaw [rad]


@dataclass(frozen=True)
class PayloadConfig:
    mass: float                      # m_p [kg]
    drag_coefficient: float          # c_pd of seed Eq. 2.53 [kg/m]
    alpha: float                     # release angle alpha of seed Eq. 2.33 [rad] (n = 1)
    beta: float                      # release angle beta of seed Eq. 2.33 [rad] (n = 1)
    swing: float                     # release angle out of the UAVs-payload plane [rad] (n = 2)


@dataclass(frozen=True)
class FormationConfig:
    """Virtual constraints the followers keep (seed §3.2, Table 3.1), world frame."""
    geometry: str                    # 'linear', 'distance', 'v' or 'circle'
    offsets: tuple[tuple[float, float, float], ...]  # linear: r_1 - r_i per follower [m]
    distance: float                  # d [m] (distance, v, circle)
    half_angle: float                # gamma [rad] (v: vertex angle 2 gamma)
    alpha_vc: float                  # formation derivative gain (Table 4.2) [1/s]
    beta_vc: float                   # formation proportional gain (Table 4.2) [1/s]


@dataclass(frozen=True)
class ControlConfig:
    mode: str                        # 'cascade' or 'constant_rotor_speed'
    constant_rotor_speed: float | None  # [rad/s]; None = balance the total weight
    position_kp: tuple[float, float, float]  # [1/s^2]
    position_kd: tuple[float, float, float]  # [1/s]
    position_ki: tuple[float, float, float]  # [1/s^3]
    attitude_kp: tuple[float, float, float]  # [1/s^2]
    attitude_kd: tuple[float, float, float]  # [1/s]
    max_tilt: float                  # [rad]


@dataclass(frozen=True)
class MissionSegment:
    velocity: tuple[float, float, float]  # leader reference velocity, world [m/s]
    end_time: float                  # the segment ends at this simulated time [s]


@dataclass(frozen=True)
class MissionConfig:
    start: tuple[float, float, float]  # reference position at t = 0, world [m]
    segments: tuple[MissionSegment, ...]
    # tau of the leader's reference prefilter [s] (not in the seed; 0 = the raw corners)
    reference_filter_time: float = 0.0


@dataclass(frozen=True)
class EventConfig:
    """One of the scenario's `events:` (issue 21), applied at the first control tick at or
    after its time (physics.events)."""
    time: float                      # [s]
    type: str                        # one of physics.layout.EVENT_KINDS
    uav: int                         # the UAV it concerns, from 1 (1 = the leader); gust: 0
    rotor: int = 0                   # rotor_effectiveness: the rotor, from 1; else 0
    effectiveness: float = 1.0       # rotor_effectiveness: its share of thrust, in [0, 1]
    duration: float = 0.0            # controller_silence: how long no command arrives [s];
    #                                  gust: how long it blows [s]
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)  # gust: its peak [m/s], world


@dataclass(frozen=True)
class TurbulenceConfig:
    """Dryden turbulence on top of the steady wind (`wind.turbulence`, multilift_sim.turbulence):
    components u (along the mean wind), v (to its left), w (up)."""
    intensity: tuple[float, float, float]     # sigma_u, sigma_v, sigma_w [m/s]
    length_scale: tuple[float, float, float]  # L_u, L_v, L_w [m]
    airspeed: float                           # V [m/s]: how fast the field passes
    seed: int                                 # of the series (a run's seed)


@dataclass(frozen=True)
class SensorConfig:
    """What the controllers receive of each UAV (`sensors:`, multilift_sim.sensors,
    docs/sensors.md): per quantity of SENSED_QUANTITIES (position [m], velocity [m/s],
    attitude [rad], body_rate [rad/s]) its white noise and bias random walk."""
    noise: tuple[float, ...]         # standard deviation of the white noise [unit]
    bias: tuple[float, ...]          # intensity of the bias random walk [unit / sqrt(s)]
    rate: float                      # samples per second [Hz]; divides control_rate
    latency_ticks: int               # control ticks from a sample to its arrival
    dropout: float                   # probability a sample is lost, in [0, 1)
    seed: int                        # of the errors (a run's seed)

    def every(self, control_rate: float) -> int:
        """Control ticks between two samples."""
        return int(round(control_rate / self.rate))


@dataclass(frozen=True)
class Scenario:
    name: str
    description: str
    source: str                      # the file it came from
    simulation: SimulationConfig
    uavs: tuple[UavConfig, ...]
    payload: PayloadConfig
    gusts: tuple[Gust, ...]
    control: ControlConfig
    mission: MissionConfig
    formation: FormationConfig | None = None
    warnings: tuple[str, ...] = field(default=())
    cable_model: str = 'rigid'       # one of CABLE_MODELS
    events: tuple[EventConfig, ...] = ()  # in time order
    wind: tuple[float, float, float] = (0.0, 0.0, 0.0)  # steady wind [m/s], world
    turbulence: TurbulenceConfig | None = None
    sensors: SensorConfig | None = None  # None: the controllers read the exact state

    @property
    def n_uavs(self) -> int:
        return len(self.uavs)

    @property
    def has_wind(self) -> bool:
        """Whether the air moves everywhere (a steady wind, turbulence or a gust event:
        /formation/wind carries it), beyond the seed's gusts at places."""
        return (any(self.wind) or self.turbulence is not None
                or any(e.type == 'gust' for e in self.events))

    def formation_params(self, baumgarte_alpha: float | None = None,
                         baumgarte_beta: float | None = None) -> FormationParams:
        """Physics parameters of the formation DAE (optionally other Baumgarte gains)."""
        sim = self.simulation
        return FormationParams(
            uavs=tuple(u.vehicle for u in self.uavs),
            cable_lengths=tuple(u.cable_length for u in self.uavs),
            payload_mass=self.payload.mass,
            payload_drag_coefficient=self.payload.drag_coefficient,
            gusts=self.gusts,
            gravity=sim.gravity, wind=self.wind,
            baumgarte_alpha=sim.baumgarte_alpha if baumgarte_alpha is None else baumgarte_alpha,
            baumgarte_beta=sim.baumgarte_beta if baumgarte_beta is None else baumgarte_beta,
        )

    def with_duration(self, duration: float) -> 'Scenario':
        """The same scenario flown for `duration` [s] (a `--duration` override); ScenarioError
        unless it is at least one control period."""
        if not _flies_a_period(duration, self.simulation.control_rate):
            raise ScenarioError(f'duration: {duration!r} '
                                f'{_one_period_rule(self.simulation.control_rate)}')
        return dataclasses.replace(
            self, simulation=dataclasses.replace(self.simulation, duration=float(duration)))

    def total_weight(self) -> float:
        """Weight of every UAV and the payload [N]."""
        mass = sum(u.vehicle.mass for u in self.uavs) + self.payload.mass
        return mass * self.simulation.gravity


# --------------------------------------------------------------------------------------------
# Reading with checks. `_Section` walks one mapping, remembers which keys were read and rejects
# the rest, so a typo is an error rather than a silently ignored key.


class _Section:
    def __init__(self, data: Any, path: str, where: str):
        if not isinstance(data, dict):
            raise ScenarioError(f'{where}: {path or "top level"}: expected a mapping, '
                                f'got {type(data).__name__}')
        self.data = data
        self.path = path
        self.where = where
        self.used: set[str] = set()

    def key(self, name: str) -> str:
        return f'{self.path}.{name}' if self.path else name

    def fail(self, name: str, value: Any, rule: str) -> ScenarioError:
        return ScenarioError(f'{self.where}: {self.key(name)}: {value!r} {rule}')

    def has(self, name: str) -> bool:
        return name in self.data

    def raw(self, name: str, default: Any = ...) -> Any:
        self.used.add(name)
        if name not in self.data:
            if default is ...:
                raise ScenarioError(f'{self.where}: {self.key(name)}: missing key')
            return default
        return self.data[name]

    def number(self, name: str, default: Any = ..., check: Callable[[float], bool] | None = None,
               rule: str = '') -> float:
        value = self.raw(name, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(name, value, 'must be a number')
        value = float(value)
        if not math.isfinite(value):
            raise self.fail(name, value, 'must be finite')
        if check is not None and not check(value):
            raise self.fail(name, value, rule)
        return value

    def positive(self, name: str, default: Any = ...) -> float:
        return self.number(name, default, lambda v: v > 0, 'must be > 0')

    def non_negative(self, name: str, default: Any = ...) -> float:
        return self.number(name, default, lambda v: v >= 0, 'must be >= 0')

    def vector(self, name: str, default: Any = ..., length: int = 3,
               check: Callable[[float], bool] | None = None, rule: str = '') -> tuple[float, ...]:
        value = self.raw(name, default)
        if (not isinstance(value, (list, tuple)) or len(value) != length
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)):
            raise self.fail(name, value, f'must be a list of {length} numbers')
        out = tuple(float(v) for v in value)
        if not all(math.isfinite(v) for v in out):
            raise self.fail(name, value, 'must be finite')
        if check is not None and not all(check(v) for v in out):
            raise self.fail(name, value, rule)
        return out

    def count(self, name: str, default: Any = ...) -> int:
        """An integer >= 0 (a seed, a number of ticks)."""
        value = self.raw(name, default)
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise self.fail(name, value, 'must be an integer >= 0')
        return value

    def text(self, name: str, default: Any = ..., choices: tuple[str, ...] | None = None) -> str:
        value = self.raw(name, default)
        if not isinstance(value, str):
            raise self.fail(name, value, 'must be a string')
        if choices is not None and value not in choices:
            raise self.fail(name, value, f'must be one of {", ".join(choices)}')
        return value

    def sequence(self, name: str, default: Any = ...) -> list:
        """A list (a missing or null key gives `default`)."""
        value = self.raw(name, default)
        if value is None and default is not ...:
            value = default
        if not isinstance(value, list):
            raise self.fail(name, value, 'must be a list')
        return value

    def section(self, name: str, default: Any = ...) -> '_Section':
        return _Section(self.raw(name, default), self.key(name), self.where)

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise ScenarioError(f'{self.where}: {self.key(unknown[0])}: unknown key '
                                f'(known here: {", ".join(sorted(self.used))})')


VEHICLE_KEYS = ('mass', 'inertia', 'frame_type', 'arm_length', 'thrust_coefficient',
                'moment_coefficient', 'rotor_speed_min', 'rotor_speed_max',
                'motor_time_constant', 'motor_rate_limit', 'drag_coefficient')


def _vehicle(sec: _Section, base: dict[str, Any] | None) -> MultirotorParams:
    """A MultirotorParams from `sec`, falling back to `base` (the shared `vehicle` section)."""
    def default(key: str) -> Any:
        return ... if base is None else base[key]
    mass = sec.positive('mass', default('mass'))
    inertia = sec.vector('inertia', default('inertia'), check=lambda v: v > 0, rule='must be > 0')
    frame_type = sec.text('frame_type', default('frame_type'), choices=FRAME_TYPES)
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
    return MultirotorParams(mass=mass, inertia=inertia, frame_type=frame_type,
                            arm_length=arm_length, thrust_coefficient=k_t,
                            moment_coefficient=k_d, rotor_speed_min=w_min, rotor_speed_max=w_max,
                            motor_time_constant=tau, motor_rate_limit=rate, drag_coefficient=drag)


SEED_INERTIA = (0.957, 0.486, 0.355)  # seed Table 4.1 / 4.2 [kg m^2]
INERTIA_SOURCES = ('given', 'seed')


def _inertia_source(sec: _Section, inertia: tuple[float, ...], default: str = 'given') -> str:
    """`inertia_source: seed` says the inertia is the seed's printed diag(0.957, 0.486, 0.355),
    which breaks the triangle inequality of a rigid body, kept on purpose: no warning then.
    Any other inertia with it is an error."""
    source = sec.text('inertia_source', default, choices=INERTIA_SOURCES)
    if source == 'seed' and any(abs(x - y) > 1e-12 for x, y in zip(inertia, SEED_INERTIA)):
        raise sec.fail('inertia_source', source, f'says the inertia is the seed\'s '
                       f'{list(SEED_INERTIA)}, but it is {list(inertia)}')
    return source


def _inertia_warning(where: str, key: str, inertia: tuple[float, ...],
                     source: str = 'given') -> list[str]:
    a, b, c = inertia
    if source == 'seed':  # the seed's printed value, a documented choice of the file
        return []
    if a + b < c or a + c < b or b + c < a:
        return [f'{where}: {key}: {list(inertia)} breaks the triangle inequality of a rigid '
                'body (the seed\'s own Table 4.1 value does); used as given']
    return []


def _scenario(data: Any, where: str) -> Scenario:
    top = _Section(data, '', where)
    name = top.text('name')
    description = top.text('description', '')
    top.text('frame', 'world', choices=('world',))
    cable_model = top.text('cable_model', 'rigid', choices=CABLE_MODELS)
    # a slack cable may start with the payload above its UAV (it falls and snaps taut)
    release_limit = 180.0 if cable_model == 'slack' else 90.0
    release_rule = f'must be within (-{release_limit:g}, {release_limit:g}) degrees' + (
        '' if cable_model == 'slack' else ' (beyond 90 needs cable_model: slack)')

    s = top.section('simulation')
    duration = s.positive('duration')
    physics_rate = s.positive('physics_rate')
    control_rate = s.number('control_rate', ..., lambda v: 0 < v <= physics_rate,
                            f'must be > 0 and <= physics_rate ({physics_rate})')
    if not _flies_a_period(duration, control_rate):
        raise s.fail('duration', duration, _one_period_rule(control_rate))
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
        integrator=s.text('integrator', 'baumgarte', choices=tuple(FORMULATIONS)))
    s.done()

    v = top.section('vehicle')
    base_vehicle = dataclasses.asdict(_vehicle(v, None))
    base_source = _inertia_source(v, tuple(base_vehicle['inertia']))
    v.done()
    warnings = _inertia_warning(where, 'vehicle.inertia', tuple(base_vehicle['inertia']),
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
    uavs = []
    for i, entry in enumerate(uav_list):
        u = _Section(entry, f'uavs[{i}]', where)
        vehicle = _vehicle(u, base_vehicle)
        source = _inertia_source(u, vehicle.inertia,
                                 base_source if vehicle.inertia == SEED_INERTIA else 'given')
        if vehicle.inertia != tuple(base_vehicle['inertia']) or source != base_source:
            warnings += _inertia_warning(where, u.key('inertia'), vehicle.inertia, source)
        if i > 0 and u.has('position'):
            raise u.fail('position', u.data['position'],
                         'is not allowed: follower positions come from the formation geometry')
        uavs.append(UavConfig(vehicle=vehicle, cable_length=u.positive('cable_length',
                                                                        default_cable),
                              position=u.vector('position', [0.0, 0.0, 0.0]),
                              yaw=u.number('yaw', 0.0)))
        u.done()

    p = top.section('payload')
    payload = PayloadConfig(mass=p.positive('mass'),
                            drag_coefficient=p.non_negative('drag_coefficient', 0.0),
                            alpha=math.radians(p.number('alpha_deg', 0.0,
                                                        lambda a: abs(a) < release_limit,
                                                        release_rule)),
                            beta=math.radians(p.number('beta_deg', 0.0, lambda a: abs(a) < 90,
                                                       'must be within (-90, 90) degrees')),
                            swing=math.radians(p.number('swing_deg', 0.0, lambda a: abs(a) < 90,
                                                        'must be within (-90, 90) degrees')))
    swing = math.degrees(payload.swing)
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
        g = _Section(entry, f'gusts[{i}]', where)
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
    turbulence = None
    if w.has('turbulence'):
        d = w.section('turbulence')
        turbulence = TurbulenceConfig(
            intensity=d.vector('intensity', check=lambda v: v >= 0, rule='must be >= 0'),
            length_scale=d.vector('length_scale', check=lambda v: v > 0, rule='must be > 0'),
            airspeed=d.positive('airspeed'), seed=d.count('seed', 0))
        d.done()
    w.done()
    sensors = _sensors(top.section('sensors'), sim) if top.has('sensors') else None

    c = top.section('control')
    mode = c.text('mode', choices=CONTROL_MODES)
    constant = c.raw('constant_rotor_speed', None)
    if constant is not None:
        constant = c.positive('constant_rotor_speed')
    gains_pos = c.section('position_gains')
    gains_att = c.section('attitude_gains')
    nonneg = dict(check=lambda x: x >= 0, rule='must be >= 0')
    control = ControlConfig(
        mode=mode, constant_rotor_speed=constant,
        position_kp=gains_pos.vector('kp', **nonneg), position_kd=gains_pos.vector('kd', **nonneg),
        position_ki=gains_pos.vector('ki', **nonneg),
        attitude_kp=gains_att.vector('kp', **nonneg), attitude_kd=gains_att.vector('kd', **nonneg),
        max_tilt=math.radians(c.number('max_tilt_deg', 30.0, lambda a: 0 < a < 90,
                                       'must be within (0, 90) degrees')))
    gains_pos.done()
    gains_att.done()
    c.done()

    m = top.section('mission')
    start = m.vector('start', list(uavs[0].position))
    segments = []
    t_prev = 0.0
    for i, entry in enumerate(m.sequence('segments', [])):
        seg = _Section(entry, f'mission.segments[{i}]', where)
        velocity = seg.vector('velocity')
        if seg.has('duration') == seg.has('until'):
            raise ScenarioError(f'{where}: {seg.path}: give exactly one of duration, until')
        if seg.has('duration'):
            end = t_prev + seg.positive('duration')
        else:
            end = seg.number('until', ..., lambda t: t > t_prev, f'must be > {t_prev}')
        seg.done()
        segments.append(MissionSegment(velocity=velocity, end_time=end))
        t_prev = end
    reference_filter_time = m.non_negative('reference_filter_time', 0.0)
    m.done()
    top.done()

    scenario = Scenario(name=name, description=description, source=where, simulation=sim,
                        uavs=tuple(uavs), payload=payload, gusts=tuple(gusts), control=control,
                        mission=MissionConfig(start=start, segments=tuple(segments),
                                              reference_filter_time=reference_filter_time),
                        formation=formation, warnings=tuple(warnings),
                        cable_model=cable_model, events=events, wind=tuple(wind),
                        turbulence=turbulence, sensors=sensors)
    _check_feasible(scenario)
    # what only the engine's DAE (physics/) models: refused with another formulation
    lagging = [i + 1 for i, u in enumerate(scenario.uavs)
               if u.vehicle.motor_time_constant > 0 or math.isfinite(u.vehicle.motor_rate_limit)]
    windy = any(wind) or turbulence is not None or any(u.vehicle.drag_coefficient
                                                       for u in scenario.uavs)
    for used, what in ((windy, 'wind and vehicle.drag_coefficient'), (events, 'events'),
                       (lagging, f'vehicle.motor_time_constant / motor_rate_limit '
                                 f'(uav{lagging[0] if lagging else 0})')):
        if used and sim.integrator != 'baumgarte':
            raise ScenarioError(f'{where}: {what} need simulation.integrator: baumgarte, got '
                                f'{sim.integrator!r}')
    if cable_model == 'slack' and sim.integrator not in SLACK_FORMULATIONS:
        raise ScenarioError(f'{where}: cable_model: slack needs simulation.integrator: '
                            f'baumgarte, got {sim.integrator!r}')
    return scenario


def _sensors(d: _Section, sim: SimulationConfig) -> SensorConfig:
    """The `sensors:` section, validated: per quantity `{name}_noise` and `{name}_bias`
    (default 0), the rate (default the control rate, which it must divide), the latency in
    ticks, the dropout probability and the seed."""
    noise = tuple(d.non_negative(f'{q}_noise', 0.0) for q in SENSED_QUANTITIES)
    bias = tuple(d.non_negative(f'{q}_bias', 0.0) for q in SENSED_QUANTITIES)
    control_rate = sim.control_rate
    rate = d.number('rate', control_rate, lambda v: 0 < v <= control_rate,
                    f'must be > 0 and <= simulation.control_rate ({control_rate:g})')
    ratio = control_rate / rate
    if abs(ratio - round(ratio)) > 1e-9:
        raise d.fail('rate', rate, f'must divide simulation.control_rate ({control_rate:g}) '
                     'into a whole number of ticks')
    config = SensorConfig(noise=noise, bias=bias, rate=rate,
                          latency_ticks=d.count('latency_ticks', 0),
                          dropout=d.number('dropout', 0.0, lambda v: 0 <= v < 1,
                                           'must be within [0, 1)'),
                          seed=d.count('seed', 0))
    d.done()
    return config


def _events(top: _Section, uavs: list[UavConfig], duration: float) -> tuple[EventConfig, ...]:
    """The `events:` list, validated (each key of its type, nothing else) and in time order."""
    events = []
    released: set[int] = set()
    for k, entry in enumerate(top.sequence('events', [])):
        e = _Section(entry, f'events[{k}]', top.where)
        time = e.number('time', ..., lambda v: 0 <= v < duration,
                        f'must be >= 0 and before the run\'s end ({duration:g} s)')
        kind = e.text('type', choices=EVENT_KINDS)
        if kind == 'gust':  # the whole formation's air: no UAV
            velocity = e.vector('velocity')
            if not any(velocity):
                raise e.fail('velocity', list(velocity), 'must not be zero')
            events.append(EventConfig(time=time, type=kind, uav=0, velocity=velocity,
                                      duration=e.positive('duration')))
            e.done()
            continue
        uav = e.raw('uav')
        if isinstance(uav, bool) or not isinstance(uav, int) or not 1 <= uav <= len(uavs):
            raise e.fail('uav', uav, f'must be a UAV from 1 to {len(uavs)}')
        event = EventConfig(time=time, type=kind, uav=uav)
        if kind == 'rotor_effectiveness':
            rotors = uavs[uav - 1].vehicle.n_rotors
            rotor = e.raw('rotor')
            if isinstance(rotor, bool) or not isinstance(rotor, int) or not 1 <= rotor <= rotors:
                raise e.fail('rotor', rotor, f'must be a rotor of uav{uav}, from 1 to {rotors}')
            event = dataclasses.replace(event, rotor=rotor, effectiveness=e.number(
                'effectiveness', ..., lambda v: 0 <= v <= 1, 'must be within [0, 1]'))
        elif kind == 'controller_silence':
            event = dataclasses.replace(event, duration=e.positive('duration'))
        elif kind == 'cable_release':
            if uav in released:
                raise e.fail('uav', uav, 'has let go of its cable already')
            released.add(uav)
            if len(released) == len(uavs):
                raise e.fail('uav', uav, 'is the last cable holding the payload')
        e.done()
        events.append(event)
    return tuple(sorted(events, key=lambda event: event.time))


def _flies_a_period(duration: float, control_rate: float) -> bool:
    """A run integrates whole control periods and asks for commands before t_max only: it
    needs at least one period, or there is nothing to integrate."""
    return math.isfinite(duration) and round(duration * control_rate) >= 1


def _one_period_rule(control_rate: float) -> str:
    return f'must be at least one control period (1/control_rate = {1.0 / control_rate:g} s)'


def _formation(f: _Section, n: int) -> FormationConfig:
    f.raw('n', n)  # checked with the UAV list
    geometry = f.text('geometry', choices=FORMATION_GEOMETRIES)
    offsets: list[tuple[float, ...]] = []
    if geometry == 'linear':
        raw = f.raw('offsets')
        if not isinstance(raw, list) or len(raw) != n - 1:
            raise f.fail('offsets', raw, f'must list one [dx, dy, dz] per follower ({n - 1})')
        holder = _Section({str(k): v for k, v in enumerate(raw)}, f.key('offsets'), f.where)
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
                             beta_vc=f.non_negative('beta_vc'))
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
            hanging_payload(uavs, [u.cable_length for u in scenario.uavs])
        except ValueError as exc:
            raise ScenarioError(f'{scenario.source}: formation: {exc}') from None


def scenario_dir() -> Path:
    """The `scenarios/` folder: $MULTILIFT_SCENARIOS, else the repository's."""
    env = os.environ.get('MULTILIFT_SCENARIOS')
    if env:
        return Path(env)
    root = os.environ.get('ML_ROOT')
    if root:
        return Path(root) / 'scenarios'
    return Path.cwd() / 'scenarios'


def resolve(name_or_path: str) -> Path:
    """A scenario name (a file in scenarios/) or a YAML path -> the file."""
    candidate = Path(name_or_path)
    if candidate.suffix in ('.yaml', '.yml') or os.sep in name_or_path:
        if not candidate.is_file():
            raise ScenarioError(f'{name_or_path}: no such scenario file')
        return candidate
    path = scenario_dir() / f'{name_or_path}.yaml'
    if not path.is_file():
        known = sorted(p.stem for p in scenario_dir().glob('*.yaml'))
        raise ScenarioError(f'{name_or_path}: unknown scenario (known: {", ".join(known)})')
    return path


def load(name_or_path: str) -> Scenario:
    """Load and validate a scenario by name or path. Raises ScenarioError."""
    path = resolve(name_or_path)
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ScenarioError(f'{path}: not valid YAML: {exc}'.replace('\n', ' ')) from None
    return _scenario(data, str(path))


def loads(text: str, where: str = '<string>') -> Scenario:
    """Validate a scenario given as YAML text (tests, tools)."""
    return _scenario(yaml.safe_load(text), where)
