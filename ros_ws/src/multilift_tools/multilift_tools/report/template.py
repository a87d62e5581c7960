"""The one renderer of docs/reproduction.md: `templates/reproduction.md` (markdown with
`str.format` placeholders) filled from a numbers.Report of typed measurements.

The template reads the measurements' fields with their units' formats (`{tl.max_g:.1e}` is the
twin-lift's max |g| [m²]) and the scenarios' own facts (`{sc_twin.simulation.physics_rate:g}`);
`_texts` adds what a format field cannot say: lists joined, ratios, unit conversions (cm, ms,
deg), the seed frame, and the sentences that depend on a comparison. Names in the template:

    r       the Report            s    SingleLiftNumbers      b   BaumgarteNumbers
    sw      SwingNumbers          tl   twin-lift run          ml  the V's run
    tm, vm  ModalNumbers          sc_swing, sc_twin, sc_multi  the loaded scenarios
    vehicle the twin-lift's vehicle (Table 4.2)                fx  fixed names and windows
    t       derived texts and numbers (_texts)                head  figure headings by number
"""
from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING

import numpy as np

from multilift_tools.report.seed import (MULTI, SEED_EIGENVALUE, SEED_PERIOD, SEED_RELEASE,
                                           SWING, TWIN)
from multilift_tools.report.single_lift import SMALL_RELEASE_DEG, render_table, vector_text

if TYPE_CHECKING:
    from multilift_tools.report.numbers import Report

TEMPLATE = Path(__file__).parent / 'templates' / 'reproduction.md'
_WORDS = ('no', 'one', 'two', 'three', 'four', 'five', 'six', 'seven', 'eight', 'nine', 'ten',
          'eleven', 'twelve')


def _cmd_run(name: str) -> str:
    """The command that records scenario `name`'s bag under runs/."""
    return f'scripts/multilift run {name} --headless --bag runs/{name}'


def _join(values, digits: int = 2, sep: str = ' / ') -> str:
    """Numbers joined by `sep`, `digits` decimals."""
    return sep.join(f'{v:.{digits}f}' for v in values)


def _axis_name(direction) -> str:
    """'+i', '-j', ... for a unit vector along an axis, else the vector."""
    d = np.asarray(direction, dtype=float)
    k = int(np.argmax(np.abs(d)))
    if abs(abs(d[k]) - 1.0) < 1e-9:
        return f'{"+" if d[k] > 0 else "-"}{"ijk"[k]}'
    return vector_text(d)


def _figure_head(number: str, caption: str, file: str) -> str:
    """A figure's heading, the seed's caption quoted, and our PNG."""
    return (f'### Fig. {number}\n\n> Seed, Fig. {number}: *"{caption}"*\n\n'
            f'![Fig. {number}: {caption}](figures/{file})')


