"""The scenario as frozen dataclasses (`Scenario` and its sections), and the rules every
duration keeps: what `scenario.parse` builds from a file, validated once. World frame (z up),
SI units."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

from multilift_sim.cables.winch import Winch
from multilift_sim.drives import Drive
from multilift_sim.events import moves_air
from multilift_sim.formation_params import FormationParams
from multilift_sim.formation_geometry import FORMATION_GEOMETRIES  # noqa: F401 (the registry)
from multilift_sim.multirotor import MultirotorParams
from multilift_sim.wind.gusts import Gust


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message says where and why."""


# `control.payload_feedback.input_shaping` (issue 20, not in the seed): each velocity step of the
# mission split into impulses (time in periods T of the payload's pendulum, share of the step);
# zero residual swing of an undamped pendulum of period T: zv (Singer & Seering 1990), zvd
# (also robust to a misjudged T; twice as long, half the acceleration)
INPUT_SHAPERS = {'none': ((0.0, 1.0),),
                 'zv': ((0.0, 0.5), (0.5, 0.5)),
                 'zvd': ((0.0, 0.25), (0.5, 0.5), (1.0, 0.25)),
                 'zvdd': ((0.0, 0.125), (0.5, 0.375), (1.0, 0.375), (1.5, 0.125))}


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
    substeps: int = 1                # RK4 steps per physics step (stiff parts: elastic cables)

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
    # where its cable holds it, body FLU [m] (issue 20; default its centre of mass)
    attach_point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    cable_stiffness: float = 0.0     # k_i [N/m] of an elastic cable (cable_model: elastic)
    cable_damping: float = 0.0       # c_i [N s/m] of an elastic cable
    # its prescribed motion (`trajectory:`, a file; issue 34): no controller, a kinematic
    # driver of the DAE (physics.prescribed); None: flown by its controller
    trajectory: Drive | None = None
    # its winch (`winch:`, cables.winch; issue 32): the cable's length reeled; None: fixed
    winch: Winch | None = None


@dataclass(frozen=True)
class PayloadConfig:
    mass: float                      # m_p [kg]
    drag_coefficient: float          # c_pd of seed Eq. 2.53 [kg/m]
    alpha: float                     # release angle alpha of seed Eq. 2.33 [rad] (n = 1)
    beta: float                      # release angle beta of seed Eq. 2.33 [rad] (n = 1)
    swing: float                     # release angle out of the UAVs-payload plane [rad] (n = 2)
    type: str = 'point'              # one of payloads.PAYLOAD_TYPES
    # rigid_body: its shape (payloads.rigid_body.SHAPES) and size [m], principal inertia [kg m^2]
    # and each cable's attach point [m], payload frame (UAV i's cable: entry i)
    shape: str = ''
    size: tuple[float, ...] = ()
    inertia: tuple[float, float, float] | None = None
    attach_points: tuple[tuple[float, float, float], ...] | None = None
    # where it starts, world [m] and [m/s] (issue 34; None: hanging at rest under the UAVs)
    initial_position: tuple[float, float, float] | None = None
    initial_velocity: tuple[float, float, float] | None = None
    radius: float = 0.0              # its sphere about r_p for the clearances [m] (point payload)


@dataclass(frozen=True)
class ObstacleConfig:
    """One of `world.obstacles` (issue 34 item 5): its type a name of
    multilift_sim.obstacles.OBSTACLE_TYPES."""
    name: str                        # how the summary names it (default obstacle<k + 1>)
    type: str
    center: tuple[float, float, float]  # [m], world
    half: tuple[float, float, float]  # half its extent along its own axes [m] (its type's)
    yaw: float                       # about world z [rad]
    bound: float                     # the radius of a sphere about its centre that holds it [m]


@dataclass(frozen=True)
class WorldConfig:
    """The `world:` section: what the formation must keep clear of (physics.clearance)."""
    obstacles: tuple[ObstacleConfig, ...] = ()
    ground: float | None = None      # the ground's height [m], world z; None: no ground
    on_contact: str = 'stop'         # 'stop' (exit 1 naming it) or 'record' (fly on)


@dataclass(frozen=True)
class FormationConfig:
    """Virtual constraints the followers keep (seed §3.2, Table 3.1), world frame."""
    geometry: str                    # 'linear', 'distance', 'v' or 'circle'
    offsets: tuple[tuple[float, float, float], ...]  # linear: r_1 - r_i per follower [m]
    distance: float                  # d [m] (distance, v, circle)
    half_angle: float                # gamma [rad] (v: vertex angle 2 gamma)
    alpha_vc: float                  # formation derivative gain (Table 4.2) [1/s]
    beta_vc: float                   # formation proportional gain (Table 4.2) [1/s]
    # issue 35: the offsets moved online by thrust margin (scenario.reorganize); 'none': fixed
    reorganize: str = 'none'
    min_spacing: float = 1.0         # least horizontal distance between UAVs [m]
    max_spread: float = math.inf     # largest horizontal distance between UAVs [m]
    max_offset_rate: float = 0.2     # largest speed of a follower's offset [m/s]
    thrust_margin_floor: float = 0.05  # [-] share of the largest thrust
    # issue 35: each follower's (x, y) from the leader at t = 0 [m], world (default (): the
    # geometry's places); the UAVs level with the leader, a point payload where it hangs
    start_places: tuple[tuple[float, float], ...] = ()


