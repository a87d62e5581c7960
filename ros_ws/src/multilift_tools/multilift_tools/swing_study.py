"""`multilift study swing_feedback`: the payload feedback (`control.payload_feedback`: the
mission's corners shaped at the payload's pendulum period, multilift_control.mission, and the
leader's swing feedback, multilift_control.laws.swing; issue 20 item 5, beyond the seed)
against the seed's law on the
seed's missions whose payload can swing under its UAVs (one UAV, or two: three or more UAVs
not on a line hold the payload at one place under them, and its swing from there is zero).

Each mission is flown by the engine (multilift_control.engine) as its scenario says (the seed's
law), with the textbook anti-sway law (TEXTBOOK) and with FEEDBACK's `control.payload_feedback`.
Measured, world frame, SI units:
- the payload's swing (multilift_sim.statistics.payload_swing: its horizontal distance from its
  rest place under the UAVs), rms over the 10 s after each corner of the mission (the end of
  each segment but the last) and over the run;
- the leader's tracking error |r_ref - r_1| against the reference it tracks (the seed's figure)
  and against the seed law's reference; the payload's, |r_ref + (r_p - r_1)_rest - r_p| (where
  the mission puts the payload);
- what the input shaping costs the path: how far the shaped reference passes from the seed
  law's reference path (the nearest point of that curve, max over the run);
- rotor saturation: the UAV-seconds with a rotor at a limit; the least cable tension.
Writes swing_feedback.md (the table), .json and a figure per mission (swing, tracking).
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from multilift_control.engine import Engine
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario import Scenario, load
from multilift_sim.start import formation_start
from multilift_sim.statistics import payload_swing

# the swing feedback flown (control.payload_feedback, the same for every mission): chosen by
# sweeps of this study's flights on the twin-lift (docs/reproduction.md tells the trade-offs)
FEEDBACK = {'input_shaping': 'zvdd', 'swing_stiffness': 0.25, 'swing_damping': -0.2,
            'swing_limit': 0.15}
# its foil: the textbook anti-sway law (a crane trolley chasing the swing, k_d > 0 alone, the
# corners unshaped), which against the leader's position loop makes the swing worse
TEXTBOOK = {'swing_damping': 1.0}
MISSIONS = ('single_lift', 'twin_lift')
WINDOW = 10.0  # [s] after each corner


@dataclass(frozen=True)
class LawRun:
    """One law's flight of a mission, sampled at every control tick."""

    label: str
    t: np.ndarray                # (T,) [s]
    swing: np.ndarray            # (T,) [m]
    leader_error: np.ndarray     # (T,) [m], against its own reference
    seed_reference_error: np.ndarray  # (T,) [m], against the seed law's reference
    payload_error: np.ndarray    # (T,) [m]
    path_offset: float           # its reference's largest distance from the seed law's path [m]
    reference: np.ndarray        # (T, 3) [m] the reference the leader tracked
    saturated_seconds: float     # UAV-seconds with a rotor at a limit [s]
    least_tension: float         # [N]; < 0: the rigid cable pushed (a real one goes slack)


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(values ** 2))) if values.size else float('nan')


def corners(scenario: Scenario) -> list[float]:
    """The mission's corners [s]: the end of each segment but the last."""
    return [s.end_time for s in scenario.mission.segments][:-1]


def payload_rest_offset(scenario: Scenario) -> np.ndarray:
    """(r_p - r_1) at the formation's hanging rest [m] (3,), world."""
    if scenario.n_uavs == 1:
        return np.array([0.0, 0.0, -scenario.uavs[0].cable_length])
    uavs, payload = formation_start(scenario)
    return payload - uavs[0]


def with_feedback(scenario: Scenario, feedback: dict | None = None) -> Scenario:
    """`scenario` with `control.payload_feedback` (FEEDBACK's fields by default)."""
    return dataclasses.replace(scenario, control=dataclasses.replace(
        scenario.control, **(FEEDBACK if feedback is None else feedback)))


