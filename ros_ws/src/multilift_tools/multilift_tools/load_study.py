"""`multilift study load_sharing` (issue 35 item 5, beyond the seed: the seed's §5.2 third
suggestion): the seed's fixed geometry, the reorganising formation (`formation.reorganize:
thrust_margin`) and the cable-force allocation (`cable_forces`) flown on the same missions.

Each mission is flown by the engine with each `formation.reorganize` its formation accepts (a
mode the scenario's validation refuses is a row saying why, not a number). Measured, world
frame, SI units, at every control tick of the whole run:
- rotor saturation: each UAV's time with a rotor at a limit the allocator wanted it beyond
  (the summary's `saturated_time`), summed over the UAVs [UAV s];
- the least thrust margin 1 - u_T / u_T,max of each UAV's commands (the summary's);
- the leader's tracking error (max and rms), the payload's swing (max; from its rest place
  under the UAVs, statistics.payload_swing) and the followers' formation error (the largest
  |g_vc| row, against the moved targets where the formation reorganises);
- the least distance between two UAVs' centres [m] (horizontal spacing is what
  `formation.min_spacing` bounds; this is the 3-D distance).
Writes load_sharing.md (the table), .json and load_sharing.png (the margins and the saturation
by mission and mode).
"""
from __future__ import annotations

import itertools
import json
import time
from pathlib import Path

import numpy as np
import yaml

from multilift_control.engine import Engine
from multilift_sim import scenario as scenario_io
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario import ScenarioError

# beam_lift and v3_box_mixed carry rigid bodies
MISSIONS = ('twin_lift', 'multi_lift', 'v3_mixed', 'beam_lift', 'v3_box_mixed')
MODES = ('none', 'thrust_margin', 'cable_forces')
AFTER = 10.0   # [s] the least margins after the start (v3_mixed hovers 10 s, reorganising)


def variant(name: str, mode: str) -> scenario_io.Scenario:
    """Scenario `name` with `formation.reorganize: mode` (its other formation keys kept but
    `start_places` in a mode that does not reorganise: the fixed geometry starts at its places);
    ScenarioError when its formation cannot fly that mode."""
    path = scenario_io.resolve(name)
    data = scenario_io.read_yaml(path.read_text())
    data.setdefault('formation', {})['reorganize'] = mode
    if mode not in ('thrust_margin', 'cable_forces'):
        data['formation'].pop('start_places', None)
    return scenario_io.loads(yaml.safe_dump(data), where=str(path))


def least_spacing(states: np.ndarray, n: int) -> float:
    """The least distance [m] between two UAVs' centres over states (T, len(x))."""
    if n < 2:
        return float('nan')
    uavs = StateLayout(n).uav_positions(states)           # (T, n, 3)
    return float(min(np.linalg.norm(uavs[:, i] - uavs[:, j], axis=1).min()
                     for i, j in itertools.combinations(range(n), 2)))


def thrust_margins(speeds: np.ndarray, scenario: scenario_io.Scenario) -> np.ndarray:
    """Each UAV's thrust margin 1 - sum omega^2 / (N omega_max^2) (T, n) of its commanded
    rotor speeds (T, n, rotors) [rad/s] (every rotor fully effective; N its rotor count)."""
    out = np.empty(speeds.shape[:2])
    for i, uav in enumerate(scenario.uavs):
        out[:, i] = uav.vehicle.thrust_margin(speeds[:, i, :uav.vehicle.n_rotors])
    return out


def fly_mode(scenario: scenario_io.Scenario) -> dict:
    """One mode's flight of a mission: the table's numbers, and each UAV's thrust margin at
    every tick ('margins' (T, n), 't' (T,) [s])."""
    start = time.monotonic()
    engine = Engine(scenario)
    ticks = int(engine.arrays.tick_count[0])
    record = engine.new_record(ticks)
    flown = int(engine.step(ticks, record)[0])    # fewer where Algorithm 1 stopped it
    summary = engine.summary(0, time.monotonic() - start)
    sim, leader = summary['sim'], summary['leader']
    followers = [v for k, v in summary.items() if k.startswith('follower')]
    t = np.arange(flown) / scenario.simulation.control_rate
    margins = thrust_margins(record.speeds[:flown, 0], scenario)
    return {'error': sim.get('error'), 'saturated_uav_seconds': float(sum(sim['saturated_time'])),
            'saturated_time': sim['saturated_time'],
            'least_thrust_margin': sim['least_thrust_margin'],
            'leader_tracking_max': leader['max_tracking_error'],
            'leader_tracking_rms': leader['rms_tracking_error'],
            'swing_max': sim['max_payload_swing'],
            'formation_error_max': max((f['max_abs_formation_error'] for f in followers),
                                       default=float('nan')),
            'least_uav_distance': least_spacing(record.states[:flown, 0], scenario.n_uavs),
            'least_thrust_margin_after': np.min(margins[t >= AFTER], axis=0).tolist(),
            't': t, 'margins': margins}


