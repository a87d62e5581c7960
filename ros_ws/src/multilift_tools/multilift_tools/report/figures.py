"""The figures of `multilift reproduce`: the figure functions of multilift_tools.figures,
.compare, .modal_cli and .studies, plus a caption footer (the seed's caption), mission phase
marks, the climb zoom of Fig. 4.8 and the gust spans of Fig. 4.15; PNG files at FIG_DPI [dpi].
"""
from __future__ import annotations

import math
import shutil
from pathlib import Path
from typing import Any, Sequence

from multilift_sim.scenario import Scenario
from multilift_tools.report.measure import CLIMB_START, delivered_thrust
from multilift_tools.report.numbers import GustEncounter, phases
from multilift_tools.report.seed import MULTI, SEED_CAPTIONS, SWING, TWIN

FIG_DPI = 100
LABELS = ('TL: twin-lift', 'ML: V of three')


def _caption_footer(fig: Any, number: str) -> None:
    """The seed's caption and the frame, below everything the figure already draws (3-D axes
    put tick labels outside their box, so the drawn extent is measured first)."""
    import textwrap
    fig.canvas.draw()
    box = fig.get_tightbbox(fig.canvas.get_renderer())          # [inch]
    width, height = fig.get_figwidth(), fig.get_figheight()
    text = (f'Counterpart of seed Fig. {number}: "{SEED_CAPTIONS[number]}" '
            'Here: world frame, z up (the seed: z down, y mirrored).')
    fig.text((box.x0 + box.x1) / 2 / width, box.y0 / height - 0.01,
             textwrap.fill(text, int(box.width * 12)), ha='center', va='top', fontsize=9,
             color='0.15')


def save_with_caption(fig: Any, path: Path, number: str) -> Path:
    """Add the caption footer, write the PNG at FIG_DPI (tight bounding box), close."""
    import matplotlib.pyplot as plt
    _caption_footer(fig, number)
    fig.savefig(path, dpi=FIG_DPI, bbox_inches='tight', pad_inches=0.12)
    plt.close(fig)
    return path


def _mark_phases(axes: Sequence[Any], scenario: Scenario) -> None:
    """Mission phase switches as dotted vertical lines; the phases named on a secondary axis
    along the top of the first axes."""
    spans = phases(scenario)
    for ax in axes:
        for phase in spans[1:]:
            ax.axvline(phase.start, color='0.55', lw=0.8, ls=':', zorder=0)
    top = axes[0].secondary_xaxis('top')
    top.set_xticks([(p.start + p.end) / 2 for p in spans], labels=[p.name for p in spans])
    top.tick_params(length=0, labelsize=7, labelcolor='0.3', pad=1)


def _climb_inset(fig: Any, run: Any, scenario: Scenario, excess: float) -> None:
    """Fig. 4.8: a zoom on the climb, where the seed reads its 6.14 %: delivered thrust
    k_T sum(omega^2) [N] of every UAV, in room made above the curves."""
    from multilift_tools.plot_style import uav_color, uav_label
    ax = fig.axes[0]
    low, high = ax.get_ylim()
    ax.set_ylim(low, high + 0.55 * (high - low))
    if ax.get_legend() is not None:
        ax.get_legend().set_loc('lower right')     # below the curves, clear of the inset
    inset = ax.inset_axes((0.4, 0.64, 0.34, 0.28))
    climb = phases(scenario)[0]
    name, start, end = climb.name, climb.start, climb.end
    t = run.rotor_time(1)
    keep = (t >= start) & (t < end)
    for i in range(1, run.n_uavs + 1):
        inset.plot(t[keep], delivered_thrust(run, scenario, i)[keep], color=uav_color(i),
                   lw=0.9, label=uav_label(i))
    inset.set_title(f'{name} {start:g}-{end:g} s, delivered thrust: leader {excess:+.2f} % '
                    f'over the first {CLIMB_START:g} s', fontsize=7)
    inset.tick_params(labelsize=7)
    inset.set_ylabel('[N]', fontsize=7)
    inset.grid(True, alpha=0.3)
    inset.legend(fontsize=6, loc='lower right')