def _texts(r: Report, fx: SimpleNamespace) -> SimpleNamespace:
    """What the template needs beyond a field and a format (see the module docstring)."""
    from multilift_sim.frames import world_to_seed_vector
    from multilift_tools.report.cases import CASES
    from multilift_tools.report.measure import STEADY, CRUISE

    s, tl, ml, sw = r.single, r.twin, r.multi, r.swing
    swing_sc, twin_sc, multi_sc = r.setup.swing, r.setup.twin, r.setup.multi
    vehicle = twin_sc.uavs[0].vehicle
    max_thrust = vehicle.max_thrust
    follower = tl.followers[0]
    mission = tl.phases
    climb = mission[0]
    cruises = [p for p in mission if p.name.endswith('cruise')]
    turns = [a.end for a, b in zip(cruises, cruises[1:]) if a.end == b.start]
    effect = r.gust_effect
    first_more = effect[0] > effect[1]
    worse = [f'{k:g}' for k, row in zip(r.baumgarte.gains[1:], r.baumgarte.baumgarte[1:])
             if row.max_abs_g > r.baumgarte.baumgarte[0].max_abs_g]
    gain_last = r.baumgarte.gains[-1]
    step = r.baumgarte.dt
    principal = np.asarray(vehicle.inertia, dtype=float)
    principal = np.diag(principal) if principal.ndim == 2 else principal
    alpha, beta = math.degrees(swing_sc.payload.alpha), math.degrees(swing_sc.payload.beta)
    from multilift_tools.studies import DEFAULT_DURATION
    legs = [f'{vector_text(world_to_seed_vector(seg.velocity), 1)} m/s for '
            f'{p.start:g}-{p.end:g} s' for p, seg in zip(mission, twin_sc.mission.segments)]
    gusts = [f'{vector_text(world_to_seed_vector((*g.center, 0.0))[:2], 0)} along '
             f'{_axis_name(world_to_seed_vector(g.direction))}, H {g.gradient_distance:g}, '
             f'U_ref {g.reference_speed:g}' for g in twin_sc.gusts]
    centres = [world_to_seed_vector((*g.center, 0.0))[:2] for g in twin_sc.gusts]
    return SimpleNamespace(
        case_count=len(CASES), total_wall=r.wall.get('total', 0.0),
        case_walls=', '.join(f'{c} {r.wall[c]:.0f} s' for c in CASES),
        release=vector_text(s.release), release_world=vector_text(s.release_world),
        seed_release=vector_text(SEED_RELEASE),
        eigenvalues=', '.join(f'±{w:.4f}j' for w in s.eigenvalues),
        linear_vs_seed=(s.linear_period / SEED_PERIOD - 1) * 100,
        large_vs_linear=(s.period_large / s.linear_period - 1) * 100,
        swing_alpha=alpha, swing_beta=beta, swing_release=f'{alpha:g}°/{beta:g}°',
        theta0=math.degrees(sw.amplitude), law_factor=s.period_law / s.linear_period,
        cycles=sw.duration / s.period_large,
        drift=sw.duration / s.period_large * (s.period_large - s.linear_period),
        excursion_ratio=sw.uav_excursion / sw.payload_excursion,
        single_table='\n'.join(render_table(s.rows)),
        file_swing=f'scenarios/{SWING}.yaml', files_formation=f'scenarios/{TWIN}.yaml, '
        f'{MULTI}.yaml', inertia='diag(' + ', '.join(f'{j:g}' for j in principal) + ')',
        mission_legs='; '.join(legs), gust_list='; '.join(gusts),
        gust_centres=' and '.join('(' + ', '.join(f'{c + 0.0:g}' for c in xy) + ')'
                                  for xy in centres),
        twin_offset=vector_text(world_to_seed_vector(twin_sc.formation.offsets[0])),
        v_half_angle=math.degrees(multi_sc.formation.half_angle),
        duration=tl.duration, steady=f'{STEADY[0]:g}-{STEADY[1]:g} s',
        cruise=f'{CRUISE[0]:g}-{CRUISE[1]:g} s', climb_length=climb.end - climb.start,
        turns=' and '.join(f'{t:g} s' for t in turns),
        phase_names=', '.join(p.name for p in mission),
        max_thrust=max_thrust,
        heaviest_payload=max_thrust / twin_sc.simulation.gravity - vehicle.mass,
        twin_dependent=', '.join(r.twin_modal.dependent),
        twin_periods=_join(r.twin_modal.periods, 2, ', '),
        twin_modal_tilt=_join(r.twin_modal.tilt_deg),
        twin_modal_tensions=_join(r.twin_modal.tensions, 3),
        v_periods=_join(r.multi_modal.periods, 2, ', '),
        twin_swing_phases=', '.join(f'{p.phase.name} {p.max_swing:.2f}'
                                    for p in tl.swing_phases),
        twin_swing_phases_m=', '.join(f'{p.phase.name} {p.max_swing:.2f} m'
                                      for p in tl.swing_phases),
        twin_tilt_rows=', '.join(f'UAV {i + 1} {a.measured:.2f} ({a.needed:.2f})'
                                 for i, a in enumerate(tl.tilt)),
        twin_tilt_measured=', '.join(f'{a.measured:.2f}°' for a in tl.tilt),
        twin_tilt_needed=', '.join(f'{a.needed:.2f}°' for a in tl.tilt),
        twin_follower=follower,
        twin_distance_change=(tl.distances[0].mean / tl.distances[0].commanded - 1) * 100,
        thrust_share=(tl.thrust_mean_after_climb[0] / tl.thrust_mean_after_climb[1] - 1) * 100,
        twin_gvc_late=', '.join(f'{f.mean_late:.3f}' for f in tl.followers),
        v_gvc_late=', '.join(f'{f.mean_late:.3f}' for f in ml.followers),
        v_gvc_late_named=', '.join(f'UAV {f.uav} {f.mean_late:.3f} m' for f in ml.followers),
        v_distances=', '.join(f'{d.mean:.2f}' for d in ml.distances),
        twin_gust_speeds=_join(g.peak_speed for g in tl.gusts),
        twin_gust_closest=_join(g.closest for g in tl.gusts),
        v_gust_speeds=_join(g.peak_speed for g in ml.gusts),
        v_gust_closest=_join(g.closest for g in ml.gusts),
        gust_effect=_join(effect, 3), effect_cm=[e * 100 for e in effect],
        stronger_gust=('more by the first gust' if first_more else
                       'more by the second gust (it blows against the direction of flight, '
                       'adding to the air speed the quadratic drag sees)'),
        second_gust_clause='' if first_more else (', and for the V the second moves the '
                                                  'payload more'),
        rotor_drop=(1 - ml.leader_omega_cruise / tl.leader_omega_cruise) * 100,
        rotor_drop_all=(1 - ml.leader_omega_all / tl.leader_omega_all) * 100,
        comparison='\n'.join(r.comparison),
        study_step_ms=step * 1e3, study_default_duration=DEFAULT_DURATION,
        cmd_study=f'scripts/multilift study baumgarte --duration {r.baumgarte.duration:g}',
        baumgarte_max=', '.join(f'α_f = {k:g}: {row.max_abs_g:.1e} m²' for k, row in
                                zip(r.baumgarte.gains, r.baumgarte.baumgarte)),
        baumgarte_worse=(
            f'- Over these {r.baumgarte.duration:g} s α_f = {" and ".join(worse)} ends up with '
            f'a larger residual than no stabilisation: at a {step * 1e3:g} ms step the '
            'critically damped Baumgarte poles at -α_f sit where RK4 is inaccurate (α_f dt = '
            f'{gain_last * step:g} for α_f = {gain_last:g}), so the stabilisation term itself '
            f'is the largest error source. At the scenario\'s own '
            f'{1e3 / swing_sc.simulation.physics_rate:g} ms step the run stays within '
            f'{sw.max_g:.0e} m² (Fig. 4.1\'s bag).\n' if worse else ''),
        gain_last=gain_last, last_gain=r.baumgarte.baumgarte[-1],
        swing_step_ms=1e3 / swing_sc.simulation.physics_rate,
        made_twin=f'`{_cmd_run(TWIN)}` then `scripts/multilift plot runs/{TWIN}`',
        made_multi=f'`{_cmd_run(MULTI)}` then `scripts/multilift plot runs/{MULTI}`',
        orders_below_seed=_WORDS[round(math.log10(2e-2 / tl.max_g))],  # the seed's eps_g
        twin_g_order=f'1e{math.floor(math.log10(tl.max_g))}',
        twin_release=math.degrees(twin_sc.payload.swing))