@dataclass(frozen=True)
class ControlConfig:
    mode: str                        # the leader's law: a name of LEADER_CONTROLLERS
    constant_rotor_speed: float | None  # [rad/s]; None = balance the total weight
    position_kp: tuple[float, float, float]  # [1/s^2]
    position_kd: tuple[float, float, float]  # [1/s]
    position_ki: tuple[float, float, float]  # [1/s^3]
    attitude_kp: tuple[float, float, float]  # [1/s^2]
    attitude_kd: tuple[float, float, float]  # [1/s]
    max_tilt: float                  # [rad]
    # control.payload_feedback (not in the seed: the leader's swing feedback,
    # multilift_control.laws.swing); both 0 = the seed's law
    swing_stiffness: float = 0.0     # k_s [1/s^2]
    swing_damping: float = 0.0       # k_d [1/s]
    swing_limit: float = math.inf    # a_max: the largest |a_s| [m/s^2]
    # the mission's corners passed through one of INPUT_SHAPERS at the hanging payload's
    # pendulum period (multilift_control.mission.MissionPath); 'none' = the seed's corners
    input_shaping: str = 'none'
    # the followers' law: a name of FOLLOWER_CONTROLLERS (scenario.controllers)
    follower: str = 'virtual_constraints'
    values: tuple[tuple[str, Any], ...] = ()  # a controller part's own keys (its parse)

    def value(self, key: str) -> Any:
        """A controller part's own value `key` (of `values`)."""
        return dict(self.values)[key]


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
    # the source (multilift_sim.missions.MISSION_SOURCES) that read it, and what tracks it
    type: str = 'segments'
    tracks: str = 'leader'           # 'leader' or 'payload' (missions.TRACKED)
    # a `polynomial` source's trajectory (missions.polynomials): times (m + 1,) [s] and
    # coefficients (m, 4, 8): x, y, z [m], yaw [rad] in powers of t - knots[k]
    knots: tuple[float, ...] = ()
    coefficients: tuple[tuple[tuple[float, ...], ...], ...] = ()
    points: tuple[tuple[float, float, float], ...] = ()  # the points it passes, world [m]
    # how fast a live goal is flown (`run --live`, multilift_control.live_goals) [m/s, m/s^2]
    max_speed: float = 1.0
    max_acceleration: float = 0.5


@dataclass(frozen=True)
class EventConfig:
    """One of the scenario's `events:` (issue 21), applied at the first control tick at or
    after its time (physics.events). Its kind's module (multilift_sim.events) reads its keys
    into these fields: the ones kinds share, and a kind's own numbers in `values`."""
    time: float                      # [s]
    type: str                        # a name of multilift_sim.events.EVENT_KINDS
    uav: int                         # the UAV it concerns, from 1 (1 = the leader); 0: none
    rotor: int = 0                   # the rotor, from 1; 0: none
    effectiveness: float = 1.0       # a rotor's share of thrust, in [0, 1]
    duration: float = 0.0            # how long it lasts [s]
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)  # a velocity [m/s], world
    values: tuple[tuple[str, float], ...] = ()  # a kind's own numbers by key

    def value(self, key: str) -> float:
        """The kind's own number `key` (of `values`)."""
        return dict(self.values)[key]


@dataclass(frozen=True)
class SensorConfig:
    """What the controllers receive of each UAV (`sensors:`, docs/sensors.md): a sensor model
    of multilift_sim.sensors.SENSOR_MODELS with its keys."""
    model: str                       # its name in SENSOR_MODELS (`sensors.model`)
    rate: float                      # samples per second [Hz]; divides control_rate
    seed: int                        # of its draws (a run's seed)
    settings: Any                    # its own keys, as its model's `parse` read them

    def every(self, control_rate: float) -> int:
        """Control ticks between two samples."""
        return int(round(control_rate / self.rate))


