"""`multilift plot BAG [--out DIR] [--scenario NAME|PATH]`: the figures of one recorded run.

Everything is drawn in the world frame (z up, SI units) from the bag (`bagdata.load_run`);
vehicle parameters the bag does not carry (rotor limits, k_T, gusts, formation geometry) come
from the scenario named in the bag's summary.json, or `--scenario`. One figure per function
(the views in space and the rotors' in `plots/`, FIGURES the registry of all);
the Agg backend (plot_style), no display needed. Exit codes: 0 done, 2 bad input (one `error:`
line).
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable

import numpy as np

from multilift_sim.topics import (ATTITUDE_SETPOINT, FORMATION_ERROR, FORMATION_STATE,
                                  PAYLOAD_GUST, PAYLOAD_ODOM, REFERENCE_TOPIC, ROTOR_CMD,
                                  uav_topic)
from multilift_tools.bagdata import Run, RunDataError
from multilift_tools.metrics import interp_rows
from multilift_tools.plot_style import (AXES_XYZ, PAYLOAD_COLOR, WORLD, Context, Parser,
                                        finish_time_axes, finish_time_plot, formation_row_labels,
                                        legend, mark_events, parse_and_load, plot_context, plt,
                                        save_figure, shade_flags, uav_color, uav_label,
                                        uav_width)
from multilift_tools.plots.obstacles import fig_clearance, lacks_world
from multilift_tools.plots.ropes import (fig_cable_lengths, fig_rope_stretch, lacks_ropes,
                                         lacks_winches)
from multilift_tools.plots.estimation import fig_estimation, lacks_estimates
from multilift_tools.plots.rotors import fig_rotor_speeds, fig_thrust, fig_thrust_margins
from multilift_tools.plots.scene import released_cables
from multilift_tools.plots.views import fig_top_view, fig_trajectories_3d

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def fig_cable_constraints(ctx: Context) -> Figure:
    """Cable constraint residuals g_i [m^2] and their rates g_i_dot [m^2/s] (seed Fig. 4.2/4.4)."""
    run = ctx.run
    t, g, g_dot = run.formation_time, run.g(), run.g_dot()
    fig, (ax_g, ax_d) = plt.subplots(2, 1, sharex=True, figsize=(9, 6), layout='constrained')
    for k in range(g.shape[1]):
        i = k + 1
        ax_g.plot(t, g[:, k], color=uav_color(i), lw=uav_width(i, 1.0),
                  label=f'$g_{i}$ (cable {i})')
        ax_d.plot(t, g_dot[:, k], color=uav_color(i), lw=uav_width(i, 1.0),
                  label=f'$\\dot g_{i}$')
    tolerance = ''
    if ctx.scenario is not None:
        sim = ctx.scenario.simulation
        tolerance = (f' (tolerance {sim.constraint_tolerance:g} m², '
                     f'{sim.constraint_rate_tolerance:g} m²/s)')
    ax_g.set_ylabel('$g_i = |r_p - r_i|^2 - l_i^2$ [m²]')
    ax_d.set_ylabel('$\\dot g_i$ [m²/s]')
    ax_g.set_title(f'{run.label}: cable constraints; max |g| = {np.abs(g).max():.2g} m², '
                   f'max |ġ| = {np.abs(g_dot).max():.2g} m²/s{tolerance}', fontsize='medium')
    for ax in (ax_g, ax_d):
        ax.ticklabel_format(axis='y', style='sci', scilimits=(-2, 3))
        legend(ax, loc='upper right', ncols=min(g.shape[1], 5))
    finish_time_axes([ax_g, ax_d])
    return fig


def fig_formation_errors(ctx: Context) -> Figure:
    """Each follower's virtual-constraint rows g_vc (seed Fig. 4.7 / 4.11), world frame."""
    run = ctx.run
    followers = run.followers
    fig, axes = plt.subplots(len(followers), 1, sharex=True, squeeze=False,
                             figsize=(9, 2.2 + 2.3 * len(followers)), layout='constrained')
    for ax, i in zip(axes[:, 0], followers):
        e = run.formation_errors(i)
        labels, unit = formation_row_labels(ctx.scenario, i, e.shape[1])
        for k in range(e.shape[1]):
            ax.plot(run.formation_error_time(i), e[:, k], lw=1.1, label=labels[k])
        norm = np.linalg.norm(e, axis=1)
        ax.axhline(0.0, color='0.3', lw=0.6)
        ax.set_ylabel(f'UAV {i}: $g_{{vc}}$ [{unit}]')
        ax.set_title(f'follower UAV {i}: norm of its rows |g_vc|: mean {norm.mean():.3f}, '
                     f'max {norm.max():.3f} ({unit})', fontsize='medium')
        legend(ax, loc='best')
    fig.suptitle(f'{run.label}: virtual-constraint errors ({WORLD}); x, y, z rows: actual '
                 'minus desired leader-follower offset', fontsize='medium')
    finish_time_axes(axes[:, 0])
    return fig


