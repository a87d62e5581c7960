"""`multilift study comms` (issue 33 item 5): the V of three (`multi_lift`, seed §4.4) flying
the §4.2 mission with its followers hearing the leader over a radio link (`comms:`,
multilift_sim.links.radio), on a grid of latency and loss, each run flown by the engine.

Measured over the whole run (the summary's figures, SI units): the leader's tracking error
(rms, max), the rotors' saturation summed over the UAVs [UAV s], the least and largest cable
tension [N], and the followers' formation error as they
compute it (from what they hear of the leader: it is what the law sees, not the truth).
Writes comms.md (the table), comms.json and comms.png.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import yaml

from multilift_control.headless import fly
from multilift_sim import scenario as scenario_io

SCENARIO = 'multi_lift'
LATENCIES = (0.0, 0.05, 0.1, 0.2, 0.5)   # [s]
LOSSES = (0.0, 0.1, 0.3, 0.6)            # probability a packet is lost
SEED = 1                                 # comms.seed: the losses' stream


def linked(latency: float, loss: float, name: str = SCENARIO) -> scenario_io.Scenario:
    """Scenario `name` with `comms: {latency, loss, seed: SEED}`."""
    path = scenario_io.resolve(name)
    data = scenario_io.read_yaml(path.read_text())
    data['comms'] = {'latency': latency, 'loss': loss, 'seed': SEED}
    return scenario_io.loads(yaml.safe_dump(data), where=str(path))


def fly_linked(scenario: scenario_io.Scenario) -> dict:
    """One run's figures (module docstring)."""
    run = fly(scenario, raise_on_stop=False)
    s = run.summary()
    followers = [v for k, v in s.items() if k.startswith('follower')]
    return {'error': run.error,
            'tracking_rms': s['leader']['rms_tracking_error'],
            'tracking_max': s['leader']['max_tracking_error'],
            'saturated_uav_seconds': float(sum(s['sim']['saturated_time'])),
            'min_tension': s['sim']['min_tension'], 'max_tension': s['sim']['max_tension'],
            'formation_error_max': max(f['max_abs_formation_error'] for f in followers)}


def comms_study(out_dir: str | Path, latencies=LATENCIES, losses=LOSSES) -> dict:
    """Fly the grid; write comms.md, .json and .png to out_dir. Returns {'rows': [{latency,
    loss, figures}], 'files', 'table'}."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = [{'latency': latency, 'loss': loss, **fly_linked(linked(latency, loss))}
            for latency in latencies for loss in losses]
    table = _table(rows)
    files = {'table': str(out / 'comms.md'), 'json': str(out / 'comms.json'),
             'figure': str(out / 'comms.png')}
    Path(files['table']).write_text(table + '\n')
    Path(files['json']).write_text(json.dumps(rows, indent=1))
    _plot(rows, latencies, losses, Path(files['figure']))
    return {'rows': rows, 'files': files, 'table': table}


def _table(rows: list[dict]) -> str:
    lines = ['| comms.latency [s] | comms.loss | leader tracking rms / max [m] | rotors '
             'saturated [UAV s] | tension min / max [N] | formation error max, as heard '
             '[m or m^2] |', '|' + '---|' * 6]
    for r in rows:
        stopped = f' (stopped: {r["error"]})' if r['error'] else ''
        lines.append(f'| {r["latency"]:g} | {r["loss"]:g}{stopped} | {r["tracking_rms"]:.4f} / '
                     f'{r["tracking_max"]:.3f} | {r["saturated_uav_seconds"]:.2f} | '
                     f'{r["min_tension"]:.2f} / {r["max_tension"]:.2f} | '
                     f'{r["formation_error_max"]:.3f} |')
    return '\n'.join(lines)


def _plot(rows: list[dict], latencies, losses, path: Path) -> None:
    """Against the latency, one line per loss: the leader's rms tracking, the largest cable
    tension and the rotors' saturation."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(12.0, 3.6), layout='constrained')
    panels = (('tracking_rms', 'leader tracking rms [m]'),
              ('max_tension', 'largest cable tension [N]'),
              ('saturated_uav_seconds', 'rotors saturated [UAV s]'))
    for k, (key, label) in enumerate(panels):
        axes = figure.add_subplot(1, len(panels), k + 1)
        for loss in losses:
            values = [next(r[key] for r in rows if r['latency'] == latency and r['loss'] == loss)
                      for latency in latencies]
            axes.plot(np.array(latencies) * 1e3, values, marker='o', markersize=3,
                      label=f'loss {100 * loss:g} %')
        axes.set_xlabel('link latency [ms]')
        axes.set_ylabel(label)
        axes.grid(True, alpha=0.3)
        if k == 0:
            axes.legend(fontsize=8)
    figure.suptitle('The V of three (seed §4.4, §4.2 mission) with its followers hearing the '
                    'leader over a lossy, late link (comms:)', fontsize=10)
    figure.savefig(path, dpi=110)