def _mark_gusts(axes: Sequence[Any], encounters: Sequence[GustEncounter], who: str
                ) -> None:
    """Shade where a payload is inside a gust (gust_encounters), named on the first axes."""
    for k, e in enumerate(encounters, start=1):
        if e.t_in is None:
            continue
        for ax in axes:
            ax.axvspan(e.t_in, e.t_out, color='tab:cyan', alpha=0.3, lw=0, zorder=0)
        axes[0].text((e.t_in + e.t_out) / 2, 0.04, f'{who} payload\nin gust {k}',
                     transform=axes[0].get_xaxis_transform(), ha='center', va='bottom',
                     fontsize=7, color='tab:blue')


def make_figures(runs: dict[str, Any], scenarios: dict[str, Scenario], figures: Path,
                 study_dir: Path, climb_excess: float, gusts: Sequence[GustEncounter]
                 ) -> dict[str, str]:
    """Every figure of the report: seed number -> PNG file name under `figures`;
    climb_excess [%]: the twin-lift leader's thrust excess over the first 2 s (Fig. 4.8);
    gusts: the V's gust encounters (Fig. 4.15; the twin-lift meets none)."""
    from multilift_tools import compare as cp, figures as pl
    from multilift_tools.plot_style import WORLD, Context

    files: dict[str, str] = {'2.12': 'fig2_12_twin_lift_eigenvalues.png'}
    time_figures = (pl.fig_cable_constraints, pl.fig_attitude, pl.fig_formation_errors,
                    pl.fig_thrust)
    swing = Context(runs[SWING], scenarios[SWING])
    fig = pl.fig_trajectories_3d(swing)
    payload = scenarios[SWING].payload
    fig.suptitle(f'{SWING}: UAV and payload paths, released at α = '
                 f'{math.degrees(payload.alpha):g}°, β = {math.degrees(payload.beta):g}° '
                 f'({WORLD}); the UAV moves little')
    files['4.1'] = save_with_caption(fig, figures / 'fig4_01_single_lift_trajectories.png',
                                     '4.1').name
    for number, source, name in (('4.2', 'baumgarte_constraint.png',
                                  'fig4_02_baumgarte_constraint.png'),
                                 ('4.3', 'baumgarte_position_error.png',
                                  'fig4_03_baumgarte_position_error.png')):
        shutil.copyfile(study_dir / source, figures / name)
        files[number] = name
    per_run = {TWIN: (('4.4', pl.fig_cable_constraints, 'constraints'),
                      ('4.5', pl.fig_top_view, 'top_view'),
                      ('4.6', pl.fig_attitude, 'attitude'),
                      ('4.7', pl.fig_formation_errors, 'formation_errors'),
                      ('4.8', pl.fig_thrust, 'thrust'),
                      ('4.9', pl.fig_trajectories_3d, 'trajectories')),
               MULTI: (('4.10', pl.fig_cable_constraints, 'constraints'),
                       ('4.11', pl.fig_formation_errors, 'formation_errors'),
                       ('4.12', pl.fig_thrust, 'thrust'),
                       ('4.13', pl.fig_top_view, 'top_view'),
                       ('4.14', pl.fig_trajectories_3d, 'trajectories'))}
    for case, specs in per_run.items():
        ctx = Context(runs[case], scenarios[case])
        for number, make, stem in specs:
            fig = make(ctx)
            if make in time_figures:
                _mark_phases(fig.axes, scenarios[case])
            if number == '4.8':
                _climb_inset(fig, runs[case], scenarios[case], climb_excess)
            name = f'fig4_{int(number.split(".")[1]):02d}_{case}_{stem}.png'
            files[number] = save_with_caption(fig, figures / name, number).name
    pair = [runs[TWIN], runs[MULTI]]
    pair_scenarios = [scenarios[TWIN], scenarios[MULTI]]
    compare = (('4.15', lambda: cp.fig_compare_payload(pair, LABELS), 'payload'),
               ('4.16', lambda: cp.fig_compare_formation_error(pair, LABELS, pair_scenarios),
                'formation_error'),
               ('4.17', lambda: cp.fig_compare_leader_rotors(pair, LABELS, pair_scenarios),
                'leader_rotor_speed'))
    for number, make, stem in compare:
        fig = make()
        _mark_phases(fig.axes, scenarios[TWIN])
        if number == '4.15':
            _mark_gusts(fig.axes, gusts, LABELS[1].split(':')[0])
        name = f'fig4_{int(number.split(".")[1]):02d}_compare_{stem}.png'
        files[number] = save_with_caption(fig, figures / name, number).name
    return files