def fig_attitude(ctx: Context) -> Figure:
    """Roll and pitch of each UAV [deg] (odometry, solid) and their set-points (dotted)."""
    run = ctx.run
    euler = np.degrees(run.uav_euler())
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(9, 6), layout='constrained')
    for k, (ax, name) in enumerate(zip(axes, ('roll φ', 'pitch θ'))):
        for i in range(1, run.n_uavs + 1):
            ax.plot(run.t, euler[i - 1, :, k], color=uav_color(i), lw=uav_width(i),
                    label=uav_label(i))
            if run.has(uav_topic(i, ATTITUDE_SETPOINT)):
                ax.plot(run.setpoint_time(i), np.degrees(run.attitude_setpoint(i)[:, k]),
                        color=uav_color(i), lw=0.8, ls=':', alpha=0.9)
        ax.plot([], [], color='0.3', lw=0.8, ls=':', label='set-points (dotted)')
        ax.set_ylabel(f'{name} [deg]')
        legend(ax, loc='best', ncols=min(run.n_uavs + 1, 4))
    axes[0].set_title(f'{run.label}: attitude (ZYX Euler angles of body FLU in {WORLD}); '
                      'solid measured, dotted set-point', fontsize='medium')
    finish_time_axes(axes)
    return fig


def fig_payload_attitude(ctx: Context) -> Figure:
    """A rigid payload's roll, pitch and yaw [deg] (/payload/odom, docs/rigid_payload.md)."""
    run = ctx.run
    series = run.topic(PAYLOAD_ODOM)
    euler = np.degrees(run.payload_euler())
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 7), layout='constrained')
    for k, (ax, name) in enumerate(zip(axes, ('roll', 'pitch', 'yaw'))):
        ax.plot(series.t, euler[:, k], color='0.2', lw=1.2)
        ax.set_ylabel(f'payload {name} [deg]')
    axes[0].set_title(f'{run.label}: payload attitude (ZYX Euler angles of its frame in '
                      f'{WORLD})', fontsize='medium')
    finish_time_axes(axes)
    return fig


def fig_payload_position(ctx: Context) -> Figure:
    """Payload x, y, z [m] over time (seed Fig. 4.15) and the gust speed met [m/s]."""
    run = ctx.run
    gust = run.has(PAYLOAD_GUST)
    rows = 4 if gust else 3
    fig, axes = plt.subplots(rows, 1, sharex=True, figsize=(9, 1.6 + 1.9 * rows),
                             layout='constrained')
    p = run.payload_position()
    for k, ax in enumerate(axes[:3]):
        ax.plot(run.payload_time, p[:, k], color=PAYLOAD_COLOR, lw=1.2)
        ax.set_ylabel(f'${AXES_XYZ[k]}_p$ [m]')
    if gust:
        speed = run.gust_speed()
        axes[3].plot(run.gust_time, speed, color='tab:cyan', lw=1.2)
        axes[3].set_ylim(0.0, max(1.0, 1.1 * float(speed.max())))
        axes[3].set_ylabel('gust |w| [m/s]')
        axes[3].set_title('gust speed at the payload' + ('' if speed.any() else
                                                         ': no gust met in this run'),
                          fontsize='small')
    axes[0].set_title(f'{run.label}: payload position ({WORLD})', fontsize='medium')
    finish_time_axes(axes)
    return fig


