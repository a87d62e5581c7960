"""The report of `multilift reproduce`: typed measurements on the cases' results, the figures,
and docs/reproduction.md (seed §2.8 and Ch. 4).

multilift_tools.reproduce runs the cases; this module measures them into frozen dataclasses of
numbers with their units (`measure`: `FormationRunNumbers` per formation run, `ModalNumbers`,
`SingleLiftNumbers`, `SwingNumbers`, `BaumgarteNumbers`, the scenario facts in `SetUp`),
draws the figures (the functions of multilift_tools.figures, .compare, .modal_cli and .studies,
plus a caption footer, mission phase marks, the climb zoom of Fig. 4.8 and the gust spans of
Fig. 4.15) and hands both to the one renderer, multilift_tools.report_template. Scenario facts
(rates, masses, cable lengths, gains, gusts, the mission) are read from the loaded scenarios,
never typed into prose. World frame, z up, SI units.
"""
from __future__ import annotations

import json
import math
import shutil
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from multilift_tools.metrics import interp_rows, peak_rms, swing_series
from multilift_tools.reproduce import (BAUMGARTE_DURATION, BAUMGARTE_GAINS, CASES, MULTI,
                                         SWING, TWIN, release_amplitude)
from multilift_sim.scenario import MissionSegment, Scenario, load

# -- the seed's figure captions (quoted from ../shared/seed, §2.8 and Ch. 4) ------------------
SEED_CAPTIONS: dict[str, str] = {
    '2.12': 'Eigenvalues from the twin-lift configuration.',
    '4.1': 'Trajectories from the single-lift system.',
    '4.2': 'Constraint equation from the single-lift system for different stabilization '
           'parameters.',
    '4.3': 'Position error from the UAV and payload for α_f = 100.',
    '4.4': 'Constraints over time from the twin-lift system.',
    '4.5': 'Top-view from the twin-lift simulation.',
    '4.6': 'Attitude from the UAVs considering the twin-lift configuration.',
    '4.7': 'Virtual constraints from the twin-lift formation control.',
    '4.8': 'Thrust force required from the UAVs in the twin-lift configuration.',
    '4.9': 'UAVs trajectories from the twin-lift configuration.',
    '4.10': 'Constraints from the multi-lift system.',
    '4.11': 'Virtual constraints from the multi-lift formation control.',
    '4.12': 'Thrust forces from the UAVs in the multi-lift configuration.',
    '4.13': 'Trajectories (Top-view) for the multi-lift configuration.',
    '4.14': 'Trajectories from the multi-lift system.',
    '4.15': 'Comparison between the payload position when considering the twin-lift and '
            'multi-lift configurations.',
    '4.16': 'Comparison between the virtual constraints when considering the twin-lift and '
            'multi-lift configurations.',
    '4.17': 'Comparison from the rotor speed from the leader in the twin-lift and multi-lift '
            'formations.',
}

# -- the report's measurement windows ---------------------------------------------------------
FIG_DPI = 100
LABELS = ('TL: twin-lift', 'ML: V of three')
LATE = 60.0                    # [s] "persistent" formation quantities are averaged after this
CRUISE = (60.0, 95.0)          # [s] a steady stretch of the -x cruise (Fig. 4.17)
STEADY = (70.0, 95.0)          # [s] steady cruise: no corner within a pendulum period
AFTER_SWITCH = 5.0             # [s] window after a phase switch (Fig. 4.12)
AFTER_GUST = 10.0              # [s] window after leaving a gust (Fig. 4.15)
HOVER_TAIL = 20.0              # [s] the last seconds of the run: the hover phase
CLIMB_START = 2.0              # [s] the start of the climb, where the thrust excess is largest


# =============================================================================================
# Typed measurements
# =============================================================================================
@dataclass(frozen=True)
class Phase:
    """A mission segment: its name ('climb', '+x cruise', 'hover', ...), start and end [s]."""

    name: str
    start: float
    end: float


@dataclass(frozen=True)
class PhaseSwing:
    """The largest payload swing [m] (metrics.swing_series) within one mission phase."""

    phase: Phase
    max_swing: float