@dataclass(frozen=True)
class EstimatorConfig:
    """The estimator of every UAV (`estimator:`, docs/estimation.md): a part of
    multilift_sim.estimators.ESTIMATORS with its keys."""
    model: str                       # its name in ESTIMATORS (`estimator.model`)
    settings: Any                    # its own keys, as its `parse` read them


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
    cable_model: str = 'rigid'       # one of cables.CABLE_MODELS
    cable: Any = None                # what its `parse_cable` read of `cable:` (None: nothing)
    events: tuple[EventConfig, ...] = ()  # in time order
    wind: tuple[float, float, float] = (0.0, 0.0, 0.0)  # steady wind [m/s], world
    # the wind models `wind:` names: (name, its config) (multilift_sim.wind.WIND_MODELS)
    wind_models: tuple[tuple[str, Any], ...] = ()
    sensors: SensorConfig | None = None  # None: the controllers read the exact state
    # the sensors of their own sections (`imu:`, `mocap:`), in the registry's order
    sensor_suite: tuple[SensorConfig, ...] = ()
    estimator: EstimatorConfig | None = None  # None: no estimator (`estimator: none`)
    # the payload's estimator (`payload_estimator:`, a part of multilift_sim.payload_estimators
    # .PAYLOAD_ESTIMATORS); None: the controllers read the payload's state
    payload_estimator: EstimatorConfig | None = None
    parts: tuple[str, ...] = ()      # part files it imports (`parts:`, multilift_sim.parts)
    world: WorldConfig | None = None  # obstacles, ground (`world:`); None: no clearance checks
    comms: Any = None                # links.CommsConfig (`comms:`); None: followers hear at once

    @property
    def n_uavs(self) -> int:
        return len(self.uavs)

    @property
    def prescribed(self) -> tuple[int, ...]:
        """The UAVs (from 0) whose motion is prescribed (`uavs[i].trajectory`)."""
        return tuple(i for i, u in enumerate(self.uavs) if u.trajectory is not None)

    @property
    def measures(self) -> bool:
        """Whether the controllers receive something other than the state (`sensors:` or an
        estimator): every /uav{i}/measured_odom carries what they received."""
        return self.sensors is not None or self.estimator is not None

    @property
    def winches(self) -> tuple[int, ...]:
        """The UAVs (from 1) that carry a winch (`uavs[i].winch`)."""
        return tuple(i + 1 for i, u in enumerate(self.uavs) if u.winch is not None)

    @property
    def controlled(self) -> bool:
        """Whether the formation has controllers: not when every UAV's motion is prescribed
        (no controller nodes, the engine answers nothing)."""
        return len(self.prescribed) < self.n_uavs

    @property
    def has_wind(self) -> bool:
        """Whether the air moves everywhere (a steady wind, turbulence or an event that blows
        air: /formation/wind carries it), beyond the seed's gusts at places."""
        return (any(self.wind) or bool(self.wind_models)
                or any(moves_air(e.type) for e in self.events))

    def formation_params(self, baumgarte_alpha: float | None = None,
                         baumgarte_beta: float | None = None) -> FormationParams:
        """Physics parameters of the formation DAE (optionally other Baumgarte gains)."""
        sim = self.simulation
        ropes = any(u.cable_stiffness for u in self.uavs)  # cables that stretch (elastic)
        return FormationParams(
            uavs=tuple(u.vehicle for u in self.uavs),
            cable_lengths=tuple(u.cable_length for u in self.uavs),
            payload_mass=self.payload.mass,
            payload_drag_coefficient=self.payload.drag_coefficient,
            gusts=self.gusts,
            gravity=sim.gravity, wind=self.wind,
            baumgarte_alpha=sim.baumgarte_alpha if baumgarte_alpha is None else baumgarte_alpha,
            baumgarte_beta=sim.baumgarte_beta if baumgarte_beta is None else baumgarte_beta,
            payload_inertia=self.payload.inertia,
            payload_attach_points=self.payload.attach_points,
            uav_attach_points=(tuple(u.attach_point for u in self.uavs)
                               if any(any(u.attach_point) for u in self.uavs) else None),
            cable_stiffness=tuple(u.cable_stiffness for u in self.uavs) if ropes else None,
            cable_damping=tuple(u.cable_damping for u in self.uavs) if ropes else None,
            substeps=sim.substeps,
            drives=(tuple(u.trajectory for u in self.uavs) if self.prescribed else None),
            winches=(tuple(u.winch for u in self.uavs) if any(u.winch for u in self.uavs)
                     else None),
            **self.chain_params(),
        )

    def chain_params(self) -> dict[str, Any]:
        """FormationParams' chain fields of `cable_model: chain` (cables.chain), else none."""
        if self.cable_model != 'chain':
            return {}
        from multilift_sim.cables.chain import drag_per_length
        return {'chain_links': self.cable['links'],
                'cable_mass_per_length': self.cable['mass_per_length'],
                'cable_drag_per_length': drag_per_length(self.cable)}

    def with_duration(self, duration: float) -> 'Scenario':
        """The same scenario flown for `duration` [s] (a `--duration` override); ScenarioError
        unless it is at least one control period."""
        if not flies_a_period(duration, self.simulation.control_rate):
            raise ScenarioError(f'duration: {duration!r} '
                                f'{one_period_rule(self.simulation.control_rate)}')
        return dataclasses.replace(
            self, simulation=dataclasses.replace(self.simulation, duration=float(duration)))

    def total_weight(self) -> float:
        """Weight of every UAV and the payload [N]."""
        mass = sum(u.vehicle.mass for u in self.uavs) + self.payload.mass
        return mass * self.simulation.gravity


def flies_a_period(duration: float, control_rate: float) -> bool:
    """A run integrates whole control periods and asks for commands before t_max only: it
    needs at least one period, or there is nothing to integrate."""
    return math.isfinite(duration) and round(duration * control_rate) >= 1


def one_period_rule(control_rate: float) -> str:
    return f'must be at least one control period (1/control_rate = {1.0 / control_rate:g} s)'
