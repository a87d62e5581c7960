"""Figures and animations of recorded multilift runs (`scripts/multilift plot|animate|compare`).

    multilift plot BAG [--out DIR] [--scenario NAME|PATH]
    multilift animate BAG [--out FILE.gif|FILE.mp4] [--fps N] [--speed X]
    multilift compare BAG_A BAG_B [--out DIR] [--labels A B] [--scenario-a S] [--scenario-b S]

Everything is drawn in the world frame (z up, SI units) from the bag (`bagdata.load_run`);
vehicle parameters the bag does not carry (rotor limits, k_T, gusts, formation geometry) come
from the scenario named in the bag's summary.json, or `--scenario`. One figure per function;
the Agg backend, no display needed. Exit codes: 0 done, 2 bad input (one `error:` line).
"""
from __future__ import annotations

import argparse
import math
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from matplotlib import animation, cm, colors  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection  # noqa: E402

from multilift_tools.bagdata import (FORMATION_TOPIC, PAYLOAD_GUST, PAYLOAD_ODOM,  # noqa: E402
                                   REFERENCE_TOPIC, Run, RunDataError, load_run, rotor_limits,
                                   run_scenario)

if TYPE_CHECKING:
    from multilift_sim.multirotor import MultirotorParams
    from multilift_sim.scenario import Scenario

WORLD = 'world frame, z up'
TIME_LABEL = 't [s] (simulated)'
PAYLOAD_COLOR = 'black'
DPI = 120
SATURATION_GREY = '0.82'
AXES_XYZ = ('x', 'y', 'z')


def uav_color(i: int) -> str:
    """Matplotlib colour of UAV i (1 = leader), the same in every figure."""
    return f'C{(i - 1) % 10}'


def uav_width(i: int, base: float = 1.2) -> float:
    """Line width of UAV i: the leader widest, so that followers drawn on top of an identical
    curve (symmetric formations) leave it visible."""
    return base + 0.9 * max(0, 3 - i) / 2


def uav_label(i: int) -> str:
    """Legend text of UAV i."""
    return 'UAV 1 (leader)' if i == 1 else f'UAV {i}'


@dataclass(frozen=True)
class Context:
    """What a figure function needs: the run, and its scenario if found (else None)."""

    run: Run
    scenario: Scenario | None


# -- small helpers ---------------------------------------------------------------------------
def _finish_time_axes(axes: Sequence[Axes]) -> None:
    for ax in axes:
        ax.grid(True, alpha=0.35)
    axes[-1].set_xlabel(TIME_LABEL)


def _legend(ax: Axes, **kwargs: Any) -> None:
    ax.legend(fontsize='small', framealpha=0.85, **kwargs)


def _span(values: np.ndarray) -> tuple[float, float]:
    lo, hi = float(np.nanmin(values)), float(np.nanmax(values))
    return lo, hi


