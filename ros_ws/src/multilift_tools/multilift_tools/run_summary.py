"""What `multilift run` shows of a run: its simulated time and real-time factor while it runs
(`Progress`), and the summary at its end from what each node left (`read_summaries`,
`print_summary`: max |g|, rotor speeds, saturation, tensions, swing, tracking, formation
errors; with a bag also BAG/summary.json), each figure in its unit from `multilift_sim.units`.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from multilift_sim.units import unit_of


class Progress:
    """Simulated time and real-time factor, on one terminal line (or a line every 10 %)."""

    def __init__(self, path: Path | None, tty: bool):
        self.path = path
        self.tty = tty
        self.last_decile = -1

    def __call__(self) -> None:
        """Show what the simulator node last wrote to the progress file."""
        try:
            t, t_max, wall = (float(v) for v in self.path.read_text().split())
        except (OSError, ValueError):
            return
        self.show(t, t_max, wall)

    def show(self, t: float, t_max: float, wall: float) -> None:
        """Simulated time t of t_max [s] after `wall` seconds."""
        rtf = t / wall if wall > 0 else 0.0
        if self.tty:
            print(f'\r  t = {t:7.2f} / {t_max:.1f} s   {rtf:5.1f}x real time ',
                  end='', flush=True)
        elif t_max > 0 and int(10 * t / t_max) > self.last_decile:
            self.last_decile = int(10 * t / t_max)
            print(f'  t = {t:.1f} / {t_max:.1f} s   {rtf:.1f}x real time', flush=True)

    def close(self) -> None:
        if self.tty:
            print()


def estimation_lines(estimation: dict | None) -> list[str]:
    """The estimators' errors against the truth over the run (issue 33 item 6): each UAV's
    position and attitude rms and mean NEES (3 dof: 3 when consistent), the payload's
    position and velocity rms and mean NEES; nothing without an estimator."""
    if not estimation:
        return []
    lines = [f'  estimate uav{i + 1}    position rms {p * 1e3:.2f} mm (NEES {pn:.2f}), attitude '
             f'rms {a * 1e3:.2f} mrad (NEES {an:.2f})'
             for i, (p, pn, a, an) in enumerate(zip(
                 estimation['position_rms'], estimation['position_nees'],
                 estimation['attitude_rms'], estimation['attitude_nees']))]
    if 'payload_position_rms' in estimation:
        lines.append(f'  estimate payload position rms {estimation["payload_position_rms"]:.4f} '
                     f'm (NEES {estimation["payload_nees"]:.2f}), velocity rms '
                     f'{estimation["payload_velocity_rms"]:.4f} m/s')
    return lines


def read_summaries(summary_dir: Path, scenario) -> dict:
    """What each node of a run left in `summary_dir` (sim, leader, follower2, ...)."""
    data = {}
    parts = ['sim', 'leader'] + [f'follower{i}' for i in range(2, scenario.n_uavs + 1)]
    for part in parts:
        path = summary_dir / f'{part}.json'
        if path.is_file():
            data[part] = json.loads(path.read_text())
    return data


def print_summary(name: str, data: dict, bag: Path | None, scenario) -> None:
    """Print the end-of-run summary; with a bag, also leave it as BAG/summary.json."""
    sim = data.get('sim', {})
    lines = []
    if sim:
        wall = sim.get('wall_time') or 0.0
        t = sim.get('simulated_time', 0.0)
        lines.append(f'{name}: {t:.1f} {unit_of("simulated_time")} simulated in {wall:.1f} '
                     f'{unit_of("wall_time")} wall '
                     f'({t / wall if wall else 0:.1f}x real time)')
        tol = scenario.simulation.constraint_tolerance
        bound = (f'tolerance {tol:g}' if 'max_stretch' not in sim else
                 'the ropes\' stretch: no tolerance, ropes are no constraints')
        lines.append(f'  max |g|          {sim["max_abs_constraint"]:.3g} {unit_of("max_abs_g")} '
                     f'({bound})')
        lines.append(f'  max |g_dot|      {sim["max_abs_constraint_rate"]:.3g} '
                     f'{unit_of("max_abs_g_dot")}')
        margins = sim.get('least_thrust_margin') or [None] * len(sim['max_rotor_speed'])
        for i, (w, s, margin) in enumerate(zip(sim['max_rotor_speed'], sim['saturated_time'],
                                               margins)):
            drive = scenario.uavs[i].trajectory
            if drive is not None:  # no controller, no rotors flown (docs/prescribed.md)
                lines.append(f'  uav{i + 1} prescribed  by {drive.source} (no controller)')
                continue
            limit = scenario.uavs[i].vehicle.rotor_speed_max
            left = '' if margin is None else f', thrust margin least {100 * margin:.1f} %'
            lines.append(f'  uav{i + 1} rotors      max {w:.1f} {unit_of("max_rotor_speed")} '
                         f'(limit {limit:g}), saturated {s:.2f} {unit_of("saturated_time")}'
                         f'{left}')
        lines.extend(fault_lines(scenario, sim.get('events', []), sim.get('simulated_time')))
        lines.append(f'  cable tension    {sim["min_tension"]:.2f} .. {sim["max_tension"]:.2f} '
                     f'{unit_of("max_tension")}')
        for i, (stretch, peak) in enumerate(zip(sim.get('max_stretch', []),
                                                sim.get('peak_tension', []))):
            lines.append(f'  rope {i + 1}           max stretch {stretch:.3g} '
                         f'{unit_of("max_stretch")}, peak '
                         f'tension {peak:.2f} {unit_of("peak_tension")} (at the control ticks)')
        for i, sag in enumerate(sim.get('max_sag', [])):  # a chain's (cable_model: chain)
            lines.append(f'  chain {i + 1}          max sag {sag:.3f} {unit_of("max_sag")} '
                         '(from its chord, at the control ticks)')
        for i in scenario.winches if 'longest_cable' in sim else ():  # a winch's reeled range
            shortest, longest = sim['shortest_cable'][i - 1], sim['longest_cable'][i - 1]
            lines.append(f'  cable {i} (winch)  length {shortest:.3f} .. {longest:.3f} '
                         f'{unit_of("longest_cable")} (at the control ticks)')
        if sim.get('compressed_time'):
            lines.append(f'  warning: a cable pushed for {sim["compressed_time"]:.2f} '
                         f'{unit_of("compressed_time")} (least tension {sim["min_tension"]:.2f} '
                         f'{unit_of("min_tension")}): rigid cables can push; '
                         '`cable_model: slack` lets them go slack instead')
        if any(sim.get('slack_time', [])):
            lines.append('  slack cables     ' + ', '.join(
                f'cable {i + 1} {s:.2f} {unit_of("slack_time")}'
                for i, s in enumerate(sim['slack_time']) if s > 0))
        if 'max_payload_swing' in sim:
            since = sim.get('swing_from', 0.0)
            if sim.get('simulated_time', 0.0) < since:
                lines.append(f'  payload swing    not measured (from t = {since:g} s on)')
            else:
                lines.append(f'  payload swing    max {sim["max_payload_swing"]:.3f} '
                             f'{unit_of("payload_swing_max")}, rms '
                             f'{sim["rms_payload_swing"]:.3f} {unit_of("payload_swing_rms")} '
                             f'(horizontal, from its rest place under the UAVs, from t = '
                             f'{since:g} s: not the release)')
                if scenario.n_uavs >= 3 and sim['max_payload_swing'] < 5e-4:  # prints 0.000
                    lines.append('                   (three or more taut cables hold the payload '
                                 'where they meet: it cannot swing under the UAVs, only with '
                                 'them)')
        if scenario.gusts:
            lines.append(f'  peak gust speed met by the payload  {sim["max_gust_speed"]:.2f} '
                         f'{unit_of("max_gust_speed")}')
        lines.extend(clearance_lines(sim))
        lines.extend(estimation_lines(sim.get('estimation')))
        if sim.get('seeds'):
            lines.append('  seeds            ' + ', '.join(
                f'{what} {seed}' for what, seed in sim['seeds'].items()))
        for event in sim.get('events', []):
            lines.append(f'  event at {event["time"]:g} s   {event["description"]}')
    control = scenario.control
    if control.input_shaping != 'none' or control.swing_stiffness or control.swing_damping:
        lines.append(f'  payload feedback {control.input_shaping} shaping of the corners, swing '
                     f'k_s {control.swing_stiffness:g}, k_d {control.swing_damping:g}, a_max '
                     f'{control.swing_limit:g} m/s^2 (control.payload_feedback)')
    leader = data.get('leader')
    if leader and leader.get('answered_states'):
        lines.append(f'  leader tracking  max {leader["max_tracking_error"]:.3f} '
                     f'{unit_of("tracking_error_max")}, rms {leader["rms_tracking_error"]:.3f} '
                     f'{unit_of("tracking_error_rms")}')
    for i in range(2, scenario.n_uavs + 1):
        follower = data.get(f'follower{i}')
        if follower and follower.get('answered_states'):
            # the largest row and the mean norm of its rows: the mean can exceed the max
            lines.append(f'  uav{i} formation  largest |g_vc| row '
                         f'{follower["max_abs_formation_error"]:.3f}, mean |g_vc| '
                         f'{follower["mean_formation_error_norm"]:.3f} '
                         f'({unit_of("formation_error_mean")})')
    if bag is not None:
        lines.append(f'  bag              {bag}')
        (bag / 'summary.json').write_text(json.dumps(data, indent=1, sort_keys=True))
    print('\n'.join(lines))


def fault_lines(scenario, events: list[dict], t_end: float | None) -> list[str]:
    """The summary's lines for the rotors that failed (the events that happened, the summary's
    first `len(events)` event rows, whose reaction reallocates a mixer:
    `multilift_control.reactions`) and the rotors their UAV's reallocated mixer then pins at
    omega_min (live, no collective share: `faults.fault_mixers`), each with how long [s]:
    neither counts as saturated."""
    if not events:
        return []
    from multilift_control.faults import fault_mixers, mixer_uavs
    from multilift_control.laws.layout import MIXER_COLLECTIVE, MIXER_WRENCH
    from multilift_sim.physics.layout import EVENT_ROTOR, EVENT_TIME, EVENT_UAV, EVENT_VALUE
    from multilift_sim.schedules import event_array

    rows = event_array(scenario)[:len(events)]
    reallocating = mixer_uavs(scenario)[:len(events)] >= 0
    if not reallocating.any():
        return []
    mixers = fault_mixers(scenario)
    end = t_end if t_end is not None else scenario.simulation.duration
    lines = []
    for k, row in enumerate(rows):
        if not reallocating[k]:
            continue
        uav, start = int(row[EVENT_UAV]) + 1, float(row[EVENT_TIME])
        lines.append(f'  uav{uav} rotor {int(row[EVENT_ROTOR]) + 1}    effectiveness '
                     f'{row[EVENT_VALUE]:g} from {start:g} s ({end - start:.2f} s)')
        for r, mixer_row in enumerate(mixers[k]):
            live = np.any(mixer_row[MIXER_WRENCH:MIXER_WRENCH + 4] != 0.0)
            if live and mixer_row[MIXER_COLLECTIVE] <= 0.0:
                lines.append(f'  uav{uav} rotor {r + 1}    pinned at its minimum speed by the '
                             f'reallocation from {start:g} s ({end - start:.2f} s)')
    return lines


# how the summary words each kind of clearance (statistics.clearance.KIND_NAMES)
CLEARANCE_WORDS = {'uav_world': 'UAV - world', 'cable_world': 'cable - world',
                   'payload_world': 'payload - world', 'uav_uav': 'UAV - UAV',
                   'uav_cable': 'UAV - cable', 'cable_cable': 'cable - cable'}


def clearance_lines(sim: dict) -> list[str]:
    """The least clearance of each kind, when and between what, and a recorded contact (a run
    with a `world:` section; docs/obstacles.md)."""
    if 'clearance' not in sim:
        return []
    lines = []
    for kind in CLEARANCE_WORDS:  # in one order whether read from summary.json or not
        if kind not in sim['clearance']:
            continue
        figure = sim['clearance'][kind]
        first, second = figure['between']
        lines.append(f'  clearance {CLEARANCE_WORDS[kind]:<16} least {figure["value"]:.3f} '
                     f'{unit_of("least_clearance")} at t = {figure["time"]:.2f} s '
                     f'({first} to {second})')
    contact = sim.get('contact')
    if contact:
        first, second = contact['between']
        lines.append(f'  contact          {first} touched {second} at t = {contact["time"]:.3f} '
                     f's (clearance {contact["value"]:.3g} m; recorded, flown on)')
    return lines
