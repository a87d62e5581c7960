"""The typed measurements of `multilift reproduce`: frozen dataclasses of numbers with their
units (`FormationRunNumbers` per formation run, `ModalNumbers`, `SingleLiftNumbers`,
`SwingNumbers`, `BaumgarteNumbers`, the scenario facts in `SetUp`; all of them in the `Report`
docs/reproduction.md is rendered from), and the mission's phases. World frame, z up, SI units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from multilift_sim.scenario import MissionSegment, Scenario
from multilift_tools.report.single_lift import BAUMGARTE_DURATION, BAUMGARTE_GAINS


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
        """From one scenario's entry of the modal case (cases)."""
        return cls(tuple(case['periods']), case['rigid'], case['unstable'], case['free'],
                   case['coordinates'], tuple(case['dependent']), tuple(case['tilt_deg']),
                   tuple(case['tensions']))


@dataclass(frozen=True)
class SingleLiftNumbers:
    """The values of single_lift.single_lift_table: release r_p(0) - r(0) [m] (seed frame and
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
    # beyond the seed: `multilift study swing_feedback` (table, rows, figures), issue 20
    swing_feedback: dict
    # beyond the seed: `multilift study load_sharing` (table, rows), issue 35
    load_sharing: dict
    files: dict[str, str]              # seed figure number -> PNG name
    comparison: tuple[str, ...]        # compare.comparison_numbers lines
    wall: dict[str, float]             # wall time per case and 'total' [s]
    jobs: int


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