def _interp_rows(t_to: np.ndarray, t_from: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Linear interpolation of the columns of `values` (T_from, k) onto `t_to`."""
    return np.stack([np.interp(t_to, t_from, values[:, k]) for k in range(values.shape[1])],
                    axis=1)


def _shade_flags(ax: Axes, t: np.ndarray, mask: np.ndarray, label: str,
                 color: str = 'tab:red') -> None:
    """A strip along the top of `ax` where `mask` is True (time intervals)."""
    if not mask.any():
        return
    ax.fill_between(t, 0.94, 1.0, where=mask, step='mid', color=color, alpha=0.8,
                    transform=ax.get_xaxis_transform(), label=label, linewidth=0)


def _equal_3d(ax: Any, points: np.ndarray, pad: float = 0.5) -> None:
    """Axis limits with equal scale on x, y, z, holding `points` (k, 3) [m]."""
    lo, hi = points.min(axis=0) - pad, points.max(axis=0) + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(hi - lo)


def formation_row_labels(scenario: Scenario | None, i: int, m: int) -> tuple[list[str], str]:
    """Labels and unit of follower i's m virtual-constraint rows (multilift_control.formation
    row order); generic 'row k' when the geometry is unknown."""
    kind = scenario.formation.geometry if scenario is not None and scenario.formation else None
    if kind in ('linear', 'v') and m == 3:
        return [f'$g_{{vc}}$ {a}: $(r_1 - r_{i})_{a}$ - $d_{a}$' for a in AXES_XYZ], 'm'
    if kind == 'distance' and m == 1:
        return [f'$|r_1 - r_{i}|^2 - d^2$'], 'm²'
    if kind == 'circle':
        n = scenario.n_uavs
        pairs = [(1, j) for j in range(2, n + 1)] + [(j, j + 1) for j in range(2, n)]
        mine = [p for p in pairs if i in p]
        if len(mine) == m:
            return [f'$|r_{a} - r_{b}|^2 - c_{b}^2$' if a == 1 else f'$|r_{a} - r_{b}|^2 - d^2$'
                    for a, b in mine], 'm²'
    return [f'row {k + 1}' for k in range(m)], 'm, or m² for distance rows'


def _vehicle(ctx: Context, i: int) -> MultirotorParams | None:
    return ctx.scenario.uavs[i - 1].vehicle if ctx.scenario is not None else None


# -- figures of one run ----------------------------------------------------------------------
def fig_trajectories_3d(ctx: Context) -> Figure:
    """3-D paths of the UAVs and the payload, with the cables at the start and the end."""
    run = ctx.run
    r, rp = run.uav_positions(), _interp_rows(run.t, run.payload_time, run.payload_position())
    fig = plt.figure(figsize=(10, 6.5))
    ax = fig.add_axes((-0.02, 0.0, 0.8, 0.94), projection='3d')
    for i in range(1, run.n_uavs + 1):
        ax.plot(*r[i - 1].T, color=uav_color(i), label=uav_label(i), lw=1.4)
    ax.plot(*rp.T, color=PAYLOAD_COLOR, lw=1.4, label='payload')
    for k, (style, what) in enumerate(((':', 'start'), ('--', 'end'))):
        idx = 0 if k == 0 else -1
        for i in range(run.n_uavs):
            ax.plot(*np.stack([r[i, idx], rp[idx]]).T, color='0.45', ls=style, lw=1.0,
                    label=f'cables at {what} (t = {run.t[idx]:.0f} s)' if i == 0 else None)
        ax.scatter(*r[:, idx].T, color=[uav_color(i) for i in range(1, run.n_uavs + 1)],
                   marker='o' if k == 0 else 's', s=30, depthshade=False)
        ax.scatter(*rp[idx], color=PAYLOAD_COLOR, marker='o' if k == 0 else 's', s=30,
                   depthshade=False)
    _equal_3d(ax, np.concatenate([r.reshape(-1, 3), rp]))
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')
    ax.set_zlabel('z [m]')
    ax.plot([], [], 'o', color='0.3', label='start')
    ax.plot([], [], 's', color='0.3', label='end')
    fig.suptitle(f'{run.label}: trajectories ({WORLD})')
    fig.legend(loc='center right', fontsize='small')
    return fig


def _gust_regions(ax: Axes, scenario: Scenario | None) -> None:
    if scenario is None:
        return
    for k, gust in enumerate(scenario.gusts, start=1):
        cx, cy = gust.center
        ax.add_patch(plt.Circle((cx, cy), gust.gradient_distance, color='tab:cyan',
                                alpha=0.25, lw=0,
                                label='gust regions (radius H)' if k == 1 else None))
        dx, dy = gust.direction[0], gust.direction[1]
        ax.annotate('', xy=(cx + dx * gust.gradient_distance, cy + dy * gust.gradient_distance),
                    xytext=(cx, cy), arrowprops={'arrowstyle': '->', 'color': 'tab:blue'})
        ax.text(cx, cy, f' gust {k}\n {gust.reference_speed:g} m/s', fontsize='x-small',
                color='tab:blue', va='top')


def _snapshot_times(ax: Axes, t: np.ndarray, payload: np.ndarray, idxs: np.ndarray,
                    near: float = 0.6) -> None:
    """'t = ... s' next to the payload at the snapshot samples; snapshots whose payloads lie
    within `near` [m] of each other share one label."""
    groups: list[list[int]] = []
    for idx in idxs:
        for group in groups:
            if np.linalg.norm(payload[group[0], :2] - payload[idx, :2]) < near:
                group.append(idx)
                break
        else:
            groups.append([idx])
    for group in groups:
        text = ', '.join(f'{t[k]:.0f}' for k in group)
        ax.annotate(f't = {text} s', payload[group[0], :2], textcoords='offset points',
                    xytext=(4, -10), fontsize='x-small', color='0.3')


def fig_top_view(ctx: Context) -> Figure:
    """x-y paths seen from above, formation snapshots (UAVs and cables) and gust regions."""
    run = ctx.run
    r, rp = run.uav_positions(), _interp_rows(run.t, run.payload_time, run.payload_position())
    fig, ax = plt.subplots(figsize=(8, 7), layout='constrained')
    _gust_regions(ax, ctx.scenario)
    if run.has(REFERENCE_TOPIC):
        ax.plot(*run.reference_position()[:, :2].T, color='0.5', ls='--', lw=1.0,
                label='leader reference')
    for i in range(1, run.n_uavs + 1):
        ax.plot(*r[i - 1, :, :2].T, color=uav_color(i), lw=1.4, label=uav_label(i))
    ax.plot(*rp[:, :2].T, color=PAYLOAD_COLOR, lw=1.4, label='payload')
    for k, idx in enumerate(np.linspace(0, len(run.t) - 1, 5).astype(int)):
        for i in range(run.n_uavs):
            ax.plot(*np.stack([r[i, idx, :2], rp[idx, :2]]).T, color='0.55', lw=0.8,
                    label='cables (projected), snapshots' if k == i == 0 else None)
        if run.n_uavs > 1:
            ring = np.vstack([r[:, idx, :2], r[:1, idx, :2]])
            ax.plot(*ring.T, color='0.55', lw=0.8, ls=':')
        ax.scatter(*r[:, idx, :2].T, color=[uav_color(i) for i in range(1, run.n_uavs + 1)],
                   s=18, zorder=3)
        ax.scatter(*rp[idx, :2], color=PAYLOAD_COLOR, marker='s', s=14, zorder=3)
    _snapshot_times(ax, run.t, rp, np.linspace(0, len(run.t) - 1, 5).astype(int))
    ax.set_aspect('equal', adjustable='datalim')
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')
    ax.set_title(f'{run.label}: top view ({WORLD}, seen from above)')
    ax.grid(True, alpha=0.35)
    _legend(ax, loc='best')
    return fig


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
        _legend(ax, loc='upper right', ncols=min(g.shape[1], 5))
    _finish_time_axes([ax_g, ax_d])
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
        _legend(ax, loc='best')
    fig.suptitle(f'{run.label}: virtual-constraint errors ({WORLD}); x, y, z rows: actual '
                 'minus desired leader-follower offset', fontsize='medium')
    _finish_time_axes(axes[:, 0])
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
            if run.has(f'/uav{i}/attitude_setpoint'):
                ax.plot(run.setpoint_time(i), np.degrees(run.attitude_setpoint(i)[:, k]),
                        color=uav_color(i), lw=0.8, ls=':', alpha=0.9)
        ax.plot([], [], color='0.3', lw=0.8, ls=':', label='set-points (dotted)')
        ax.set_ylabel(f'{name} [deg]')
        _legend(ax, loc='best', ncols=min(run.n_uavs + 1, 4))
    axes[0].set_title(f'{run.label}: attitude (ZYX Euler angles of body FLU in {WORLD}); '
                      'solid measured, dotted set-point', fontsize='medium')
    _finish_time_axes(axes)
    return fig


def fig_thrust(ctx: Context) -> Figure:
    """Collective thrust per UAV [N]: set-point and, with k_T known, k_T sum(omega^2)."""
    run = ctx.run
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    max_thrust = []
    for i in range(1, run.n_uavs + 1):
        if run.has(f'/uav{i}/attitude_setpoint'):
            ax.plot(run.setpoint_time(i), run.thrust(i), color=uav_color(i), lw=uav_width(i),
                    label=f'{uav_label(i)} set-point')
        vehicle = _vehicle(ctx, i)
        if vehicle is not None and run.has(f'/uav{i}/rotor_cmd'):
            omega = run.rotor_speeds(i)
            ax.plot(run.rotor_time(i), vehicle.thrust_coefficient * (omega ** 2).sum(axis=1),
                    color=uav_color(i), lw=0.8, ls='--', alpha=0.8,
                    label=f'{uav_label(i)} delivered $k_T \\sum\\omega^2$')
            max_thrust.append(vehicle.thrust_coefficient * omega.shape[1]
                              * vehicle.rotor_speed_max ** 2)
    if max_thrust and np.allclose(max_thrust, max_thrust[0]):
        ax.axhline(max_thrust[0], color='tab:red', lw=1.0, ls='-.',
                   label=f'max thrust {max_thrust[0]:.2f} N (all rotors at ω_max)')
    ax.set_ylabel('thrust along body z [N]')
    ax.set_title(f'{run.label}: collective thrust per UAV', fontsize='medium')
    _legend(ax, loc='best', ncols=2)
    _finish_time_axes([ax])
    return fig


def _rotor_panel(ax: Axes, run: Run, i: int, limits: tuple[float, float] | None,
                 limit_note: str) -> None:
    t, omega, sat = run.rotor_time(i), run.rotor_speeds(i), run.saturated(i)
    for k in range(omega.shape[1]):
        ax.plot(t, omega[:, k], lw=0.9, color=f'C{k}', label=f'rotor {k + 1}')
    lo, hi = _span(omega)
    if limits is not None:
        w_min, w_max = limits
        lo, hi = min(lo, w_max), max(hi, w_max)
        margin = 0.08 * max(hi - lo, 1.0)
        ax.axhspan(w_max, hi + margin, color=SATURATION_GREY, zorder=0,
                   label=f'saturation ω ≥ ω_max = {w_max:g} rad/s{limit_note}')
        if w_min > 0 and lo - margin < w_min:
            ax.axhspan(lo - margin, w_min, color=SATURATION_GREY, zorder=0,
                       label=f'saturation ω ≤ ω_min = {w_min:g} rad/s')
        ax.set_ylim(lo - margin, hi + margin)
    _shade_flags(ax, t, sat.any(axis=1), 'a rotor clipped (saturated flag)')
    ax.set_ylabel(f'UAV {i}: ω [rad/s]')
    ax.set_title(f'{uav_label(i)}: saturated {np.mean(sat.any(axis=1)) * 100:.1f} % of the '
                 f'time, mean ω = {omega.mean():.0f} rad/s', fontsize='small')
    _legend(ax, loc='lower left', ncols=3)


def fig_rotor_speeds(ctx: Context) -> Figure:
    """Rotor speeds per UAV [rad/s] after saturation, the saturation band shaded grey."""
    run = ctx.run
    uavs = [i for i in range(1, run.n_uavs + 1) if run.has(f'/uav{i}/rotor_cmd')]
    fig, axes = plt.subplots(len(uavs), 1, sharex=True, squeeze=False,
                             figsize=(9, 1.5 + 2.6 * len(uavs)), layout='constrained')
    for ax, i in zip(axes[:, 0], uavs):
        note = '' if ctx.scenario is not None else ' (inferred from the flags)'
        _rotor_panel(ax, run, i, rotor_limits(run, ctx.scenario, i), note)
    fig.suptitle(f'{run.label}: rotor speeds (commands after saturation)', fontsize='medium')
    _finish_time_axes(axes[:, 0])
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
    _finish_time_axes(axes)
    return fig


def fig_tensions(ctx: Context) -> Figure:
    """Cable tensions T_i [N]; negative values (compression of the rigid rod) shaded."""
    run = ctx.run
    t, tension = run.formation_time, run.tensions()
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    for k in range(tension.shape[1]):
        ax.plot(t, tension[:, k], color=uav_color(k + 1), lw=uav_width(k + 1, 1.0),
                label=f'$T_{k + 1}$ (UAV {k + 1} - payload)')
    ax.axhline(0.0, color='0.3', lw=0.7)
    lo = tension.min()
    if lo < 0:
        ax.axhspan(min(lo * 1.1, -0.05), 0.0, color='tab:red', alpha=0.08,
                   label='T < 0: compression (rigid-rod model; a real cable goes slack)')
    ax.set_ylabel('cable tension [N]')
    ax.set_title(f'{run.label}: cable tensions, {lo:.2f} .. {tension.max():.2f} N',
                 fontsize='medium')
    _legend(ax, loc='best')
    _finish_time_axes([ax])
    return fig


def fig_leader_tracking(ctx: Context) -> Figure:
    """Leader position minus its mission reference, per world axis and its norm [m]."""
    run = ctx.run
    ref = _interp_rows(run.t, run.reference_time, run.reference_position())
    err = run.uav_positions()[0] - ref
    fig, ax = plt.subplots(figsize=(9, 4.5), layout='constrained')
    for k in range(3):
        ax.plot(run.t, err[:, k], lw=1.0, label=f'{AXES_XYZ[k]}')
    norm = np.linalg.norm(err, axis=1)
    ax.plot(run.t, norm, color='black', lw=1.2, label='|r_1 - r_ref|')
    ax.set_ylabel('leader tracking error $r_1 - r_{ref}$ [m]')
    ax.set_title(f'{run.label}: leader tracking ({WORLD}); max {norm.max():.3f} m, '
                 f'rms {np.sqrt(np.mean(norm ** 2)):.3f} m', fontsize='medium')
    _legend(ax, loc='best', ncols=4)
    _finish_time_axes([ax])
    return fig


@dataclass(frozen=True)
class FigureSpec:
    """A figure of `plot`: file stem, function, and `lacks(run)`: what the bag lacks for it
    (empty: it can be drawn)."""

    name: str
    make: Callable[[Context], Figure]
    lacks: Callable[[Run], list[str]]


def _topics(*topics: str) -> Callable[[Run], list[str]]:
    """A `lacks` function: the topics of `topics` the bag has no messages on."""
    return lambda run: [topic for topic in topics if not run.has(topic)]


def _lacks_followers(run: Run) -> list[str]:
    return [] if run.followers else ['follower (no /uav{i}/formation_error topic)']


FIGURES: tuple[FigureSpec, ...] = (
    FigureSpec('trajectories_3d', fig_trajectories_3d, _topics(PAYLOAD_ODOM)),
    FigureSpec('top_view', fig_top_view, _topics(PAYLOAD_ODOM)),
    FigureSpec('cable_constraints', fig_cable_constraints, _topics(FORMATION_TOPIC)),
    FigureSpec('cable_tensions', fig_tensions, _topics(FORMATION_TOPIC)),
    FigureSpec('formation_errors', fig_formation_errors, _lacks_followers),
    FigureSpec('attitude', fig_attitude, _topics()),
    FigureSpec('thrust', fig_thrust, _topics('/uav1/attitude_setpoint')),
    FigureSpec('rotor_speeds', fig_rotor_speeds, _topics('/uav1/rotor_cmd')),
    FigureSpec('payload_position', fig_payload_position, _topics(PAYLOAD_ODOM)),
    FigureSpec('leader_tracking', fig_leader_tracking, _topics(REFERENCE_TOPIC)),
)


def save_figure(fig: Figure, path: Path) -> Path:
    """Write `fig` as PNG to `path` and close it."""
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def make_plots(ctx: Context, out: Path) -> tuple[list[Path], list[str]]:
    """Every figure of FIGURES the bag has data for, as `out/<name>.png`; (written, skipped)."""
    out.mkdir(parents=True, exist_ok=True)
    written, skipped = [], []
    for spec in FIGURES:
        missing = spec.lacks(ctx.run)
        if missing:
            skipped.append(f'{spec.name}: bag has no {", ".join(missing)}')
            continue
        try:
            fig = spec.make(ctx)
        except RunDataError as exc:  # a topic a figure needs only in part
            plt.close('all')
            skipped.append(f'{spec.name}: {exc}')
            continue
        written.append(save_figure(fig, out / f'{spec.name}.png'))
    return written, skipped


# -- command line ----------------------------------------------------------------------------
class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of exiting, so the *_main functions return exit codes."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise _UsageError(f'{self.prog}: {message}')


class _UsageError(Exception):
    pass


def _parse(parser: argparse.ArgumentParser, argv: list[str]) -> argparse.Namespace | int:
    try:
        return parser.parse_args(argv)
    except _UsageError as exc:
        print(parser.format_usage().rstrip(), file=sys.stderr)
        print(f'error: {exc}', file=sys.stderr)
        return 2
    except SystemExit as exc:  # --help
        return int(exc.code or 0)


def _load(bag: str) -> Run | None:
    try:
        return load_run(bag)
    except (FileNotFoundError, ValueError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return None


def _context(run: Run, scenario: str | None) -> Context:
    found, note = run_scenario(run, scenario)
    if found is None:
        print(f'note: {note}; rotor limits inferred from the saturation flags, no gusts or '
              'max thrust drawn', file=sys.stderr)
    return Context(run, found)


def plot_main(argv: list[str]) -> int:
    """`multilift plot BAG [--out DIR] [--scenario S]`: PNG figures of one run; prints each file
    written. Returns the exit code (0 done, 2 bad input)."""
    parser = _Parser(prog='multilift plot', description='PNG figures of a recorded run')
    parser.add_argument('bag', help='a bag directory written by `multilift run --bag`')
    parser.add_argument('--out', help='output directory (default: BAG/plots)')
    parser.add_argument('--scenario', help='scenario name or YAML for the vehicle parameters '
                        "(default: the one in the bag's summary.json)")
    args = _parse(parser, argv)
    if isinstance(args, int):
        return args
    started = time.perf_counter()
    run = _load(args.bag)
    if run is None:
        return 2
    out = Path(args.out) if args.out else run.path / 'plots'
    written, skipped = make_plots(_context(run, args.scenario), out)
    for path in written:
        print(path)
    for note in skipped:
        print(f'skipped {note}', file=sys.stderr)
    print(f'{len(written)} figures in {time.perf_counter() - started:.1f} s', file=sys.stderr)
    return 0


# -- animation -------------------------------------------------------------------------------
@dataclass(frozen=True)
class AnimationData:
    """The run on the animation's frame times: t (F,) [s], UAVs (n, T, 3), payload (T, 3) [m],
    tensions (T, n) [N] on the odometry time base T, and `frames` (F,) indices into it."""

    t: np.ndarray
    uavs: np.ndarray
    payload: np.ndarray
    tensions: np.ndarray
    frames: np.ndarray


def animation_data(run: Run, fps: float, speed: float) -> AnimationData:
    """Sample the run every `speed / fps` simulated seconds (`speed` x real time at `fps`)."""
    t = run.t
    uavs = run.uav_positions()
    payload = _interp_rows(t, run.payload_time, run.payload_position())
    tensions = (_interp_rows(t, run.formation_time, run.tensions()) if run.has(FORMATION_TOPIC)
                else np.zeros((len(t), run.n_uavs)))
    times = np.arange(t[0], t[-1] + 1e-9, speed / fps)
    frames = np.unique(np.clip(np.searchsorted(t, times), 0, len(t) - 1))
    return AnimationData(t, uavs, payload, tensions, frames)


def _tension_norm(tensions: np.ndarray) -> colors.Normalize:
    lo, hi = float(tensions.min()), float(tensions.max())
    if hi - lo < 1e-9:
        lo, hi = lo - 0.5, hi + 0.5
    return colors.Normalize(lo, hi)


class FormationAnimator:
    """The formation in 3-D (world frame, z up): UAVs, cables coloured by tension, payload, and
    the paths so far. `render(k)` draws odometry sample k by blitting the moving artists on a
    background drawn once (axes, ticks, colour bar) and returns the RGBA pixels."""

    def __init__(self, data: AnimationData, title: str, dpi: int = 80,
                 figsize: tuple[float, float] = (7.0, 5.6)) -> None:
        self.data = data
        self.fig = plt.figure(figsize=figsize, dpi=dpi)
        self.ax = ax = self.fig.add_axes((0.0, 0.05, 0.82, 0.85), projection='3d')
        n = data.uavs.shape[0]
        _equal_3d(ax, np.concatenate([data.uavs.reshape(-1, 3), data.payload]))
        ax.set_xlabel('x [m]')
        ax.set_ylabel('y [m]')
        ax.set_zlabel('z [m]')
        self.fig.suptitle(f'{title} ({WORLD})', fontsize='medium')
        self.norm = _tension_norm(data.tensions)
        self.cmap = plt.get_cmap('plasma')
        self.cables = Line3DCollection(self._segments(0), cmap=self.cmap, norm=self.norm, lw=2.2,
                                       animated=True)
        ax.add_collection(self.cables)
        self.fig.colorbar(cm.ScalarMappable(norm=self.norm, cmap=self.cmap),
                          cax=self.fig.add_axes((0.86, 0.2, 0.025, 0.6)),
                          label='cable tension [N] (< 0: compression)')
        self.uav_paths = [ax.plot([], [], [], color=uav_color(i + 1), lw=0.8, animated=True)[0]
                          for i in range(n)]
        self.uav_dots = [ax.plot([], [], [], 'o', color=uav_color(i + 1), ms=7, animated=True,
                                 label=uav_label(i + 1))[0] for i in range(n)]
        self.payload_path = ax.plot([], [], [], color=PAYLOAD_COLOR, lw=0.8, animated=True)[0]
        self.payload_dot = ax.plot([], [], [], 's', color=PAYLOAD_COLOR, ms=6, animated=True,
                                   label='payload')[0]
        self.clock = ax.text2D(0.02, 0.95, '', transform=ax.transAxes, animated=True)
        ax.legend(loc='upper right', fontsize='x-small')
        dt = float(np.median(np.diff(data.t))) if len(data.t) > 1 else 1.0
        self.stride = max(1, int(round(0.1 / dt)))  # paths drawn at about 10 Hz
        self._background: Any = None

    def _segments(self, k: int) -> np.ndarray:
        d = self.data
        return np.stack([d.uavs[:, k], np.repeat(d.payload[k][None], d.uavs.shape[0], 0)],
                        axis=1)

    def _path(self, points: np.ndarray, k: int) -> np.ndarray:
        """points[:k + 1] thinned to every `stride`-th sample, ending exactly at sample k."""
        return np.concatenate([points[:k + 1:self.stride], points[k:k + 1]])

    def update(self, k: int) -> list[Any]:
        """Move the artists to odometry sample k; returns them."""
        d = self.data
        self.cables.set_segments(self._segments(k))
        self.cables.set_array(d.tensions[k])
        for i, (path, dot) in enumerate(zip(self.uav_paths, self.uav_dots)):
            path.set_data_3d(*self._path(d.uavs[i], k).T)
            dot.set_data_3d(*d.uavs[i, k:k + 1].T)
        self.payload_path.set_data_3d(*self._path(d.payload, k).T)
        self.payload_dot.set_data_3d(*d.payload[k:k + 1].T)
        self.clock.set_text(f't = {d.t[k]:6.1f} s')
        return [self.cables, *self.uav_paths, self.payload_path, *self.uav_dots,
                self.payload_dot, self.clock]

    def render(self, k: int) -> np.ndarray:
        """(H, W, 4) uint8 RGBA pixels of the figure at odometry sample k."""
        canvas = self.fig.canvas
        if self._background is None:
            canvas.draw()  # everything but the animated artists; sets the 3-D projection
            self._background = canvas.copy_from_bbox(self.fig.bbox)
        canvas.restore_region(self._background)
        for artist in self.update(k):
            if isinstance(artist, Line3DCollection):
                artist.do_3d_projection()
            self.ax.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba())


class _PixelPillowWriter(animation.PillowWriter):
    """matplotlib's PillowWriter fed with ready RGBA frames (`add`) instead of one full
    `savefig` per frame; `finish` writes the GIF as PillowWriter does."""

    def setup(self, fig: Figure, outfile: str | Path, dpi: float | None = None) -> None:
        super().setup(fig, outfile, dpi=dpi)
        self._images: list[Any] = []

    def add(self, rgba: np.ndarray) -> None:
        """Append one (H, W, 4) uint8 frame."""
        from PIL import Image
        self._images.append(Image.fromarray(rgba[..., :3].copy(), 'RGB'))

    def grab_frame(self, **savefig_kwargs: Any) -> None:
        self.add(np.asarray(self.fig.canvas.buffer_rgba()))

    def finish(self) -> None:
        self._images[0].save(self.outfile, save_all=True, append_images=self._images[1:],
                             duration=int(1000 / self.fps), loop=0)


def _check_output(out: Path) -> str:
    kind = out.suffix.lower()
    if kind not in ('.gif', '.mp4'):
        raise ValueError(f'{out}: the output must end in .gif or .mp4')
    if kind == '.mp4' and shutil.which('ffmpeg') is None:
        raise ValueError(f'{out}: writing .mp4 needs an ffmpeg binary on PATH and there is '
                         'none; write a .gif instead')
    return kind


def write_animation(run: Run, out: Path, fps: float, speed: float, dpi: int = 80) -> int:
    """Write the formation animation to `out` (.gif, or .mp4 when ffmpeg is on PATH), showing
    `speed` simulated seconds per second at `fps` frames per second; returns the frame count.
    ValueError (naming `out`) for another suffix or a missing ffmpeg."""
    kind = _check_output(out)
    data = animation_data(run, fps, speed)
    anim = FormationAnimator(data, f'{run.label}, {speed:g}x real time', dpi=dpi)
    writer: animation.AbstractMovieWriter = (
        _PixelPillowWriter(fps=fps) if kind == '.gif'
        else animation.FFMpegWriter(fps=fps, bitrate=1800))
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        with writer.saving(anim.fig, str(out), dpi=dpi):
            for k in data.frames:
                if isinstance(writer, _PixelPillowWriter):
                    writer.add(anim.render(int(k)))
                else:  # ffmpeg: a full draw per frame, the moving artists included
                    for artist in anim.update(int(k)):
                        artist.set_animated(False)
                    writer.grab_frame()
    finally:
        plt.close(anim.fig)
    return len(data.frames)


def _positive(text: str) -> float:
    value = float(text)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f'{text} must be a finite number > 0')
    return value


def animate_main(argv: list[str]) -> int:
    """`multilift animate BAG [--out FILE] [--fps N] [--speed X]`: the formation in 3-D over
    time. Returns the exit code (0 done, 2 bad input)."""
    parser = _Parser(prog='multilift animate', description='animate a recorded run in 3-D')
    parser.add_argument('bag', help='a bag directory written by `multilift run --bag`')
    parser.add_argument('--out', help='FILE.gif or FILE.mp4 (mp4 needs ffmpeg; default: '
                        'BAG/animation.gif)')
    parser.add_argument('--fps', type=_positive, default=10.0, help='frames per second (10)')
    parser.add_argument('--speed', type=_positive, default=5.0,
                        help='simulated seconds per second of animation (5)')
    parser.add_argument('--dpi', type=int, default=80, help='resolution (80: 560 x 448 px)')
    args = _parse(parser, argv)
    if isinstance(args, int):
        return args
    started = time.perf_counter()
    run = _load(args.bag)
    if run is None:
        return 2
    out = Path(args.out) if args.out else run.path / 'animation.gif'
    try:
        frames = write_animation(run, out, args.fps, args.speed, args.dpi)
    except (ValueError, OSError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    print(out)
    print(f'{frames} frames ({frames / args.fps:.1f} s at {args.fps:g} fps), '
          f'{out.stat().st_size / 1e6:.1f} MB, {time.perf_counter() - started:.1f} s',
          file=sys.stderr)
    return 0


# -- comparison of two runs (seed Fig. 4.15-4.17) --------------------------------------------
def _common_end(runs: Sequence[Run]) -> float:
    return min(float(r.t[-1]) for r in runs)


def _window(t: np.ndarray, t_end: float) -> np.ndarray:
    return t <= t_end + 1e-9


def fig_compare_payload(runs: Sequence[Run], labels: Sequence[str]) -> Figure:
    """Payload x, y, z [m] of both runs on the same axes (seed Fig. 4.15)."""
    t_end = _common_end(runs)
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 7), layout='constrained')
    for run, label, style in zip(runs, labels, ('-', '--')):
        keep = _window(run.payload_time, t_end)
        p = run.payload_position()[keep]
        for k, ax in enumerate(axes):
            ax.plot(run.payload_time[keep], p[:, k], ls=style, lw=1.2,
                    label=f'$ {AXES_XYZ[k]}_p$ | {label}')
    for k, ax in enumerate(axes):
        ax.set_ylabel(f'${AXES_XYZ[k]}_p$ [m]')
        _legend(ax, loc='best')
    axes[0].set_title(f'payload position ({WORLD}): {labels[0]} vs {labels[1]}',
                      fontsize='medium')
    _finish_time_axes(axes)
    return fig


def fig_compare_formation_error(runs: Sequence[Run], labels: Sequence[str],
                                scenarios: Sequence[Scenario | None]) -> Figure:
    """Virtual-constraint errors of every follower of both runs (seed Fig. 4.16): the x, y, z
    rows [m] where both runs have them, and the norm |g_vc| per follower."""
    t_end = _common_end(runs)
    by_axis = all(formation_row_labels(s, i, r.formation_errors(i).shape[1])[1] == 'm'
                  for r, s in zip(runs, scenarios) for i in r.followers)
    rows = 4 if by_axis else 1
    fig, axes = plt.subplots(rows, 1, sharex=True, squeeze=False, figsize=(9, 1.8 + 1.9 * rows),
                             layout='constrained')
    axes = axes[:, 0]
    for run, label, style in zip(runs, labels, ('-', '--')):
        for i in run.followers:
            keep = _window(run.formation_error_time(i), t_end)
            t, e = run.formation_error_time(i)[keep], run.formation_errors(i)[keep]
            color = uav_color(i)
            if by_axis:
                for k in range(3):
                    axes[k].plot(t, e[:, k], ls=style, color=color, lw=1.1,
                                 label=f'UAV {i} | {label}')
            axes[-1].plot(t, np.linalg.norm(e, axis=1), ls=style, color=color, lw=1.1,
                          label=f'UAV {i} | {label}')
    unit = 'm' if by_axis else 'm or m²'
    if by_axis:
        for k in range(3):
            axes[k].set_ylabel(f'$g_{{vc}}$ {AXES_XYZ[k]} [m]')
            axes[k].axhline(0.0, color='0.3', lw=0.6)
    axes[-1].set_ylabel(f'$|g_{{vc}}|$ [{unit}]')
    for ax in axes:
        _legend(ax, loc='best', ncols=2)
    axes[0].set_title(f'virtual-constraint error per follower ({WORLD}): solid {labels[0]}, '
                      f'dashed {labels[1]}', fontsize='medium')
    _finish_time_axes(axes)
    return fig


def fig_compare_leader_rotors(runs: Sequence[Run], labels: Sequence[str],
                              scenarios: Sequence[Scenario | None]) -> Figure:
    """The leader's rotor speeds [rad/s] of both runs (seed Fig. 4.17): the mean over its rotors
    and their range, with the saturation band shaded."""
    t_end = _common_end(runs)
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    top, bottom, lowest = -math.inf, math.inf, math.inf
    for run, label, color in zip(runs, labels, ('tab:blue', 'tab:orange')):
        keep = _window(run.rotor_time(1), t_end)
        t, omega = run.rotor_time(1)[keep], run.rotor_speeds(1)[keep]
        ax.fill_between(t, omega.min(axis=1), omega.max(axis=1), color=color, alpha=0.25,
                        lw=0, label=f'range over rotors | {label}')
        ax.plot(t, omega.mean(axis=1), color=color, lw=1.2,
                label=f'mean $\\omega_{{r,1}}$ | {label} ({omega.mean():.0f} rad/s)')
        # the axis ends at the 1st percentile: brief dips at segment switches would
        # otherwise squash the few-% difference this figure is about
        top = max(top, float(omega.max()))
        bottom = min(bottom, float(np.percentile(omega.min(axis=1), 1)))
        lowest = min(lowest, float(omega.min()))
    ax.set_ylim(bottom - 0.08 * (top - bottom), None)
    if lowest < bottom - 0.08 * (top - bottom):
        ax.text(0.99, 0.02, f'axis cut: brief dips down to {lowest:.0f} rad/s', ha='right',
                transform=ax.transAxes, fontsize='x-small', color='0.3')
    limits = [rotor_limits(r, s, 1) for r, s in zip(runs, scenarios)]
    known = [lim for lim in limits if lim is not None]
    if known:
        w_max = min(lim[1] for lim in known)
        margin = 0.08 * max(max(top, w_max) - bottom, 1.0)
        ax.axhspan(w_max, max(top, w_max) + margin, color=SATURATION_GREY, zorder=0,
                   label=f'saturation ω ≥ ω_max = {w_max:g} rad/s')
        ax.set_ylim(bottom - margin, max(top, w_max) + margin)
    _legend(ax, loc='lower left', ncols=2)
    ax.set_ylabel('leader rotor speed ω [rad/s]')
    ax.set_title(f'leader (UAV 1) rotor speeds: {labels[0]} vs {labels[1]}', fontsize='medium')
    _finish_time_axes([ax])
    return fig


def pendulum_period(run: Run, scenario: Scenario | None, gravity: float = 9.81) -> float:
    """2 pi sqrt(h/g) [s], h the cable length of the scenario or else the mean height of the
    UAVs' centroid above the payload [m]."""
    if scenario is not None:
        h = float(np.mean([u.cable_length for u in scenario.uavs]))
        gravity = scenario.simulation.gravity
    else:
        centroid = run.uav_positions().mean(axis=0)
        p = _interp_rows(run.t, run.payload_time, run.payload_position())
        h = float(np.mean(centroid[:, 2] - p[:, 2]))
    return 2 * math.pi * math.sqrt(max(h, 1e-3) / gravity)