def fig_tensions(ctx: Context) -> Figure:
    """Cable tensions T_i [N]; negative values (compression of the rigid rod) shaded, the
    intervals a cable was slack (cable_model: slack) as a strip in its colour, and a released
    cable (a cable_release event) as a strip from its release on, labelled so."""
    run = ctx.run
    t, tension, taut = run.formation_time, run.tensions(), run.taut()
    released = released_cables(run)
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    for k in range(tension.shape[1]):
        i = k + 1
        ax.plot(t, tension[:, k], color=uav_color(i), lw=uav_width(i, 1.0),
                label=f'$T_{i}$ (UAV {i} - payload)')
        gone = t >= released[i] if i in released else np.zeros(len(t), dtype=bool)
        shade_flags(ax, t, ~taut[:, k] & ~gone, f'cable {i} slack', color=uav_color(i))
        shade_flags(ax, t, gone, f'cable {i} released ({released.get(i, 0.0):.0f} s on)',
                    color=uav_color(i), side='bottom')
    ax.axhline(0.0, color='0.3', lw=0.7)
    lo = tension.min()
    if lo < 0:
        ax.axhspan(min(lo * 1.1, -0.05), 0.0, color='tab:red', alpha=0.08,
                   label='T < 0: compression (rigid-rod model; a real cable goes slack)')
    finish_time_plot(ax, 'cable tension [N]',
                     f'{run.label}: cable tensions, {lo:.2f} .. {tension.max():.2f} N', loc='best')
    return fig


def fig_leader_tracking(ctx: Context) -> Figure:
    """Leader position minus its mission reference, per world axis and its norm [m]."""
    run = ctx.run
    ref = interp_rows(run.t, run.reference_time, run.reference_position())
    err = run.uav_positions()[0] - ref
    fig, ax = plt.subplots(figsize=(9, 4.5), layout='constrained')
    for k in range(3):
        ax.plot(run.t, err[:, k], lw=1.0, label=f'{AXES_XYZ[k]}')
    norm = np.linalg.norm(err, axis=1)
    ax.plot(run.t, norm, color='black', lw=1.2, label='|r_1 - r_ref|')
    finish_time_plot(ax, 'leader tracking error $r_1 - r_{ref}$ [m]',
                     f'{run.label}: leader tracking ({WORLD}); max {norm.max():.3f} m, '
                     f'rms {np.sqrt(np.mean(norm ** 2)):.3f} m', loc='best', ncols=4)
    return fig


@dataclass(frozen=True)
class FigureSpec:
    """A figure of `plot`: file stem, function, and `lacks(run)`: what the bag lacks for it
    (empty: it can be drawn); `over_time`: its axes share simulated time, on which the run's
    events are marked."""

    name: str
    make: Callable[[Context], Figure]
    lacks: Callable[[Run], list[str]]
    over_time: bool = True


def _topics(*topics: str) -> Callable[[Run], list[str]]:
    """A `lacks` function: for each topic of `topics` without messages, why."""
    return lambda run: [f'no messages on {topic}' for topic in topics if not run.has(topic)]


def _lacks_followers(run: Run) -> list[str]:
    if run.n_uavs < 2:
        return ['one UAV: no follower']
    if run.followers:
        return []
    return [f'no messages on {uav_topic(2, FORMATION_ERROR)} .. '
            f'{uav_topic(run.n_uavs, FORMATION_ERROR)} (the followers\' virtual-constraint '
            'errors)']


