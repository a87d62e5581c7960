"""Prescribed motion in a scenario (issue 34 item 3), validated once: `uavs[i].trajectory` (a
CSV `t,x,y,z[,vx,vy,vz[,ax,ay,az]][,roll,pitch,yaw]`, world z up, SI, relative to the
scenario's folder; splined by `drives.spline_drive`) and `payload.initial_position` /
`initial_velocity` (world [m], [m/s]). A bad file, a file that does not cover the run, a
scenario the prescribed DAE does not model or a payload start that does not fit the cables is
one line (ScenarioError: exit 2)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from multilift_sim.drives import Drive, spline_drive
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario.config import Scenario, ScenarioError
from multilift_sim.scenario.csv_table import read_table
from multilift_sim.scenario.reading import Section

REQUIRED = ('t', 'x', 'y', 'z')
GROUPS = (('vx', 'vy', 'vz'), ('ax', 'ay', 'az'), ('roll', 'pitch', 'yaw'))
# |chord - l_i| [m] a rigid cable's payload start may be off its length (the Baumgarte
# stabilisation takes it in; Algorithm 1's check applies from t = 0)
START_TOLERANCE = 1e-3


def scenario_folder(where: str) -> Path:
    """The folder a scenario's files are relative to: its file's, else the working one."""
    source = Path(where)
    return source.parent if source.is_file() else Path.cwd()


def read_trajectory(u: Section, folder: Path, yaw: float) -> Drive | None:
    """`uavs[i].trajectory` read and splined, or None without the key; `yaw` [rad] the UAV's
    (its level attitude without roll, pitch, yaw columns)."""
    if not u.has('trajectory'):
        return None
    optional = tuple(c for group in GROUPS for c in group)
    present, data = read_table(u, 'trajectory', folder, REQUIRED, optional)
    name = u.data['trajectory']
    groups = []
    for group in GROUPS:
        given = [c for c in group if c in present]
        if given and len(given) < len(group):
            missing = next(c for c in group if c not in present)
            raise u.fail('trajectory', name, f'lacks the column {missing!r} '
                         f'({",".join(group)} go together)')
        groups.append(data[:, [present.index(c) for c in group]] if given else None)
    velocities, accelerations, euler = groups
    if accelerations is not None and velocities is None:
        raise u.fail('trajectory', name, 'lacks the column \'vx\' (ax,ay,az need vx,vy,vz)')
    position = data[:, [present.index(c) for c in REQUIRED[1:]]]
    return spline_drive(str(name), data[:, 0], position, velocities, accelerations, euler, yaw)


def check_prescribed(scenario: Scenario) -> None:
    """What only a prescribed scenario must satisfy: each file covers [0, duration]; every
    UAV prescribed or none (a formation of both is not built yet); rigid cables from the UAVs'
    centres on a point payload (what `physics.prescribed` models); then the payload's start
    (`check_payload_start`)."""
    where = scenario.source
    prescribed = scenario.prescribed
    duration = scenario.simulation.duration
    for i in prescribed:
        drive = scenario.uavs[i].trajectory
        if drive.start > 0.0 or drive.end < duration:
            raise ScenarioError(
                f'{where}: uavs[{i}].trajectory: {drive.source!r} covers {drive.start:g} .. '
                f'{drive.end:g} s, must cover the run, 0 .. {duration:g} s')
    if prescribed:
        if len(prescribed) < scenario.n_uavs:
            free = next(i for i in range(scenario.n_uavs) if i not in prescribed)
            raise ScenarioError(
                f'{where}: uavs[{free}]: has no trajectory while uavs[{prescribed[0]}] has '
                'one: either every UAV\'s motion is prescribed or none (a formation of both '
                'is not built yet)')
        if len(prescribed) > 3:  # D D^T of the driven cables (n x n, rank 3) is singular
            raise ScenarioError(
                f'{where}: uavs[3].trajectory: at most 3 prescribed UAVs: a point payload on '
                f'{len(prescribed)} driven rigid cables is held by more constraints than it has '
                'coordinates (their tensions are not determined)')
        for i in prescribed:
            if any(scenario.uavs[i].attach_point):
                raise ScenarioError(f'{where}: uavs[{i}].attach_point: a prescribed UAV holds '
                                    'its cable at its centre')
        if scenario.cable_model != 'rigid' or scenario.payload.type != 'point':
            raise ScenarioError(
                f'{where}: uavs[{prescribed[0]}].trajectory: prescribed motion needs '
                f'cable_model: rigid and payload.type: point, got {scenario.cable_model!r} '
                f'and {scenario.payload.type!r}')
    check_payload_start(scenario)


def check_payload_start(scenario: Scenario) -> None:
    """`payload.initial_position` against the cables from the UAVs' start places: each
    chord within START_TOLERANCE of its cable's length (rigid or elastic: its start length),
    at most the length for a slack cable; `initial_velocity` with a rigid cable's rate
    g_dot_i = 2 d_i . (v_p - v_i) within Algorithm 1's constraint_rate_tolerance (else the run
    would stop at t = 0); a rigid-body payload starts hanging."""
    from multilift_sim.cables import CABLE_MODELS
    from multilift_sim.start import initial_state, start_lengths, uav_start_motion
    payload = scenario.payload
    if payload.initial_position is None and payload.initial_velocity is None:
        return
    if payload.type != 'point':
        raise ScenarioError(f'{scenario.source}: payload.initial_position: a {payload.type} '
                            'payload starts hanging (a point payload only)')
    slackens = CABLE_MODELS[scenario.cable_model].SLACKENS
    ends, velocities = uav_start_motion(scenario)
    if payload.initial_velocity is not None and CABLE_MODELS[scenario.cable_model].KEEPS_LENGTH \
            and not slackens:
        layout = StateLayout(scenario.n_uavs)
        state = initial_state(scenario)
        offsets = layout.payload_position(state) - ends
        rates = 2.0 * np.sum(offsets * (layout.payload_velocity(state) - velocities), axis=1)
        tolerance = scenario.simulation.constraint_rate_tolerance
        for i, rate in enumerate(rates):
            if abs(rate) > tolerance:
                raise ScenarioError(
                    f'{scenario.source}: payload.initial_velocity: '
                    f'{list(payload.initial_velocity)} moves along cable {i + 1}: its rate '
                    f'g_dot = {rate:.3g} m^2/s must be within simulation.'
                    f'constraint_rate_tolerance ({tolerance:g})')
    if payload.initial_position is None:
        return
    start = np.asarray(payload.initial_position, dtype=float)
    for i, (uav, length) in enumerate(zip(ends, start_lengths(scenario))):
        chord = float(np.linalg.norm(start - uav))
        fits = chord <= length + START_TOLERANCE if slackens else \
            abs(chord - length) <= START_TOLERANCE
        if not fits:
            rule = (f'at most its length {length:g} m' if slackens else
                    f'its length {length:g} m within {START_TOLERANCE:g} m')
            raise ScenarioError(
                f'{scenario.source}: payload.initial_position: {list(payload.initial_position)}'
                f' is {chord:.6g} m from uav{i + 1}\'s cable end at the start, {uav.tolist()};'
                f' cable {i + 1} must span {rule}')


def finite_vector(p: Section, key: str) -> tuple[float, float, float] | None:
    """A payload start vector `key` (world), None without it."""
    if not p.has(key):
        return None
    value = p.vector(key)
    if not all(math.isfinite(v) for v in value):
        raise p.fail(key, list(value), 'must be finite')
    return value