@dataclass(frozen=True)
class GustEncounter:
    """How a payload met one gust: closest horizontal approach to its centre [m] and when [s],
    the peak gust speed it met [m/s] (Eq. 2.55 on its path), the gust's radius H [m], and when
    it entered and left the gust [s] (None: never)."""

    closest: float
    t_closest: float
    peak_speed: float
    radius: float
    t_in: float | None
    t_out: float | None


@dataclass(frozen=True)
class PairDistance:
    """Mean distance [m] of UAVs `pair` after LATE against the commanded one [m]."""

    pair: tuple[int, int]
    mean: float
    commanded: float


@dataclass(frozen=True)
class Tilt:
    """A UAV's tilt from level at the run's end [deg]: measured, and what the static balance of
    thrust, weight and the recorded cable pull needs (Eq. 2.73)."""

    measured: float
    needed: float


@dataclass(frozen=True)
class FollowerError:
    """Follower `uav`'s virtual-constraint error: mean |g_vc| after LATE and over the run [m],
    its mean rows (x, y, z) after LATE [m], and the altitude row |g_vc,z| [m]: max in the
    climb, max after it, mean in the STEADY cruise."""

    uav: int
    mean_late: float
    mean_all: float
    rows_late: tuple[float, ...]
    z_climb_max: float
    z_after_climb_max: float
    z_steady_mean: float


@dataclass(frozen=True)
class ClimbExcess:
    """The leader's delivered thrust above the first follower's in the climb [%]: over the
    first CLIMB_START s, over the whole climb, at the largest tick."""

    start: float
    whole: float
    peak: float


@dataclass(frozen=True)
class FormationRunNumbers:
    """What the report quotes of one formation run (twin-lift or V). Units: g [m²], tension
    [N], swing and distances [m], rotor speeds [rad/s], times [s], thrust [N]."""

    name: str
    duration: float
    phases: tuple[Phase, ...]
    max_g: float
    max_g_hover: float
    final_g: float
    min_tension: float
    swing_max: float
    swing_rms: float
    swing_phases: tuple[PhaseSwing, ...]
    swing_steady: float
    gusts: tuple[GustEncounter, ...]
    distances: tuple[PairDistance, ...]
    tilt: tuple[Tilt, ...]
    followers: tuple[FollowerError, ...]
    leader_omega_cruise: float
    leader_omega_all: float
    leader_omega_cruise_max: float
    saturated: tuple[float, ...]
    thrust_mean_after_climb: tuple[float, ...]
    thrust_range_switch: float
    thrust_range_steady: float
    climb_excess: ClimbExcess | None
    tracking_max: float
    tracking_rms: float

    def follower(self, uav: int) -> FollowerError:
        """The errors of follower `uav`."""
        return next(f for f in self.followers if f.uav == uav)


@dataclass(frozen=True)
class ModalNumbers:
    """The modal analysis of a formation at its Eq. 2.73 equilibrium: pendulum periods [s],
    rigid-body zeros and unstable eigenvalues (counts), independent of all coordinates, the
    dependent ones' names, UAV tilts [deg] and cable tensions [N]."""

    periods: tuple[float, ...]
    rigid: int
    unstable: int
    free: int
    coordinates: int
    dependent: tuple[str, ...]
    tilt_deg: tuple[float, ...]
    tensions: tuple[float, ...]

    @classmethod
    def from_case(cls, case: dict) -> ModalNumbers:
        """From one scenario's entry of reproduce's modal case."""
        return cls(tuple(case['periods']), case['rigid'], case['unstable'], case['free'],
                   case['coordinates'], tuple(case['dependent']), tuple(case['tilt_deg']),
                   tuple(case['tensions']))


