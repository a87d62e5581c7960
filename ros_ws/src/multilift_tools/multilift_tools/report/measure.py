"""The measurements of `multilift reproduce` on the cases' results (seed §4.2-4.5): a formation
run's numbers (`measure_run`), the single-lift swing's (`measure_swing`), how far each gust
moves the V's payload (`gust_effect`), and all of them as the Report's fields (`measure`), over
the windows below. World frame, z up, SI units.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from multilift_sim.scenario import Scenario
from multilift_tools.metrics import interp_rows, peak_rms, swing_series
from multilift_tools.report.numbers import (BaumgarteNumbers, ClimbExcess, FollowerError,
                                            FormationRunNumbers, GustEncounter, ModalNumbers,
                                            PairDistance, Phase, PhaseSwing, SetUp,
                                            SingleLiftNumbers, SwingNumbers, Tilt, phases)
from multilift_tools.report.seed import MULTI, SWING, TWIN
from multilift_tools.report.single_lift import release_amplitude

# -- the report's measurement windows ---------------------------------------------------------
LATE = 60.0                    # [s] "persistent" formation quantities are averaged after this
CRUISE = (60.0, 95.0)          # [s] a steady stretch of the -x cruise (Fig. 4.17)
STEADY = (70.0, 95.0)          # [s] steady cruise: no corner within a pendulum period
AFTER_SWITCH = 5.0             # [s] window after a phase switch (Fig. 4.12)
AFTER_GUST = 10.0              # [s] window after leaving a gust (Fig. 4.15)
HOVER_TAIL = 20.0              # [s] the last seconds of the run: the hover phase
CLIMB_START = 2.0              # [s] the start of the climb, where the thrust excess is largest


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
                                       multi.gusts),
            'swing_feedback': results['swing_feedback'],
            'load_sharing': results['load_sharing']}