def load_sharing_study(out_dir: str | Path, missions: tuple[str, ...] = MISSIONS) -> dict:
    """Fly each mission in each mode; write load_sharing.md, .json and .png to out_dir.
    Returns {'rows': {mission: {mode: numbers or {'refused': why}}}, 'files', 'table'}."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows: dict[str, dict[str, dict]] = {}
    for name in missions:
        rows[name] = {}
        for mode in MODES:
            try:
                scenario = variant(name, mode)
            except ScenarioError as error:  # the formation cannot fly this mode: say why
                rows[name][mode] = {'refused': str(error).split(': ', 1)[-1]}
                continue
            rows[name][mode] = fly_mode(scenario)
    table = _table(rows)
    files = {'table': str(out / 'load_sharing.md'), 'json': str(out / 'load_sharing.json'),
             'figure': str(out / 'load_sharing.png')}
    Path(files['table']).write_text(table + '\n')
    _plot(rows, Path(files['figure']))
    for modes in rows.values():   # the table's numbers (the series are in the figure)
        for r in modes.values():
            r.pop('t', None), r.pop('margins', None)
    Path(files['json']).write_text(json.dumps(rows, indent=1))
    return {'rows': rows, 'files': files, 'table': table}


def _margins(values: list) -> str:
    return ', '.join('-' if v is None else f'{100 * v:.1f}' for v in values)


def _table(rows: dict[str, dict[str, dict]]) -> str:
    lines = ['| mission | formation.reorganize | rotors saturated [UAV s] (per UAV) | '
             'least thrust margin per UAV [%], whole run / after 10 s | '
             'leader tracking max / rms [m] | payload swing max [m] | '
             'formation error max [m or m^2] | least UAV distance [m] |', '|' + '---|' * 8]
    for name, modes in rows.items():
        for mode, r in modes.items():
            if 'refused' in r:
                lines.append(f'| {name} | {mode} | not flown: {r["refused"]} | | | | | |')
                continue
            saturated = ', '.join(f'{v:.2f}' for v in r['saturated_time'])
            stopped = f' (stopped: {r["error"]})' if r['error'] else ''
            lines.append(
                f'| {name} | {mode}{stopped} | {r["saturated_uav_seconds"]:.2f} ({saturated}) | '
                f'{_margins(r["least_thrust_margin"])} / '
                f'{_margins(r["least_thrust_margin_after"])} | {r["leader_tracking_max"]:.3f} / '
                f'{r["leader_tracking_rms"]:.3f} | {r["swing_max"]:.3f} | '
                f'{r["formation_error_max"]:.3f} | {r["least_uav_distance"]:.2f} |')
    return '\n'.join(lines)


def _plot(rows: dict[str, dict[str, dict]], path: Path) -> None:
    """Per mission and mode, the least thrust margin after AFTER s and the saturation (bars;
    n/a: a mode the formation cannot fly); each mission's weakest UAV's margin against time
    for every mode (its least margin in the fixed geometry)."""
    from matplotlib.figure import Figure

    names = list(rows)
    figure = Figure(figsize=(12.0, 3.0 + 2.2 * len(names)), layout='constrained')
    grid = figure.add_gridspec(len(names), 2, width_ratios=[1.0, 1.6])
    margin_axes = figure.add_subplot(grid[:len(names) // 2 or 1, 0])
    saturation_axes = figure.add_subplot(grid[len(names) // 2 or 1:, 0], sharex=margin_axes)
    width = 0.8 / len(MODES)
    for k, mode in enumerate(MODES):
        x = np.arange(len(names)) + (k - (len(MODES) - 1) / 2) * width
        flown = [rows[n][mode] for n in names]
        least = [np.nan if 'refused' in r else min(r['least_thrust_margin_after'])
                 for r in flown]
        margin_axes.bar(x, 100 * np.array(least), width, label=f'reorganize: {mode}')
        saturation_axes.bar(x, [r.get('saturated_uav_seconds', np.nan) for r in flown], width)
        for xi, r in zip(x, flown):
            if 'refused' in r:
                for axes in (margin_axes, saturation_axes):
                    axes.text(xi, 0.0, 'n/a', ha='center', va='bottom', fontsize=7)
    margin_axes.set_ylabel(f'least thrust margin of\nany UAV after {AFTER:g} s [%]')
    saturation_axes.set_ylabel('rotors saturated,\nwhole run [UAV s]')
    saturation_axes.set_xticks(np.arange(len(names)), names, fontsize=8)
    margin_axes.legend(fontsize=7)
    for axes in (margin_axes, saturation_axes):
        axes.grid(True, axis='y', alpha=0.3)
        axes.tick_params(axis='x', labelsize=8)  # five missions' names side by side
    for row, name in enumerate(names):
        axes = figure.add_subplot(grid[row, 1])
        fixed = rows[name]['none']
        weakest = int(np.argmin(fixed['least_thrust_margin_after'])) if 'refused' not in fixed \
            else 0
        for mode in MODES:
            r = rows[name][mode]
            if 'refused' not in r:
                axes.plot(r['t'], 100 * r['margins'][:, weakest], linewidth=0.8,
                          label=f'reorganize: {mode}')
        axes.axhline(0.0, color='0.3', linewidth=0.7)
        axes.legend(fontsize=7, loc='lower right')
        axes.set_ylabel(f'{name}\nuav{weakest + 1} margin [%]', fontsize=8)
        axes.grid(True, alpha=0.3)
        if row == 0:
            axes.set_title('the weakest UAV\'s thrust margin against time', fontsize=9)
        if row == len(names) - 1:
            axes.set_xlabel('time t [s]')
    figure.suptitle('Sharing the load: the fixed geometry, the reorganising formation and the '
                    'cable-force allocation', fontsize=10)
    figure.savefig(path, dpi=110)