@dataclass(frozen=True)
class SingleLiftNumbers:
    """The values of reproduce.single_lift_table: release r_p(0) - r(0) [m] (seed frame and
    world), pendulum eigenvalues [1/s], periods [s] (linear, simulated at the small and the
    seed's release, reduced model, amplitude law and its factor), the scenario's error against
    the reduced model [m], the static tension and m_p g [N]. `rows`: the table as computed."""

    release: tuple[float, float, float]
    release_world: tuple[float, float, float]
    eigenvalues: tuple[float, ...]
    linear_period: float
    period_small: float
    period_large: float
    period_reduced: float
    period_law: float
    scenario_error: float
    static_tension: float
    weight: float
    rows: tuple[dict, ...]

    @classmethod
    def from_rows(cls, rows: Sequence[dict]) -> SingleLiftNumbers:
        """From the rows' raw values (`value`)."""
        v = {r['key']: r['value'] for r in rows}
        release = tuple(v['release'])
        world = (release[0], -release[1], -release[2])        # multilift_sim.frames
        return cls(release, world, tuple(v['eigenvalues']), v['linear_period'],
                   v['period_small'], v['period_large'], v['period_reduced'], v['period_law'],
                   v['scenario_error'], v['static_tension'][0], v['static_tension'][1],
                   tuple(rows))


@dataclass(frozen=True)
class IntegratorNumbers:
    """One integrator of the Baumgarte study: max and final |g| [m²], max UAV and payload
    position error against the reduced model [m]."""

    label: str
    max_abs_g: float
    final_abs_g: float
    max_uav_error: float
    max_payload_error: float


@dataclass(frozen=True)
class BaumgarteNumbers:
    """The Baumgarte study (Fig. 4.2, 4.3): RK4 step [s], span [s], the Baumgarte runs in the
    order of BAUMGARTE_GAINS and the null-space integrator."""

    dt: float
    duration: float
    gains: tuple[float, ...]
    baumgarte: tuple[IntegratorNumbers, ...]
    nullspace: IntegratorNumbers

    @classmethod
    def from_study(cls, study: dict) -> BaumgarteNumbers:
        """From the study's JSON (studies.baumgarte_study)."""
        rows = {r['integrator']: IntegratorNumbers(
            r['integrator'], r['max_abs_g'], r['final_abs_g'], r.get('max_uav_error', math.nan),
            r.get('max_payload_error', math.nan)) for r in study['rows']}
        return cls(study['dt'], BAUMGARTE_DURATION, BAUMGARTE_GAINS,
                   tuple(rows[f'Baumgarte alpha_f = {k:g}'] for k in BAUMGARTE_GAINS),
                   rows['null space + projection'])


@dataclass(frozen=True)
class SwingNumbers:
    """Fig. 4.1 from the single-lift bag: horizontal excursions [m] of the UAV and the payload
    from their start, the release angle from the vertical [rad], m_p / m, max |g| [m²], the
    run's length [s]."""

    uav_excursion: float
    payload_excursion: float
    amplitude: float
    mass_ratio: float
    max_g: float
    duration: float


@dataclass(frozen=True)
class SetUp:
    """Scenario facts the report states, read from the loaded scenarios: rates [Hz], steps [s],
    gains [1/s], release angles [rad], durations [s], the mission's phases, the gusts."""

    swing: Scenario
    twin: Scenario
    multi: Scenario

    @property
    def twin_phases(self) -> tuple[Phase, ...]:
        """The §4.2 mission's phases (the twin-lift's and the V's are the same)."""
        return tuple(phases(self.twin))


@dataclass(frozen=True)
class Report:
    """Everything docs/reproduction.md is rendered from."""

    setup: SetUp
    single: SingleLiftNumbers
    baumgarte: BaumgarteNumbers
    swing: SwingNumbers
    twin: FormationRunNumbers
    multi: FormationRunNumbers
    twin_modal: ModalNumbers
    multi_modal: ModalNumbers
    gust_effect: tuple[float, ...]     # the V's payload moved by each gust [m]
    files: dict[str, str]              # seed figure number -> PNG name
    comparison: tuple[str, ...]        # compare.comparison_numbers lines
    wall: dict[str, float]             # wall time per case and 'total' [s]
    jobs: int