def _lacks_payload_attitude(run: Run) -> list[str]:
    if not run.has(PAYLOAD_ODOM):
        return [f'no messages on {PAYLOAD_ODOM}']
    orientation = run.topic(PAYLOAD_ODOM)['orientation']
    rotates = bool(np.any(orientation[:, :3] != 0.0))
    return [] if rotates else ['the payload is a point (no attitude; a rigid_body has one)']


FIGURES: tuple[FigureSpec, ...] = (
    FigureSpec('trajectories_3d', fig_trajectories_3d, _topics(PAYLOAD_ODOM), over_time=False),
    FigureSpec('top_view', fig_top_view, _topics(PAYLOAD_ODOM), over_time=False),
    FigureSpec('cable_constraints', fig_cable_constraints, _topics(FORMATION_STATE)),
    FigureSpec('cable_tensions', fig_tensions, _topics(FORMATION_STATE)),
    FigureSpec('rope_stretch', fig_rope_stretch, lacks_ropes),
    FigureSpec('cable_lengths', fig_cable_lengths, lacks_winches),
    FigureSpec('clearance', fig_clearance, lacks_world),
    FigureSpec('formation_errors', fig_formation_errors, _lacks_followers),
    FigureSpec('attitude', fig_attitude, _topics()),
    FigureSpec('thrust', fig_thrust, _topics(uav_topic(1, ATTITUDE_SETPOINT))),
    FigureSpec('rotor_speeds', fig_rotor_speeds, _topics(uav_topic(1, ROTOR_CMD))),
    FigureSpec('thrust_margins', fig_thrust_margins, _topics(uav_topic(1, ROTOR_CMD))),
    FigureSpec('estimation', fig_estimation, lacks_estimates),
    FigureSpec('payload_position', fig_payload_position, _topics(PAYLOAD_ODOM)),
    FigureSpec('payload_attitude', fig_payload_attitude, _lacks_payload_attitude),
    FigureSpec('leader_tracking', fig_leader_tracking, _topics(REFERENCE_TOPIC)),
)


def make_plots(ctx: Context, out: Path) -> tuple[list[Path], list[str]]:
    """Every figure of FIGURES the bag has data for, as `out/<name>.png`; (written, skipped)."""
    out.mkdir(parents=True, exist_ok=True)
    written, skipped = [], []
    for spec in FIGURES:
        missing = spec.lacks(ctx.run)
        if missing:
            skipped.append(f'{spec.name}: {"; ".join(missing)}')
            continue
        try:
            fig = spec.make(ctx)
        except RunDataError as exc:  # a topic a figure needs only in part
            plt.close('all')
            skipped.append(f'{spec.name}: {exc}')
            continue
        if spec.over_time:
            mark_events([ax for ax in fig.axes if ax.get_label() != '<colorbar>'],
                        ctx.run.events())
        written.append(save_figure(fig, out / f'{spec.name}.png'))
    return written, skipped


def plot_main(argv: list[str]) -> int:
    """`multilift plot BAG [--out DIR] [--scenario S]`: PNG figures of one run; prints each file
    written. Returns the exit code (0 done, 2 bad input)."""
    parser = Parser(prog='multilift plot', description='PNG figures of a recorded run')
    parser.add_argument('bag', help='a bag directory written by `multilift run --bag`')
    parser.add_argument('--out', help='output directory (default: BAG/plots)')
    parser.add_argument('--scenario', help='scenario name or YAML for the vehicle parameters '
                        "(default: the one in the bag's summary.json)")
    started = time.perf_counter()
    loaded = parse_and_load(parser, argv, 'plots')
    if isinstance(loaded, int):
        return loaded
    args, run, out = loaded
    written, skipped = make_plots(plot_context(run, args.scenario), out)
    for path in written:
        print(path)
    for note in skipped:
        print(f'skipped {note}', file=sys.stderr)
    print(f'{len(written)} figures in {time.perf_counter() - started:.1f} s', file=sys.stderr)
    return 0
