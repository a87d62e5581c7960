"""Cables' figures (issue 32; docs/cables.md): elastic ropes' (`cable_model: elastic`) stretch
L_i - l_i [mm] (from the recorded constraint value g_i = L_i^2 - l_i^2 and the rest length
l_i, the scenario's or a winch's /uav{i}/cable_length: L_i - l_i = g_i / (L_i + l_i)) and
tension T_i [N] over time; winches' (`uavs[i].winch`) reeled lengths [m] and the tensions.
World frame, SI units (the stretch in mm)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from multilift_tools.bagdata import Run, RunDataError
from multilift_tools.plot_style import (Context, finish_time_axes, legend, plt, uav_color,
                                        uav_width)

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def lacks_ropes(run: Run) -> list[str]:
    """Why the bag has no rope figure: its run's summary gives no rope stretch (a run on
    cables that do not stretch, or a bag without summary.json)."""
    sim = run.summary.get('sim', {})
    if sim.get('max_sag'):  # a chain's g is its worst link's, not a rope's stretch
        return ['elastic links of a chain (their max_stretch is in the summary; the stretch '
                'plot reads a rope\'s from g)']
    if sim.get('max_stretch'):
        return []
    return ['no elastic ropes (the summary gives no max_stretch: cable_model is not elastic)']


def fig_rope_stretch(ctx: Context) -> Figure:
    """Each rope's stretch [mm] and tension [N] at the recorded ticks."""
    run, scenario = ctx.run, ctx.scenario
    if scenario is None:
        raise RunDataError('the ropes\' rest lengths need the scenario (--scenario)')
    t, g, tension = run.formation_time, run.g(), run.tensions()
    rest = np.array([u.cable_length for u in scenario.uavs], dtype=float) * np.ones_like(g)
    for i in scenario.winches:  # a reeled rope's rest length, at the formation's stamps
        rest[:, i - 1] = np.interp(t, *run.cable_lengths(i))
    stretch = g / (np.sqrt(np.maximum(g + rest ** 2, 0.0)) + rest)   # L_i - l_i [m]
    fig, (ax_s, ax_t) = plt.subplots(2, 1, sharex=True, figsize=(9, 6), layout='constrained')
    for k in range(g.shape[1]):
        i = k + 1
        ax_s.plot(t, 1e3 * stretch[:, k], color=uav_color(i), lw=uav_width(i, 1.0),
                  label=f'rope {i}: max {1e3 * stretch[:, k].max():.3f} mm')
        ax_t.plot(t, tension[:, k], color=uav_color(i), lw=uav_width(i, 1.0),
                  label=f'$T_{i}$: peak {tension[:, k].max():.2f} N')
    ax_s.axhline(0.0, color='0.3', lw=0.7)
    ax_s.set_ylabel('stretch $L_i - l_i$ [mm]\n(< 0: slack)')
    ax_t.set_ylabel('rope tension $T_i$ [N]')
    ax_s.set_title(f'{run.label}: elastic ropes, stretch and tension (at the control ticks)',
                   fontsize='medium')
    for ax in (ax_s, ax_t):
        legend(ax, loc='upper right', ncols=min(g.shape[1], 4))
    finish_time_axes([ax_s, ax_t])
    return fig


def lacks_winches(run: Run) -> list[str]:
    """Why the bag has no reeled-length figure: no /uav{i}/cable_length (no winch)."""
    if any(run.has(topic) for topic in run.series if topic.endswith('/cable_length')):
        return []
    return ['no winches (no /uav{i}/cable_length: no uavs[i].winch)']


def fig_cable_lengths(ctx: Context) -> Figure:
    """Each winch's cable length [m] and each cable's tension [N] over time."""
    run = ctx.run
    fig, (ax_l, ax_t) = plt.subplots(2, 1, sharex=True, figsize=(9, 6), layout='constrained')
    for i in range(1, run.n_uavs + 1):
        if not run.has(f'/uav{i}/cable_length'):
            continue
        t, length = run.cable_lengths(i)
        ax_l.plot(t, length, color=uav_color(i), lw=uav_width(i, 1.0),
                  label=f'cable {i}: {length.min():.2f} .. {length.max():.2f} m')
    tension = run.tensions()
    for k in range(tension.shape[1]):
        i = k + 1
        ax_t.plot(run.formation_time, tension[:, k], color=uav_color(i), lw=uav_width(i, 1.0),
                  label=f'$T_{i}$')
    ax_l.set_ylabel('cable length $l_i$ [m]')
    ax_t.set_ylabel('cable tension $T_i$ [N]')
    ax_l.set_title(f'{run.label}: winches, reeled length and tension', fontsize='medium')
    for ax in (ax_l, ax_t):
        legend(ax, loc='upper right', ncols=min(tension.shape[1], 4))
    finish_time_axes([ax_l, ax_t])
    return fig