# =============================================================================================
# Measurements on the formation runs (seed §4.2-4.5)
# =============================================================================================
def phase_name(segment: MissionSegment) -> str:
    """'climb', 'hover' or '+x cruise' ... of a mission segment (world axes)."""
    v = np.asarray(segment.velocity, dtype=float)
    if not v.any():
        return 'hover'
    if v[2] > 0 and not v[:2].any():
        return 'climb'
    k = int(np.argmax(np.abs(v)))
    return f'{"+" if v[k] > 0 else "-"}{"xyz"[k]} cruise'


def phases(scenario: Scenario) -> list[Phase]:
    """The mission's segments as phases (name, start, end [s])."""
    out, start = [], 0.0
    for segment in scenario.mission.segments:
        out.append(Phase(phase_name(segment), start, segment.end_time))
        start = segment.end_time
    return out


def delivered_thrust(run: Any, scenario: Scenario, i: int) -> np.ndarray:
    """k_T sum(omega^2) of UAV i's commands [N] (on its rotor_cmd stamps)."""
    return scenario.uavs[i - 1].vehicle.collective_thrust(run.rotor_speeds(i))


def swing_by_phase(t: np.ndarray, swing: np.ndarray, mission: Sequence[Phase]
                   ) -> tuple[PhaseSwing, ...]:
    """The largest payload swing [m] (metrics.swing_series: t [s], swing [m]) in each phase."""
    return tuple(PhaseSwing(p, _peak_between(t, swing, p.start, p.end)) for p in mission)


def _peak_between(t: np.ndarray, values: np.ndarray, t0: float, t1: float) -> float:
    """The largest finite value of `values` at t0 <= t <= t1 [s] (1 ns tolerance)."""
    return peak_rms(values[(t >= t0 - 1e-9) & (t <= t1 + 1e-9)])[0]


def gust_encounters(run: Any, scenario: Scenario) -> tuple[GustEncounter, ...]:
    """How the payload met each gust of the scenario (GustEncounter)."""
    p, t = run.payload_position(), run.payload_time
    out = []
    for gust in scenario.gusts:
        distance = np.linalg.norm(p[:, :2] - np.asarray(gust.center), axis=1)
        k = int(np.argmin(distance))
        speeds = np.array([gust.speed(q) for q in p])
        inside = np.nonzero(speeds > 0.0)[0]
        out.append(GustEncounter(float(distance[k]), float(t[k]), float(speeds.max()),
                                 gust.gradient_distance,
                                 float(t[inside[0]]) if inside.size else None,
                                 float(t[inside[-1]]) if inside.size else None))
    return tuple(out)


def pair_distances(run: Any, scenario: Scenario) -> tuple[PairDistance, ...]:
    """Mean UAV-UAV distance after LATE [s] against the commanded one (nominal positions)."""
    from multilift_sim.formation_geometry import nominal_positions
    f = scenario.formation
    nominal = nominal_positions(f.geometry, scenario.n_uavs, (0.0, 0.0, 0.0), f.offsets,
                                f.distance, f.half_angle)
    r = run.uav_positions()
    late = run.t >= LATE
    out = []
    for i in range(scenario.n_uavs):
        for j in range(i + 1, scenario.n_uavs):
            d = np.linalg.norm(r[i, late] - r[j, late], axis=1)
            out.append(PairDistance((i + 1, j + 1), float(d.mean()),
                                    float(np.linalg.norm(nominal[i] - nominal[j]))))
    return tuple(out)


def hover_tilt(run: Any, scenario: Scenario) -> tuple[Tilt, ...]:
    """Measured tilt and the tilt the static balance needs [deg] per UAV at the run's last
    sample: the thrust must carry m_i g and the cable's pull T_i (r_p - r_i)/|r_p - r_i|."""
    r = run.uav_positions()[:, -1]
    euler = run.uav_euler()[:, -1]
    p = interp_rows(run.t[-1:], run.payload_time, run.payload_position())[0]
    tension = run.tensions()[-1]
    g = scenario.simulation.gravity
    out = []
    for i in range(scenario.n_uavs):
        pull = tension[i] * (p - r[i]) / np.linalg.norm(p - r[i])
        force = scenario.uavs[i].vehicle.mass * g * np.array([0.0, 0.0, 1.0]) - pull
        needed = math.degrees(math.acos(force[2] / np.linalg.norm(force)))
        measured = math.degrees(math.acos(math.cos(euler[i, 0]) * math.cos(euler[i, 1])))
        out.append(Tilt(measured, needed))
    return tuple(out)


