"""The scenario's `world:` section (issue 34 item 5), validated once: `obstacles` (each of a
registered type, multilift_sim.obstacles.OBSTACLE_TYPES: `type`, its size keys, `center`,
optional `name` and `yaw` [rad]), `ground` (a height [m] or null) and `on_contact` (stop or
record); then `check_start`: no body of the formation starts touching the world or another
(the clearances of the start, `physics.clearance.measure`). World frame (z up), SI units."""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.scenario.config import ObstacleConfig, Scenario, ScenarioError, WorldConfig
from multilift_sim.scenario.reading import Section

ON_CONTACT = ('stop', 'record')


def read_world(top: Section) -> WorldConfig | None:
    """The `world:` section, or None without one (no clearance checks)."""
    from multilift_sim.obstacles import OBSTACLE_TYPES
    if not top.has('world'):
        return None
    w = top.section('world')
    ground = w.raw('ground', None)
    ground = None if ground is None else w.number('ground')
    on_contact = w.text('on_contact', 'stop', choices=ON_CONTACT)
    obstacles: list[ObstacleConfig] = []
    for k, entry in enumerate(w.sequence('obstacles', [])):
        o = Section(entry, f'{w.key("obstacles")}[{k}]', top.where)
        kind = o.text('type', choices=tuple(OBSTACLE_TYPES))
        name = o.text('name', f'obstacle{k + 1}')
        if any(other.name == name for other in obstacles):
            raise o.fail('name', name, 'is the name of an obstacle before it')
        half, bound = OBSTACLE_TYPES[kind].parse(o)
        obstacles.append(ObstacleConfig(
            name=name, type=kind, center=o.vector('center'), half=tuple(float(h) for h in half),
            yaw=o.number('yaw', 0.0), bound=float(bound)))
        o.done()
    w.done()
    return WorldConfig(obstacles=tuple(obstacles), ground=ground, on_contact=on_contact)


def world_arrays(scenario: Scenario) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(world (WORLD_COLUMNS,), obstacles (k, OBSTACLE_COLUMNS), UAV radii (n,) [m]) of the
    scenario, the rows physics.clearance reads (WORLD_CHECKED 0 without a `world:`)."""
    from multilift_sim.obstacles import type_index
    from multilift_sim.physics import layout
    world = scenario.world
    row = np.zeros(layout.WORLD_COLUMNS)
    row[layout.WORLD_GROUND] = math.nan
    rows = np.zeros((0 if world is None else len(world.obstacles), layout.OBSTACLE_COLUMNS))
    if world is not None:
        row[layout.WORLD_CHECKED] = 1.0
        row[layout.WORLD_GROUND] = math.nan if world.ground is None else world.ground
        row[layout.WORLD_PAYLOAD_RADIUS] = payload_radius(scenario)
        row[layout.WORLD_RECORD_CONTACT] = float(world.on_contact == 'record')
        for k, o in enumerate(world.obstacles):
            rows[k, layout.OBSTACLE_TYPE] = type_index(o.type)
            rows[k, layout.OBSTACLE_CENTER:layout.OBSTACLE_CENTER + 3] = o.center
            rows[k, layout.OBSTACLE_HALF:layout.OBSTACLE_HALF + 3] = o.half
            rows[k, layout.OBSTACLE_COS_YAW] = math.cos(o.yaw)
            rows[k, layout.OBSTACLE_SIN_YAW] = math.sin(o.yaw)
            rows[k, layout.OBSTACLE_BOUND] = o.bound
    return row, rows, np.array([u.vehicle.radius for u in scenario.uavs], dtype=float)


def payload_radius(scenario: Scenario) -> float:
    """The payload's sphere about r_p [m]: `payload.radius` (a point payload), or the sphere
    about a rigid body's centre that holds its box (half its diagonal: `payload.size`)."""
    payload = scenario.payload
    if payload.type == 'point' or not payload.size:
        return payload.radius
    size = list(payload.size) + [0.0] * (3 - len(payload.size))
    return max(payload.radius, 0.5 * math.sqrt(sum(s * s for s in size)))


def check_start(scenario: Scenario) -> None:
    """ScenarioError (one line) when a body starts touching an obstacle, the ground or another
    body: the clearances of the initial state (`start.initial_state`)."""
    if scenario.world is None:
        return
    from multilift_sim.physics import layout
    from multilift_sim.physics.clearance import measure
    from multilift_sim.start import initial_state
    world, obstacles, radii = world_arrays(scenario)
    params = scenario.formation_params()
    from multilift_sim.formulations import make_formulation
    uavs = make_formulation(scenario.simulation.integrator, params,
                            scenario.cable_model).physics_constants()[0]
    clearance = np.zeros((layout.CLEARANCE_KINDS, layout.CLEARANCE_COLUMNS))
    clearance[:, layout.CLEARANCE_VALUE] = math.inf
    contact = np.full(layout.CLEARANCE_COLUMNS, -1.0)
    measure(world, obstacles, radii, uavs, initial_state(scenario), 0.0, clearance, contact)
    if contact[layout.CLEARANCE_KIND] >= 0:
        first, second = contact_names(scenario, contact)
        raise ScenarioError(f'{scenario.source}: world: {first} starts touching {second} '
                            f'(clearance {contact[layout.CLEARANCE_VALUE]:.3g} m)')


def contact_names(scenario: Scenario, row: np.ndarray, kind: int | None = None
                  ) -> tuple[str, str]:
    """The names of the two bodies of a clearance row (CLEARANCE_*; its kind given, or the
    contact row's own): `uav1`, `cable2`, `payload`, `obstacle 'pillar3'`, `ground`."""
    from multilift_sim.physics import layout
    kind = int(row[layout.CLEARANCE_KIND]) if kind is None else kind
    first, second = int(row[layout.CLEARANCE_FIRST]), int(row[layout.CLEARANCE_SECOND])
    firsts = {layout.CLEARANCE_UAV_WORLD: 'uav', layout.CLEARANCE_CABLE_WORLD: 'cable',
              layout.CLEARANCE_UAV_UAV: 'uav', layout.CLEARANCE_UAV_CABLE: 'uav',
              layout.CLEARANCE_CABLE_CABLE: 'cable'}
    seconds = {layout.CLEARANCE_UAV_UAV: 'uav', layout.CLEARANCE_UAV_CABLE: 'cable',
               layout.CLEARANCE_CABLE_CABLE: 'cable'}
    name = 'payload' if kind == layout.CLEARANCE_PAYLOAD_WORLD else f'{firsts[kind]}{first + 1}'
    if kind in seconds:
        return name, f'{seconds[kind]}{second + 1}'
    if second == layout.OBSTACLE_GROUND:
        return name, 'ground'
    return name, f"obstacle '{scenario.world.obstacles[second].name}'"