def swing_metrics(run: Run, scenario: Scenario | None, t_end: float) -> dict[str, float]:
    """Payload swing: its horizontal offset d(t) from the UAVs' centroid [m] (world x, y),
    minus the moving mean of d over one pendulum period; returns the max and RMS of |that|
    [m], and the period [s] used. Over t <= t_end."""
    keep = _window(run.t, t_end)
    t = run.t[keep]
    p = _interp_rows(t, run.payload_time, run.payload_position())
    d = p[:, :2] - run.uav_positions()[:, keep, :2].mean(axis=0)
    period = pendulum_period(run, scenario)
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    width = max(1, min(len(t), int(round(period / dt))))
    kernel = np.ones(width) / width
    smooth = np.stack([np.convolve(np.pad(d[:, k], (width // 2, width - 1 - width // 2),
                                          mode='edge'), kernel, mode='valid')
                       for k in range(2)], axis=1)
    swing = np.linalg.norm(d - smooth, axis=1)
    return {'max': float(swing.max()), 'rms': float(np.sqrt(np.mean(swing ** 2))),
            'period': period}


def _percent(a: float, b: float) -> str:
    return f'{(b - a) / a * 100:+.2f} %' if a and math.isfinite(a) and math.isfinite(b) else '-'


def _formation_norms(run: Run, i: int, t_end: float) -> np.ndarray:
    keep = _window(run.formation_error_time(i), t_end)
    return np.linalg.norm(run.formation_errors(i)[keep], axis=1)


def comparison_rows(runs: Sequence[Run], scenarios: Sequence[Scenario | None]
                    ) -> list[tuple[str, float, float]]:
    """(quantity with unit, value of A, value of B) over the common time span; NaN where a run
    has no such quantity (a follower it lacks)."""
    t_end = _common_end(runs)
    swings = [swing_metrics(r, s, t_end) for r, s in zip(runs, scenarios)]
    rows = [('payload swing, max [m]', swings[0]['max'], swings[1]['max']),
            ('payload swing, rms [m]', swings[0]['rms'], swings[1]['rms'])]
    means = [float(r.rotor_speeds(1)[_window(r.rotor_time(1), t_end)].mean()) for r in runs]
    rows.append(('leader mean rotor speed [rad/s]', means[0], means[1]))
    followers = sorted(set(runs[0].followers) | set(runs[1].followers))
    for stat, fn in (('mean', np.mean), ('max', np.max)):
        for i in followers:
            values = [float(fn(_formation_norms(r, i, t_end))) if i in r.followers else math.nan
                      for r in runs]
            rows.append((f'{stat} |g_vc| UAV {i} [m]', values[0], values[1]))
    return rows


def comparison_numbers(runs: Sequence[Run], labels: Sequence[str],
                       scenarios: Sequence[Scenario | None]) -> list[str]:
    """The table `compare` prints: payload swing, leader rotor speed, virtual-constraint error
    per follower, over the common time span; the last column is (B - A) / A."""
    t_end = _common_end(runs)
    periods = ' / '.join(f'{pendulum_period(r, s):.1f}' for r, s in zip(runs, scenarios))
    width = max(10, max(len(label) for label in labels) + 2)
    lines = [f'compared over t = 0 .. {t_end:.1f} s (the shorter run)',
             f'{"":34}{labels[0]:>{width}}{labels[1]:>{width}}{"B vs A":>10}']
    for name, a, b in comparison_rows(runs, scenarios):
        cells = [f'{v:.3f}' if abs(v) < 100 else f'{v:.1f}' for v in (a, b)]
        cells = [c if c != 'nan' else '-' for c in cells]
        lines.append(f'{name:34}{cells[0]:>{width}}{cells[1]:>{width}}{_percent(a, b):>10}')
    lines.append("swing: the payload's horizontal offset from the UAVs' centroid about its "
                 f'moving mean over one pendulum period ({periods} s)')
    lines.append("|g_vc|: norm of a follower's virtual-constraint rows")
    return lines


def _compare_needs(run: Run) -> list[str]:
    need = [PAYLOAD_ODOM, '/uav1/rotor_cmd']
    return [t for t in need if not run.has(t)]


def compare_main(argv: list[str]) -> int:
    """`multilift compare BAG_A BAG_B [--out DIR] [--labels A B]`: seed Fig. 4.15-4.17 with both
    runs on the same axes, and a few numbers. Returns the exit code (0 done, 2 bad input)."""
    parser = _Parser(prog='multilift compare', description='compare two recorded runs')
    parser.add_argument('bags', nargs=2, metavar='BAG', help='two bag directories: A and B')
    parser.add_argument('--out', help='output directory (default: BAG_A/compare_<name of B>)')
    parser.add_argument('--labels', nargs=2, metavar=('A', 'B'),
                        help='legend names (default: the scenario names)')
    parser.add_argument('--scenario-a', help='scenario of A if its summary.json has none')
    parser.add_argument('--scenario-b', help='scenario of B if its summary.json has none')
    args = _parse(parser, argv)
    if isinstance(args, int):
        return args
    runs = [_load(bag) for bag in args.bags]
    if any(r is None for r in runs):
        return 2
    for run in runs:
        missing = _compare_needs(run)
        if missing:
            print(f'error: bag {run.path} has no {", ".join(missing)}', file=sys.stderr)
            return 2
    labels = list(args.labels) if args.labels else [r.label for r in runs]
    if labels[0] == labels[1]:
        labels = [f'{labels[0]} (A)', f'{labels[1]} (B)']
    scenarios = [_context(r, s).scenario for r, s in zip(runs, (args.scenario_a,
                                                                   args.scenario_b))]
    out = Path(args.out) if args.out else runs[0].path / f'compare_{runs[1].path.name}'
    out.mkdir(parents=True, exist_ok=True)
    written = [save_figure(fig_compare_payload(runs, labels), out / 'compare_payload.png')]
    if any(r.followers for r in runs):
        written.append(save_figure(fig_compare_formation_error(runs, labels, scenarios),
                                   out / 'compare_formation_error.png'))
    else:
        print('skipped compare_formation_error: neither run has followers', file=sys.stderr)
    written.append(save_figure(fig_compare_leader_rotors(runs, labels, scenarios),
                               out / 'compare_leader_rotor_speed.png'))
    for path in written:
        print(path)
    print('\n'.join(comparison_numbers(runs, [f'A: {labels[0]}', f'B: {labels[1]}'],
                                         scenarios)))
    return 0