def follower_errors(run: Any, climb: Phase) -> tuple[FollowerError, ...]:
    """Virtual-constraint errors of every follower (FollowerError)."""
    out = []
    for i in run.followers:
        t, e = run.formation_error_time(i), run.formation_errors(i)
        norms, z = np.linalg.norm(e, axis=1), np.abs(e[:, 2])
        late = t >= LATE
        during, after = (t >= climb.start) & (t < climb.end), t >= climb.end
        steady = (t >= STEADY[0]) & (t <= STEADY[1])
        out.append(FollowerError(i, float(norms[late].mean()), float(norms.mean()),
                                 tuple(float(v) for v in e[late].mean(axis=0)),
                                 float(z[during].max()), float(z[after].max()),
                                 float(z[steady].mean())))
    return tuple(out)


def measure_run(run: Any, scenario: Scenario) -> FormationRunNumbers:
    """The numbers of one formation run that the report quotes."""
    g = np.abs(run.g())
    tail = run.formation_time >= run.formation_time[-1] - HOVER_TAIL
    t_swing, swing = swing_series(run, scenario)
    swing_max, swing_rms = peak_rms(swing)
    mission = phases(scenario)
    climb = mission[0]
    t_rot = run.rotor_time(1)
    omega = run.rotor_speeds(1)
    cruise = (t_rot >= CRUISE[0]) & (t_rot <= CRUISE[1])
    dt = float(np.median(np.diff(t_rot)))
    thrusts = [delivered_thrust(run, scenario, i) for i in range(1, run.n_uavs + 1)]
    in_steady = (t_rot >= STEADY[0]) & (t_rot <= STEADY[1])
    switch_ranges = [float(np.ptp(th[(t_rot >= p.end) & (t_rot <= p.end + AFTER_SWITCH)]))
                     for th in thrusts for p in mission[:-1]]
    excess = None
    if run.n_uavs >= 2:
        def over(end: float) -> float:
            w = t_rot < end  # the corner at the climb's end belongs to the next phase
            return float(thrusts[0][w].mean() / thrusts[1][w].mean() - 1) * 100
        w = t_rot < climb.end
        excess = ClimbExcess(over(CLIMB_START), over(climb.end),
                             float(np.max(thrusts[0][w] / thrusts[1][w] - 1) * 100))
    ref = interp_rows(run.t, run.reference_time, run.reference_position())
    err = np.linalg.norm(run.uav_positions()[0] - ref, axis=1)
    return FormationRunNumbers(
        name=scenario.name, duration=float(run.t[-1]), phases=tuple(mission),
        max_g=float(g.max()), max_g_hover=float(g[tail].max()), final_g=float(g[-1].max()),
        min_tension=float(run.tensions().min()),
        swing_max=swing_max, swing_rms=swing_rms,
        swing_phases=swing_by_phase(t_swing, swing, mission),
        swing_steady=_peak_between(t_swing, swing, *STEADY),
        gusts=gust_encounters(run, scenario), distances=pair_distances(run, scenario),
        tilt=hover_tilt(run, scenario), followers=follower_errors(run, climb),
        leader_omega_cruise=float(omega[cruise].mean()), leader_omega_all=float(omega.mean()),
        leader_omega_cruise_max=float(omega[cruise].max()),
        saturated=tuple(float(run.saturated(i).any(axis=1).sum() * dt)
                        for i in range(1, run.n_uavs + 1)),
        thrust_mean_after_climb=tuple(float(th[t_rot > climb.end].mean()) for th in thrusts),
        thrust_range_switch=max(switch_ranges),
        thrust_range_steady=max(float(np.ptp(th[in_steady])) for th in thrusts),
        climb_excess=excess, tracking_max=float(err.max()),
        tracking_rms=float(np.sqrt(np.mean(err ** 2))))


