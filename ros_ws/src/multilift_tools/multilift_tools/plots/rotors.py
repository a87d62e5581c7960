"""The UAVs' actuation: `fig_thrust` (collective thrust, asked and delivered),
`fig_thrust_margins` (the share of each UAV's largest thrust left) and
`fig_rotor_speeds` (each rotor's speed [rad/s] after saturation, the bands beyond the limits
grey, and where a rotor was clipped: a strip at the top for the upper limit, at the bottom for
the lower one). Each rotor has its own colour and dash, so six (a hexarotor) stay apart where
they overlap.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from multilift_sim.topics import ATTITUDE_SETPOINT, ROTOR_CMD, uav_topic
from multilift_tools.bagdata import Run, rotor_limits
from multilift_tools.plot_style import (SATURATION_GREY, Context, finish_time_axes,
                                        finish_time_plot, legend, plt, shade_flags, uav_color,
                                        uav_label, uav_width, value_span, vehicle_of)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

# rotor k's line: colour C(k) and the k-th dash (k from 0); distinct for up to 8 rotors
ROTOR_DASHES = ('-', (0, (6, 2)), (0, (2, 1.5)), (0, (6, 2, 2, 2)), (0, (1, 1)),
                (0, (8, 2, 1, 2, 1, 2)), (0, (4, 4)), (0, (3, 1, 1, 1)))
CLIP_HIGH = 'clipped at ω_max (top strip)'
CLIP_LOW = 'clipped at ω_min (bottom strip)'


def rotor_style(k: int) -> dict:
    """Colour, dash and width of rotor k (from 0) in every rotor panel."""
    return {'color': f'C{k % 10}', 'ls': ROTOR_DASHES[k % len(ROTOR_DASHES)],
            'lw': 1.6 - 0.15 * (k % 6)}


def fig_thrust(ctx: Context) -> Figure:
    """Collective thrust per UAV [N]: set-point and, with k_T known, k_T sum(omega^2)."""
    run = ctx.run
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    max_thrust = []
    for i in range(1, run.n_uavs + 1):
        if run.has(uav_topic(i, ATTITUDE_SETPOINT)):
            ax.plot(run.setpoint_time(i), run.thrust(i), color=uav_color(i), lw=uav_width(i),
                    label=f'{uav_label(i)} set-point')
        vehicle = vehicle_of(ctx, i)
        if vehicle is not None and run.has(uav_topic(i, ROTOR_CMD)):
            omega = run.rotor_speeds(i)
            ax.plot(run.rotor_time(i), vehicle.collective_thrust(omega),
                    color=uav_color(i), lw=0.8, ls='--', alpha=0.8,
                    label=f'{uav_label(i)} delivered $k_T \\sum\\omega^2$')
            max_thrust.append(vehicle.max_thrust)
    if max_thrust and np.allclose(max_thrust, max_thrust[0]):
        ax.axhline(max_thrust[0], color='tab:red', lw=1.0, ls='-.',
                   label=f'max thrust {max_thrust[0]:.2f} N (all rotors at ω_max)')
    finish_time_plot(ax, 'thrust along body z [N]', f'{run.label}: collective thrust per UAV',
                     loc='best', ncols=2)
    return fig


def clipped_sides(omega: np.ndarray, saturated: np.ndarray,
                  limits: tuple[float, float] | None) -> tuple[np.ndarray, np.ndarray]:
    """(high, low) (T,) bool: some rotor clipped at its upper / lower limit. A flagged rotor
    is high when nearer omega_max than omega_min (without limits: above the median speed)."""
    if limits is None:
        middle = float(np.median(omega))
        high = saturated & (omega >= middle)
    else:
        w_min, w_max = limits
        high = saturated & (np.abs(omega - w_max) <= np.abs(omega - w_min))
    return high.any(axis=1), (saturated & ~high).any(axis=1)


def _rotor_panel(ax: Axes, run: Run, i: int, limits: tuple[float, float] | None,
                 limit_note: str) -> None:
    t, omega, sat = run.rotor_time(i), run.rotor_speeds(i), run.saturated(i)
    for k in range(omega.shape[1]):
        ax.plot(t, omega[:, k], label=f'rotor {k + 1}', **rotor_style(k))
    lo, hi = value_span(omega)
    if limits is not None:
        w_min, w_max = limits
        lo, hi = min(lo, w_max), max(hi, w_max)
        margin = 0.08 * max(hi - lo, 1.0)
        ax.axhspan(w_max, hi + margin, color=SATURATION_GREY, zorder=0,
                   label=f'beyond ω_max = {w_max:g} rad/s{limit_note}')
        if lo - margin < w_min:
            ax.axhspan(lo - margin, w_min, color=SATURATION_GREY, zorder=0,
                       label=f'below ω_min = {w_min:g} rad/s')
        ax.set_ylim(lo - margin, hi + margin)
    high, low = clipped_sides(omega, sat, limits)
    shade_flags(ax, t, high, CLIP_HIGH)
    shade_flags(ax, t, low, CLIP_LOW, color='tab:purple', side='bottom')
    ax.set_ylabel(f'UAV {i}: ω [rad/s]')
    ax.set_title(f'{uav_label(i)}: a rotor clipped {np.mean(sat.any(axis=1)) * 100:.1f} % of '
                 f'the time (at ω_max {np.mean(high) * 100:.1f} %, at ω_min '
                 f'{np.mean(low) * 100:.1f} %), mean ω = {omega.mean():.0f} rad/s',
                 fontsize='small')
    _label_ends(ax, t, omega)
    legend(ax, loc='upper left', bbox_to_anchor=(1.01, 1.0))


def rotor_groups(final: np.ndarray, near: float) -> list[list[int]]:
    """Rotors (from 1) grouped by their final speed [rad/s]: within `near` of the group's
    first, in order of speed."""
    groups: list[list[int]] = []
    for k in np.argsort(final, kind='stable'):
        if groups and abs(final[k] - final[groups[-1][0] - 1]) <= near:
            groups[-1].append(int(k) + 1)
        else:
            groups.append([int(k) + 1])
    return groups


def _label_ends(ax: Axes, t: np.ndarray, omega: np.ndarray) -> None:
    """Which rotors end where: 'rotors 1, 4' at the right end of the lines they share (lines
    that lie on each other cannot be told apart by colour alone)."""
    final = omega[-1]
    near = 0.01 * max(float(np.ptp(omega)), 1.0)
    for group in rotor_groups(final, near):
        names = ', '.join(str(k) for k in sorted(group))
        ax.annotate(f'{"rotors" if len(group) > 1 else "rotor"} {names}',
                    (t[-1], final[group[0] - 1]), textcoords='offset points', xytext=(-2, 4),
                    ha='right', fontsize='small', color='0.15')


def fig_thrust_margins(ctx: Context) -> Figure:
    """Each UAV's thrust margin 1 - u_T / u_T,max [%] of its commanded rotor speeds (issue
    35: the share of its largest thrust left; every rotor counted fully effective, where the
    summary's least margin counts a fault's), its least marked."""
    run = ctx.run
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    for i in range(1, run.n_uavs + 1):
        vehicle = vehicle_of(ctx, i)
        if vehicle is None or not run.has(uav_topic(i, ROTOR_CMD)):
            continue
        margin = 100.0 * vehicle.thrust_margin(run.rotor_speeds(i))
        ax.plot(run.rotor_time(i), margin, color=uav_color(i), lw=uav_width(i),
                label=f'{uav_label(i)}: least {margin.min():.1f} %')
    ax.axhline(0.0, color='tab:red', lw=1.0, ls='-.',
               label='no thrust left (every rotor at ω_max)')
    finish_time_plot(ax, 'thrust margin $1 - u_T / u_{T,max}$ [%]',
                     f'{run.label}: the share of each UAV\'s largest thrust left',
                     loc='best', ncols=2)
    return fig


def fig_rotor_speeds(ctx: Context) -> Figure:
    """Rotor speeds per UAV [rad/s] after saturation, the saturation bands shaded grey."""
    run = ctx.run
    uavs = [i for i in range(1, run.n_uavs + 1) if run.has(uav_topic(i, ROTOR_CMD))]
    fig, axes = plt.subplots(len(uavs), 1, sharex=True, squeeze=False,
                             figsize=(9, 1.5 + 2.9 * len(uavs)), layout='constrained')
    for ax, i in zip(axes[:, 0], uavs):
        note = '' if ctx.scenario is not None else ' (inferred from the flags)'
        _rotor_panel(ax, run, i, rotor_limits(run, ctx.scenario, i), note)
    fig.suptitle(f'{run.label}: rotor speeds (commands after saturation)', fontsize='medium')
    finish_time_axes(axes[:, 0])
    return fig