def _path_offset(reference: np.ndarray, seed_path: np.ndarray) -> float:
    """The largest distance [m] of a reference's points (T, 3) from the polyline `seed_path`
    (K, 3): for each point its nearest segment."""
    start, end = seed_path[:-1], seed_path[1:]
    along = end - start
    length = np.maximum(np.einsum('ij,ij->i', along, along), 1e-300)
    worst = 0.0
    for point in reference:
        u = np.clip(np.einsum('ij,ij->i', point - start, along) / length, 0.0, 1.0)
        nearest = start + u[:, None] * along
        worst = max(worst, float(np.sqrt(np.min(np.sum((nearest - point) ** 2, axis=1)))))
    return worst


def law_label(control) -> str:
    """A law's name in the table: the seed's, or its payload feedback's settings."""
    if control.input_shaping == 'none' and not (control.swing_stiffness or
                                                control.swing_damping):
        return 'seed law'
    return (f'payload feedback: {control.input_shaping} shaping, k_s={control.swing_stiffness:g}'
            f', k_d={control.swing_damping:g}, a_max={control.swing_limit:g}')


def fly(scenario: Scenario, feedbacks: tuple[dict, ...] = (TEXTBOOK, FEEDBACK)) -> list[LawRun]:
    """The mission under the seed's law, then with each of `feedbacks` (ControlConfig fields
    of control.payload_feedback)."""
    flown = [scenario] + [with_feedback(scenario, feedback) for feedback in feedbacks]
    ticks = int(round(scenario.simulation.duration * scenario.simulation.control_rate))
    records = []
    for law in flown:  # an engine each: a shaped mission has more steps
        engine = Engine(law)
        record = engine.new_record(ticks)
        engine.step(ticks, record)
        records.append(record)
    layout = StateLayout(scenario.n_uavs)
    t = np.arange(ticks) / scenario.simulation.control_rate
    lengths = np.array([u.cable_length for u in scenario.uavs])
    rest = payload_rest_offset(scenario)
    seed_reference = records[0].reference[:, 0, :3]
    runs = []
    for record, law in zip(records, flown):
        x = record.states[:, 0]
        uavs, payload = layout.uav_positions(x), layout.payload_position(x)
        reference = record.reference[:, 0, :3]
        runs.append(LawRun(
            label=law_label(law.control), t=t, swing=payload_swing(uavs, payload, lengths),
            leader_error=np.linalg.norm(reference - uavs[:, 0], axis=1),
            seed_reference_error=np.linalg.norm(seed_reference - uavs[:, 0], axis=1),
            payload_error=np.linalg.norm(reference + rest - payload, axis=1),
            path_offset=_path_offset(reference[::10], seed_reference), reference=reference,
            saturated_seconds=float(record.saturated[:, 0].any(axis=2).sum())
            / scenario.simulation.control_rate,
            least_tension=float(record.tension[:, 0].min())))
    return runs


def metrics(run: LawRun, scenario: Scenario) -> dict:
    """The table's numbers of one run."""
    after = [_rms(run.swing[(run.t >= c) & (run.t < c + WINDOW)]) for c in corners(scenario)]
    return {'law': run.label, 'swing_rms_after_corners': after,
            'swing_rms': _rms(run.swing), 'swing_max': float(run.swing.max()),
            'leader_tracking_rms': _rms(run.leader_error),
            'leader_error_from_seed_reference_rms': _rms(run.seed_reference_error),
            'payload_tracking_rms': _rms(run.payload_error), 'path_offset': run.path_offset,
            'saturated_uav_seconds': run.saturated_seconds,
            'least_tension': run.least_tension}