def render_report(r: Report, template: str | None = None) -> str:
    """docs/reproduction.md as text: TEMPLATE (or `template`) filled from `r`."""
    from multilift_tools.report.measure import (AFTER_GUST, AFTER_SWITCH, CLIMB_START,
                                                HOVER_TAIL, LATE)
    from multilift_tools.report.seed import SEED_CAPTIONS
    fx = SimpleNamespace(
        swing=SWING, twin=TWIN, multi=MULTI, cmd_swing=_cmd_run(SWING), cmd_twin=_cmd_run(TWIN),
        cmd_multi=_cmd_run(MULTI),
        cmd_compare=f'scripts/multilift compare runs/{TWIN} runs/{MULTI} --labels TL ML',
        seed_period=SEED_PERIOD, seed_eigenvalue=SEED_EIGENVALUE,
        small_release=SMALL_RELEASE_DEG, late=LATE, hover_tail=HOVER_TAIL,
        after_switch=AFTER_SWITCH, after_gust=AFTER_GUST, climb_start=CLIMB_START)
    head = {number: _figure_head(number, caption, r.files[number])
            for number, caption in SEED_CAPTIONS.items()}
    text = TEMPLATE.read_text(encoding='utf-8') if template is None else template
    return text.format(
        r=r, s=r.single, b=r.baumgarte, sw=r.swing, tl=r.twin, ml=r.multi, tm=r.twin_modal,
        vm=r.multi_modal, sc_swing=r.setup.swing, sc_twin=r.setup.twin,
        sc_multi=r.setup.multi, vehicle=r.setup.twin.uavs[0].vehicle, fx=fx,
        t=_texts(r, fx), head=head)
