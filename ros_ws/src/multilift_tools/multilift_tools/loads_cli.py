"""`multilift loads SCENARIO [--json FILE]`: how the formation shares its payload (issue 35):
each cable's tension, each UAV's thrust and thrust margin (the share of its largest thrust
left, 1 - u_T / u_T,max) at hover, from the statics of Eq. 2.73, and the least margin of each
UAV over the mission's reference flown quasi-statically (multilift_sim.analysis.loads: the
reference's acceleration and velocity, the payload hanging where they take it; a rigid body at
its rest under them, laws.rigid_statics.hang_body). The run summary's least thrust margin is
the flown one. World frame (z up), SI units.
Exit codes: 0 done, 2 bad scenario or argument (one `error:` line).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from multilift_control.controllers import LeaderController
from multilift_control.laws import runnable
from multilift_control.laws.rigid_statics import hang_body
from multilift_sim.analysis.loads import LoadShares, QuasiStatic, hover_loads
from multilift_sim.scenario import Scenario, ScenarioError, load
from multilift_tools.plot_style import Parser, parse_args


def mission_loads(scenario: Scenario) -> list[tuple[float, LoadShares]]:
    """(t [s], the quasi-static shares) at every control tick of the leader's reference
    (`LeaderController`'s path: filters and input shaping as flown); instants with the same
    reference acceleration and velocity share one solve."""
    path = LeaderController(scenario).path
    statics = QuasiStatic(scenario, runnable(hang_body))
    solved: dict[tuple, LoadShares] = {}
    out = []
    for tick in range(scenario.simulation.tick_count + 1):
        t = tick / scenario.simulation.control_rate
        reference = path(t)
        key = tuple(np.round(np.concatenate((reference.acceleration, reference.velocity)), 12))
        if key not in solved:
            solved[key] = statics.loads(reference.acceleration, reference.velocity)
        out.append((t, solved[key]))
    return out


def loads_report(scenario: Scenario) -> tuple[str, dict]:
    """The text the command prints and the figures it writes as JSON."""
    hover = hover_loads(scenario)
    lines = [f'loads of {scenario.name} (n = {scenario.n_uavs}): the statics of Eq. 2.73',
             '  at hover         tension [N]   thrust [N]   largest [N]   margin']
    for i in range(scenario.n_uavs):
        lines.append(f'    uav{i + 1:<12} {hover.tensions[i]:>10.3f}   {hover.thrusts[i]:>10.3f}'
                     f'   {hover.largest_thrusts[i]:>11.3f}   {100 * hover.margins[i]:5.1f} %')
    figures = {'scenario': scenario.name,
               'hover': {'tension': hover.tensions.tolist(), 'thrust': hover.thrusts.tolist(),
                         'largest_thrust': hover.largest_thrusts.tolist(),
                         'thrust_margin': hover.margins.tolist()}}
    try:
        flown = mission_loads(scenario)
    except ValueError as exc:
        lines.append(f'  over the mission: {exc}')
        return '\n'.join(lines), figures
    margins = np.array([shares.margins for _, shares in flown])       # (ticks, n)
    worst = margins.argmin(axis=0)
    lines.append('  over the mission\'s reference, quasi-static (no swing, no transients: the '
                 'run summary\'s least thrust margin has them)')
    for i, k in enumerate(worst):
        t, shares = flown[k]
        a = shares.acceleration
        lines.append(f'    uav{i + 1:<12} least margin {100 * margins[k, i]:5.1f} % at t = '
                     f'{t:.2f} s (a = {a[0]:+.2f}, {a[1]:+.2f}, {a[2]:+.2f} m/s^2; tension '
                     f'{shares.tensions[i]:.3f} N)')
    figures['mission'] = {'least_thrust_margin': margins.min(axis=0).tolist(),
                          'at_time': [flown[k][0] for k in worst]}
    return '\n'.join(lines), figures


def loads_main(argv: list[str] | None = None) -> int:
    """`multilift loads SCENARIO [--json FILE]` (argv without the word 'loads')."""
    parser = Parser(prog='multilift loads', description='load shares and thrust margins of a '
                    'formation (statics of Eq. 2.73), at hover and over its mission')
    parser.add_argument('scenario', help='a name in scenarios/ or a YAML path')
    parser.add_argument('--json', help='also write the figures to this JSON file')
    args = parse_args(parser, sys.argv[1:] if argv is None else argv)
    if isinstance(args, int):
        return args
    try:
        scenario = load(args.scenario)
        text, figures = loads_report(scenario)
    except (ScenarioError, ValueError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    print(text)
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=1))
    return 0