def gust_effect(run: Any, still: dict, encounters: Sequence[GustEncounter]
                ) -> tuple[float, ...]:
    """Per gust: how far the gust moves the payload [m]. delta(t) = payload of this run minus
    the same run in still air; the largest |delta(t) - delta(t_in)| from entering the gust to
    AFTER_GUST s after leaving it (0 for a gust never met)."""
    p = interp_rows(still['t'], run.payload_time, run.payload_position())
    delta = p - still['payload']
    out = []
    for e in encounters:
        if e.t_in is None:
            out.append(0.0)
            continue
        window = (still['t'] >= e.t_in) & (still['t'] <= e.t_out + AFTER_GUST)
        start = delta[int(np.argmax(still['t'] >= e.t_in))]
        out.append(float(np.linalg.norm(delta[window] - start, axis=1).max()))
    return tuple(out)


def measure_swing(run: Any, scenario: Scenario) -> SwingNumbers:
    """Fig. 4.1 numbers of the single-lift bag (SwingNumbers)."""
    r = run.uav_positions()[0]
    p = run.payload_position()
    return SwingNumbers(float(np.linalg.norm(r[:, :2] - r[0, :2], axis=1).max()),
                        float(np.linalg.norm(p[:, :2] - p[0, :2], axis=1).max()),
                        release_amplitude(scenario),
                        scenario.payload.mass / scenario.uavs[0].vehicle.mass,
                        float(np.abs(run.g()).max()), float(run.t[-1]))


# =============================================================================================
# Figures
# =============================================================================================
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


# =============================================================================================
# The report
# =============================================================================================
def measure(results: dict[str, dict], work: Path, runs: dict[str, Any],
            scenarios: dict[str, Scenario]) -> dict[str, Any]:
    """The typed measurements of the cases' results (the Report's fields but the figures,
    the comparison lines and the wall times)."""
    twin = measure_run(runs[TWIN], scenarios[TWIN])
    multi = measure_run(runs[MULTI], scenarios[MULTI])
    study = json.loads((work / 'baumgarte' / 'baumgarte.json').read_text())
    return {'setup': SetUp(scenarios[SWING], scenarios[TWIN], scenarios[MULTI]),
            'single': SingleLiftNumbers.from_rows(results['single_lift_table']['rows']),
            'baumgarte': BaumgarteNumbers.from_study(study),
            'swing': measure_swing(runs[SWING], scenarios[SWING]), 'twin': twin, 'multi': multi,
            'twin_modal': ModalNumbers.from_case(results['modal'][TWIN]),
            'multi_modal': ModalNumbers.from_case(results['modal'][MULTI]),
            'gust_effect': gust_effect(runs[MULTI], results['multi_lift_still_air'],
                                       multi.gusts)}


def write_reproduction(out: Path, results: dict[str, dict], work: Path, jobs: int,
                       started: float) -> Path:
    """Figures and reproduction.md in `out` from the cases' results; returns the report."""
    from multilift_tools.bagdata import load_run
    from multilift_tools.compare import comparison_numbers
    from multilift_tools.report_template import render_report

    scenarios = {name: load(name) for name in (SWING, TWIN, MULTI)}
    runs = {name: load_run(results[name]['bag']) for name in (SWING, TWIN, MULTI)}
    numbers = measure(results, work, runs, scenarios)
    files = make_figures(runs, scenarios, out / 'figures', work / 'baumgarte',
                         numbers['twin'].climb_excess.start, numbers['multi'].gusts)
    wall = {case: results[case]['wall_time'] for case in CASES}
    wall['total'] = time.monotonic() - started
    report = Report(**numbers, files=files, comparison=tuple(comparison_numbers(
        [runs[TWIN], runs[MULTI]], ['A: TL', 'B: ML'], [scenarios[TWIN], scenarios[MULTI]])),
        wall=wall, jobs=jobs)
    path = out / 'reproduction.md'
    path.write_text(render_report(report))
    return path
