"""`multilift modal SCENARIO [--out DIR] [--hold-uavs]`: the modal analysis of
multilift_sim.analysis (seed Sec. 2.8; a rigid-body payload's too, docs/rigid_payload.md) printed
as a table, each mode named by where its kinetic energy sits (the payload's swing, heave, roll,
pitch, yaw; the UAVs), plotted in the complex plane (the analogue of seed Fig. 2.12) and
written as JSON. World frame (z up), SI units; eigenvalues [1/s], periods [s].
Exit codes: 0 done, 2 bad scenario or argument (one `error:` line).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from multilift_sim.analysis.coordinates import coordinate_names
from multilift_sim.analysis.modal import ModalAnalysis, scenario_modal_analysis
from multilift_sim.analysis.modes import MODE_KINDS, motion_shares
from multilift_sim.formation_params import StateLayout
from multilift_sim.kinematics import euler_from_quaternion, rotation_matrix
from multilift_sim.physics.layout import seed_payload_slot
from multilift_sim.scenario import ScenarioError, load


def _shape_text(analysis: ModalAnalysis, mode: int, count: int = 3) -> str:
    """The `count` largest components of mode `mode`'s shape ([m], [rad]), named by
    coordinate."""
    names = coordinate_names(analysis.params.n_uavs, analysis.params.rigid_payload)
    shape = analysis.shapes[mode]
    top = [k for k in np.argsort(-np.abs(shape))[:count] if abs(shape[k]) >= 0.01]
    parts = []
    for k in top:
        value = shape[k]
        text = (f'{value.real:+.2f}' if abs(value.imag) < 1e-3 * abs(value)
                else f'{abs(value):.2f}<{math.degrees(np.angle(value)):.0f}deg')
        parts.append(f'{names[k]} {text}')
    return ', '.join(parts)


def modal_report(analysis: ModalAnalysis, name: str) -> str:
    """The eigenvalue table (each mode's motion by kinetic energy share, its largest shape
    components), pendulum periods and rigid-body count as text."""
    eq = analysis.equilibrium
    params = analysis.params
    n = params.n_uavs
    layout = StateLayout(n)
    tilts = np.degrees(np.arccos(np.cos(layout.uav_euler(eq.state)[:, 0])
                                 * np.cos(layout.uav_euler(eq.state)[:, 1])))
    names = coordinate_names(n, params.rigid_payload)
    lines = [f'modal analysis of {name} (n = {n}): open loop, rotor speeds held at the static '
             'equilibrium of Eq. 2.73',
             '  cable tensions  ' + ', '.join(f'{t:.3f}' for t in eq.tensions) + ' N',
             '  rotor speeds    ' + ', '.join(f'{np.mean(s):.1f}' for s in eq.rotor_speeds)
             + ' rad/s (per UAV)',
             '  UAV tilt        ' + ', '.join(f'{t:.2f}' for t in tilts) + ' deg',
             f'  coordinates     {analysis.basis.shape[0]}, of them {analysis.basis.shape[1]} '
             'independent' + (' (dependent: ' + ', '.join(names[k] for k in analysis.dependent)
                              if analysis.dependent else ' (null-space basis')
             + (f'; the UAVs\' {seed_payload_slot(n)} held)' if analysis.held_uavs else ')')]
    if params.rigid_payload:
        lines.append(f'  payload         a rigid body of {params.payload_mass:g} kg, J_p '
                     + ', '.join(f'{j:.4g}' for j in params.payload_inertia) + ' kg m^2, level; '
                     'its rotation vector rx_p, ry_p, rz_p [rad] (payload frame) in the '
                     'coordinates')
    if analysis.held_uavs:
        lines.append('  UAVs            held still (--hold-uavs): their coordinates clamped, '
                     'only the payload moves')
    lines += ['',
              f'  {"#":>2}  {"Re [1/s]":>10}  {"Im [1/s]":>12}  {"period [s]":>10}  '
              f'{"kind":<11}  {"motion (kinetic energy share)":<36}  shape (largest components)']
    row = 0
    for k, value in enumerate(analysis.eigenvalues):
        kind = analysis.kinds[k]
        if kind == 'rigid' or value.imag < 0:
            continue
        row += 1          # a complex pair is one row (+/-), a real eigenvalue its own
        imag = f'+/-{value.imag:.5f}' if value.imag > 0 else f'{0.0:.5f}'
        period = f'{2 * math.pi / value.imag:.4f}' if value.imag > 0 else '-'
        lines.append(f'  {row:>2}  {value.real:>+10.2e}  {imag:>12}  {period:>10}  '
                     f'{kind:<11}  {analysis.motion(k):<36}  {_shape_text(analysis, k)}')
    lines += ['', rigid_line(analysis),
              '  pendulum periods: ' + (', '.join(f'{p:.4f}' for p in analysis.pendulum_periods)
                                        or 'none') + ' s']
    lines += suspension_lines(analysis)
    unstable = analysis.indices('unstable')
    if unstable.size:
        lines.append('  unstable: ' + ', '.join(f'{analysis.eigenvalues[k]:.4g}'
                                                for k in unstable) + ' 1/s')
    return '\n'.join(lines)


def rigid_line(analysis: ModalAnalysis) -> str:
    """The near-zero (rigid-body) modes: how many, the largest |lambda| among them, what they
    are; 'none' when there are none (no 'largest 0' of an empty set)."""
    zeros = [abs(v) for v, c in zip(analysis.eigenvalues, analysis.kinds) if c == 'rigid']
    tolerance = f'|lambda| < {analysis.zero_tolerance:g} 1/s'
    if not zeros:
        return f'  rigid-body modes: none (no eigenvalue with {tolerance})'
    held = ('motions of the payload its cables do not hold' if analysis.held_uavs else
            'translation of the free formation and the UAV attitudes, which nothing holds in '
            'open loop' + (', and any rotation of the body its cables do not hold'
                           if analysis.params.rigid_payload else ''))
    return (f'  rigid-body modes: {len(zeros)} eigenvalues with {tolerance} (largest '
            f'{max(zeros):.1e}): {held}')


def cable_drops(analysis: ModalAnalysis) -> np.ndarray:
    """Each cable's vertical drop h_i [m] at the equilibrium: the height of its upper end (the
    UAV's centre, or R_i a_i from it) above its lower end (the payload, or a rigid body's
    attach point r_p + R_p b_i); h_i = l_i cos(splay_i)."""
    params = analysis.params
    layout = StateLayout(params.n_uavs, params.rigid_payload)
    x = analysis.equilibrium.state
    upper = layout.uav_positions(x).copy()
    if params.uav_attach_points is not None:
        upper += np.einsum('ijk,ik->ij', rotation_matrix(layout.uav_euler(x)),
                           np.asarray(params.uav_attach_points, dtype=float))
    lower = np.repeat(layout.payload_position(x)[None], params.n_uavs, axis=0)
    if params.rigid_payload:
        w, qx, qy, qz = layout.payload_quaternion(x)
        rotation = rotation_matrix(euler_from_quaternion([qx, qy, qz, w]))
        lower = lower + np.asarray(params.payload_attach_points, dtype=float) @ rotation.T
    return upper[:, 2] - lower[:, 2]


def suspension_lines(analysis: ModalAnalysis) -> list[str]:
    """Why a swing's period is not 2 pi sqrt(l/g): the cables' length l, their vertical drop
    h = l cos(splay) and each pendulum mode's effective length g / omega^2 [m]. A swing across
    parallel cables (a point payload under one cable; a beam swinging out of its cables' plane)
    is a pendulum of length h; where the cables splay out from a body's attach points (a
    trapezoid: box_lift's corners, beam_lift's ends in their plane) a swing also turns the body
    (the mode's shape), and the effective length differs from both h and l."""
    params = analysis.params
    g = float(params.gravity)
    lengths = np.asarray(params.cable_lengths, dtype=float)
    drops = cable_drops(analysis)
    splay = np.degrees(np.arccos(np.clip(drops / lengths, -1.0, 1.0)))
    h, length = float(np.mean(drops)), float(np.mean(lengths))
    omegas = [analysis.eigenvalues[k].imag for k in analysis.pendulum_modes]
    effective = ', '.join(f'{g / w ** 2:.3f}' for w in omegas) or 'none'
    lines = ['  cables          length l ' + ', '.join(f'{v:.3f}' for v in lengths)
             + ' m; vertical drop h = l cos(splay) ' + ', '.join(f'{v:.3f}' for v in drops)
             + ' m (splayed ' + ', '.join(f'{v:.1f}' for v in splay) + ' deg)',
             f'  swing length    g/omega^2 of the pendulum modes {effective} m; a pendulum of '
             f'length h swings in {2 * math.pi * math.sqrt(h / g):.4f} s, of length l in '
             f'{2 * math.pi * math.sqrt(length / g):.4f} s (mean h, l)']
    if params.rigid_payload and float(np.max(splay)) > 1.0:
        lines.append('                  the cables splay out from the body\'s attach points (a '
                     'trapezoid, not parallel strings): a swing across them turns the body too '
                     '(the shapes above), so its period is neither 2 pi sqrt(l/g) nor '
                     '2 pi sqrt(h/g)')
    return lines


def _label_groups(analysis: ModalAnalysis, gap: float = 0.03) -> list[list[int]]:
    """The pendulum modes (positive imaginary part, fastest first) as the plot labels them:
    one label each, but a run of three or more whose imaginary parts lie within `gap` of the
    largest |lambda| [1/s] of the run's first (labels that would overlap, e.g. box_lift's
    formation modes near 8.7 s) shares one label."""
    modes = list(analysis.pendulum_modes)
    span = max(1e-3, float(np.max(np.abs(analysis.eigenvalues))))
    groups: list[list[int]] = []
    for k in modes:
        first = groups[-1][0] if groups else None
        if first is not None and (analysis.eigenvalues[first].imag
                                  - analysis.eigenvalues[k].imag) <= gap * span:
            groups[-1].append(k)
        else:
            groups.append([k])
    out: list[list[int]] = []
    for group in groups:          # a pair keeps its two labels (on alternating sides)
        out += [group] if len(group) >= 3 else [[k] for k in group]
    return out


def plot_eigenvalues(analysis: ModalAnalysis, path: Path, title: str) -> None:
    """Eigenvalues in the complex plane (the analogue of seed Fig. 2.12) as a PNG."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.4, 4.8), layout='constrained')
    axes = figure.add_subplot()
    markers = {'pendulum': ('o', 'tab:blue'), 'oscillatory': ('s', 'tab:green'),
               'unstable': ('^', 'tab:red'), 'damped': ('v', 'tab:purple'),
               'rigid': ('x', 'tab:gray')}
    for kind in MODE_KINDS:
        k = analysis.indices(kind)
        if k.size == 0:
            continue
        marker, colour = markers[kind]
        values = analysis.eigenvalues[k]
        label = f'{kind} ({k.size})' if kind != 'rigid' else f'rigid body ({k.size}, at 0)'
        axes.plot(values.real, values.imag, marker, color=colour, linestyle='none',
                  markersize=8, fillstyle='none' if kind == 'rigid' else 'full', label=label)
    for count, group in enumerate(_label_groups(analysis)):   # sides alternate: close pairs
        value = analysis.eigenvalues[group[0]]
        periods = [2 * math.pi / analysis.eigenvalues[k].imag for k in group]
        text = (f'{periods[0]:.2f} s' if len(group) == 1 else
                f'{min(periods):.2f}-{max(periods):.2f} s ({len(group)})')
        right = count % 2 == 0
        axes.annotate(text, (value.real, value.imag),
                      textcoords='offset points', xytext=(8 if right else -8, -3),
                      ha='left' if right else 'right', fontsize=8)
    axes.axhline(0.0, color='black', linewidth=0.5)
    axes.axvline(0.0, color='black', linewidth=0.5)
    span = max(1e-3, float(np.max(np.abs(analysis.eigenvalues))))
    if analysis.indices('unstable').size == 0 and analysis.indices('damped').size == 0:
        axes.set_xlim(-0.5 * span, 0.5 * span)
    axes.set_xlabel(r'real part Re($\lambda$) [1/s]')
    axes.set_ylabel(r'imaginary part Im($\lambda$) [1/s]')
    axes.set_title(title, fontsize=10)
    axes.grid(True, alpha=0.3)
    axes.legend(loc='best', fontsize=8)
    figure.savefig(path, dpi=120)


def modal_summary(analysis: ModalAnalysis, name: str) -> dict:
    """JSON-ready eigenvalues [1/s], kinds, each mode's motion (kinetic energy shares, for
    the non-rigid modes), pendulum periods [s] and equilibrium."""
    eq = analysis.equilibrium
    params = analysis.params
    names = coordinate_names(params.n_uavs, params.rigid_payload)
    return {'scenario': name,
            'payload': 'rigid_body' if params.rigid_payload else 'point',
            'held_uavs': analysis.held_uavs,
            'eigenvalues': [[float(v.real), float(v.imag)] for v in analysis.eigenvalues],
            'kinds': list(analysis.kinds),
            'motions': [None if kind == 'rigid' else
                        {m: round(s, 6) for m, s in motion_shares(analysis, k).items()}
                        for k, kind in enumerate(analysis.kinds)],
            'pendulum_periods': [float(p) for p in analysis.pendulum_periods],
            'rigid_count': analysis.rigid_count,
            'coordinates': list(names),
            'dependent_coordinates': [names[k] for k in analysis.dependent],
            'equilibrium': {'state': eq.state.tolist(),
                            'rotor_speeds': [s.tolist() for s in eq.rotor_speeds],
                            'tensions': eq.tensions.tolist()}}


class _UsageError(Exception):
    """A bad command line (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    """argparse raising _UsageError instead of exiting."""

    def error(self, message: str) -> None:      # one line, exit code 2 (not argparse's usage)
        raise _UsageError(message)


def modal_main(argv: list[str] | None = None) -> int:
    """`multilift modal SCENARIO [--out DIR] [--hold-uavs]` (argv without the word 'modal').

    Prints the eigenvalue table and the pendulum periods, writes DIR/<name>_eigenvalues.png
    and DIR/<name>_modal.json (DIR default runs/modal; with --hold-uavs <name>_held_...).
    --hold-uavs clamps the UAVs (the cables' upper ends held still: a suspension's own modes).
    Exit 0, or 2 with one line on stderr for a bad scenario or argument.
    """
    parser = _Parser(prog='multilift modal', description='modal analysis of a formation at '
                     'its static equilibrium (seed Sec. 2.8)')
    parser.add_argument('scenario', help='a name in scenarios/ or a YAML path')
    parser.add_argument('--out', default='runs/modal', help='directory for the plot and JSON')
    parser.add_argument('--hold-uavs', action='store_true', help='clamp the UAVs: the cables\' '
                        'upper ends held still, only the payload moves')
    try:
        args = parser.parse_args(argv)
        scenario = load(args.scenario)
        analysis = scenario_modal_analysis(scenario, hold_uavs=args.hold_uavs)
    except (_UsageError, ScenarioError, ValueError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    for warning in scenario.warnings:
        print(f'warning: {warning}', file=sys.stderr)
    print(modal_report(analysis, scenario.name))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    stem = scenario.name + ('_held' if args.hold_uavs else '')
    png = out / f'{stem}_eigenvalues.png'
    plot_eigenvalues(analysis, png, f'{scenario.name}: eigenvalues of the linearised formation '
                     '(open loop' + (', UAVs held)' if args.hold_uavs else ')'))
    summary = out / f'{stem}_modal.json'
    summary.write_text(json.dumps(modal_summary(analysis, scenario.name), indent=1))
    print(f'  wrote {png} and {summary}')
    return 0


if __name__ == '__main__':
    sys.exit(modal_main())