def _table(results: dict[str, list[dict]], scenarios: dict[str, Scenario]) -> str:
    lines = ['| mission | law | swing rms, 10 s after each corner [m] | swing rms / max [m] | '
             'leader tracking rms [m] | leader from the seed law\'s reference, rms [m] | '
             'payload tracking rms [m] | reference from the seed law\'s path, max [m] | '
             'rotors saturated [UAV s] | least tension [N] |', '|' + '---|' * 10]
    for name, rows in results.items():
        times = ', '.join(f'{c:g}' for c in corners(scenarios[name]))
        for row in rows:
            swing = ' / '.join(f'{v:.3f}' for v in row['swing_rms_after_corners'])
            lines.append(f'| {name} (corners at {times} s) | {row["law"]} | {swing} | '
                         f'{row["swing_rms"]:.3f} / {row["swing_max"]:.2f} | '
                         f'{row["leader_tracking_rms"]:.3f} | '
                         f'{row["leader_error_from_seed_reference_rms"]:.3f} | '
                         f'{row["payload_tracking_rms"]:.3f} | {row["path_offset"]:.2f} | '
                         f'{row["saturated_uav_seconds"]:.2f} | {row["least_tension"]:.2f} |')
        seed, damped = rows[0], rows[-1]  # the ratios of the last law to the seed's
        ratios = ' / '.join(f'{d / s:.2f}' for s, d in zip(seed['swing_rms_after_corners'],
                                                            damped['swing_rms_after_corners']))
        lines.append(f'| {name} | last / seed | {ratios} | '
                     f'{damped["swing_rms"] / seed["swing_rms"]:.2f} | '
                     f'{damped["leader_tracking_rms"] / seed["leader_tracking_rms"]:.2f} | | '
                     f'{damped["payload_tracking_rms"] / seed["payload_tracking_rms"]:.2f} | '
                     f'| {damped["saturated_uav_seconds"] / seed["saturated_uav_seconds"]:.2f}'
                     f' | |')
    return '\n'.join(lines)


def _plot(runs: list[LawRun], scenario: Scenario, path: Path) -> None:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(11.0, 6.5), layout='constrained')
    axes = figure.subplot_mosaic([['swing', 'top'], ['leader', 'top'], ['payload', 'top']],
                                 width_ratios=[2.2, 1.0])
    swing, leader, payload, top = (axes[k] for k in ('swing', 'leader', 'payload', 'top'))
    leader.sharex(swing)
    payload.sharex(swing)
    for run in runs:
        swing.plot(run.t, run.swing, label=run.label, linewidth=1.0)
        leader.plot(run.t, run.leader_error, linewidth=1.0)
        payload.plot(run.t, run.payload_error, linewidth=1.0)
        top.plot(run.reference[:, 0], run.reference[:, 1], linewidth=1.0)
    top.set_aspect('equal', adjustable='box')
    top.set_xlabel('x [m]')
    top.set_ylabel('y [m]')
    top.set_title('the references, top view (world)', fontsize=9)
    top.grid(True, alpha=0.3)
    for axes in (swing, leader, payload):
        for corner in corners(scenario):
            axes.axvline(corner, color='0.6', linewidth=0.8, linestyle=':')
            axes.axvspan(corner, corner + WINDOW, color='0.9', zorder=0)
        axes.grid(True, alpha=0.3)
    swing.set_ylabel('payload swing [m]')
    leader.set_ylabel('leader |r_ref - r_1| [m]')
    payload.set_ylabel('payload tracking [m]')
    payload.set_xlabel('time t [s] (shaded: the 10 s after each corner)')
    swing.set_title(f'{scenario.name}: the seed\'s law and the payload feedback', fontsize=10)
    swing.legend(fontsize=8)
    figure.savefig(path, dpi=110)


def swing_feedback_study(out_dir: str | Path, missions: tuple[str, ...] = MISSIONS,
                         feedbacks: tuple[dict, ...] = (TEXTBOOK, FEEDBACK)) -> dict:
    """Fly each mission under the seed's law and with each of `feedbacks` (ControlConfig
    fields; the last is the one the ratios compare); write swing_feedback.md, .json and
    swing_feedback_<mission>.png to out_dir. Returns {'rows': {mission: [seed, *feedbacks]},
    'files', 'table'}."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results, scenarios, files = {}, {}, {}
    for name in missions:
        scenario = load(name)
        runs = fly(scenario, feedbacks)
        scenarios[name] = scenario
        results[name] = [metrics(run, scenario) for run in runs]
        files[name] = str(out / f'swing_feedback_{name}.png')
        _plot(runs, scenario, Path(files[name]))
    table = _table(results, scenarios)
    files['table'] = str(out / 'swing_feedback.md')
    Path(files['table']).write_text(table + '\n')
    files['json'] = str(out / 'swing_feedback.json')
    Path(files['json']).write_text(json.dumps({'feedbacks': feedbacks, 'rows': results},
                                              indent=1))
    return {'rows': results, 'files': files, 'table': table}
