"""The single-lift numbers of seed §2.8.1 and §4.1 (`single_lift_table`), which
tests/unit/test_reproduction.py regenerates and compares with the committed report: the release,
the linearised open loop (multilift_sim.analysis.modal), the periods of the simulated swing, of the
reduced model and of the amplitude law, the Baumgarte study and the static tension; and their
markdown (`render_table`). World frame, z up, SI units.
"""
from __future__ import annotations

import dataclasses
import math
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from multilift_sim.scenario import Scenario, load
from multilift_tools.report.seed import SEED_EIGENVALUE, SEED_PERIOD, SEED_RELEASE, SWING

# -- how the single-lift table is computed ---------------------------------------------------
SMALL_RELEASE_DEG = 1.0        # alpha = beta [deg] of the small-amplitude swing
BAUMGARTE_DURATION = 20.0      # [s] the Baumgarte study's span (the scenario's 20 s swing)
BAUMGARTE_GAINS = (0.0, 20.0, 100.0)
REST_DURATION = 1.0            # [s] of the hanging-at-rest run for the static tension


def _swing_scenario(alpha_deg: float | None = None, beta_deg: float | None = None,
                    duration: float | None = None) -> Scenario:
    """single_lift_swing, optionally released at other angles [deg] or run for `duration` [s]."""
    scenario = load(SWING)
    payload, simulation = scenario.payload, scenario.simulation
    if alpha_deg is not None:
        payload = dataclasses.replace(payload, alpha=math.radians(alpha_deg),
                                      beta=math.radians(beta_deg or 0.0))
    if duration is not None:
        simulation = dataclasses.replace(simulation, duration=duration)
    return dataclasses.replace(scenario, payload=payload, simulation=simulation)


@dataclass(frozen=True)
class SwingHistory:
    """A headless single-lift run at every control tick: t (T,) [s], UAV and payload positions
    (T, 3) [m] (world), cable tension (T,) [N]."""

    t: np.ndarray
    uav: np.ndarray
    payload: np.ndarray
    tension: np.ndarray


def swing_history(scenario: Scenario) -> SwingHistory:
    """Fly a single-lift scenario with run_headless (Algorithm 1, the DAE) and keep its path."""
    from multilift_control.headless import run_headless

    rows: list[tuple[float, np.ndarray, np.ndarray, float]] = []
    held: list[np.ndarray] = []  # the commands held since the tick before (the last tick's)

    def tick(sim: Any, snap: Any, answers: list) -> None:
        if answers:
            held[:] = [a.output.rotor_speeds for a in answers]
        tension = sim.cable_state(held)[0]
        rows.append((sim.t, snap.uavs[0].position, snap.payload_position, float(tension[0])))

    run_headless(scenario, tick)
    return SwingHistory(np.array([r[0] for r in rows]), np.array([r[1] for r in rows]),
                        np.array([r[2] for r in rows]), np.array([r[3] for r in rows]))


def swing_signal(uav: np.ndarray, payload: np.ndarray) -> np.ndarray:
    """The payload's horizontal offset from the UAV [m] along its initial horizontal direction
    (a swing released at rest stays in that vertical plane)."""
    offset = payload[:, :2] - uav[:, :2]
    direction = offset[0] / np.linalg.norm(offset[0])
    return offset @ direction


def upward_crossings(t: np.ndarray, signal: np.ndarray) -> np.ndarray:
    """Times [s] where `signal` crosses zero upwards, linearly interpolated between samples."""
    k = np.nonzero((signal[:-1] < 0.0) & (signal[1:] >= 0.0))[0]
    return t[k] - signal[k] * (t[k + 1] - t[k]) / (signal[k + 1] - signal[k])


def swing_period(t: np.ndarray, uav: np.ndarray, payload: np.ndarray) -> float:
    """Mean period [s] of the swing over its complete cycles (successive upward crossings)."""
    crossings = upward_crossings(t, swing_signal(uav, payload))
    if len(crossings) < 2:
        raise ValueError('the run holds less than one full swing: no period')
    return float(np.mean(np.diff(crossings)))


def release_amplitude(scenario: Scenario) -> float:
    """Angle [rad] of the released cable from the vertical: cos = cos(alpha) cos(beta)."""
    return math.acos(math.cos(scenario.payload.alpha) * math.cos(scenario.payload.beta))


def amplitude_period_factor(amplitude: float) -> float:
    """T(amplitude) / T(0) of a plane pendulum: 2 K(sin^2(amplitude / 2)) / pi (K the complete
    elliptic integral of the first kind, parameter m = k^2)."""
    from scipy.special import ellipk
    return 2.0 * float(ellipk(math.sin(amplitude / 2.0) ** 2)) / math.pi


def table_row(key: str, quantity: str, seed: str, ours: str, command: str,
              value: Any = None) -> dict:
    """One row of a numbers table: what, the seed's value, ours, the command that gives it,
    and the raw value(s) for tests."""
    return {'key': key, 'quantity': quantity, 'seed': seed, 'ours': ours, 'command': command,
            'value': value}


def vector_text(v: Sequence[float], digits: int = 2) -> str:
    """'{a, b, c}' with `digits` decimals, as the seed writes vectors."""
    return '{' + ', '.join(f'{c + 0.0:.{digits}f}' for c in v) + '}'  # + 0.0: no '-0.00'


def single_lift_table(study_dir: str | Path | None = None) -> list[dict]:
    """The single-lift numbers of seed §2.8.1 and §4.1, computed (about 8 s on one core).

    Rows (dicts with key, quantity, seed, ours, command, value; `render_row` makes the markdown):
    the release r_p(0); size of A, eigenvalues and period of the linearised open loop
    (multilift_sim.analysis.modal); the periods of the simulated swing (run_headless, the
    formation DAE of Algorithm 1) released at 1/1 deg and at the seed's 15/25 deg, of the
    nonlinear reduced model (Eq. 2.34) at 15/25 deg and of the plane-pendulum amplitude law; the
    Baumgarte study (max |g| for alpha_f = 0, 20, 100; alpha_f = 100 against the reduced model)
    over BAUMGARTE_DURATION; the scenario's own run against the reduced model; the static tension
    against m_p g. `study_dir`: where the Baumgarte study writes its table and figures (Fig.
    4.2, 4.3); default a temporary directory, removed.
    """
    from multilift_sim.analysis.modal import scenario_modal_analysis
    from multilift_sim.formation_params import StateLayout
    from multilift_sim.frames import world_to_seed_vector
    from multilift_sim.start import initial_state
    from multilift_tools.studies import baumgarte_study, reduced_swing

    rows = []
    scenario = _swing_scenario()
    x0 = initial_state(scenario)
    layout = StateLayout(1)
    release_world = layout.payload_position(x0) - layout.uav_positions(x0)[0]
    release = world_to_seed_vector(release_world)
    rows.append(table_row(
        'release', 'payload at release r_p(0) - r(0), α = 15°, β = 25°, seed frame (z down) [m]',
        vector_text(SEED_RELEASE),
        f'{vector_text(release)} (world, z up: {vector_text(release_world)})',
        f'scripts/multilift run {SWING} --headless --bag B (first /payload/odom)',
        [float(c) for c in release]))

    analysis = scenario_modal_analysis(scenario)
    omegas = sorted(float(analysis.eigenvalues[k].imag) for k in analysis.pendulum_modes)
    size = analysis.state_matrix.shape[0]
    rows.append(table_row(
        'state_matrix', 'linearised single-lift: size of A (independent coordinates)',
        '16 × 16 (8)', f'{size} × {size} ({analysis.basis.shape[1]} of 9; '
        f'{analysis.rigid_count} rigid-body zeros)', f'scripts/multilift modal {SWING}', size))
    rows.append(table_row(
        'eigenvalues', 'pendulum eigenvalues λ_1 = λ_2 [1/s]',
        f'±{SEED_EIGENVALUE:.2f}j, ±{SEED_EIGENVALUE:.2f}j',
        ', '.join(f'±{w:.4f}j' for w in omegas), f'scripts/multilift modal {SWING}', omegas))
    linear = 2.0 * math.pi / omegas[0]
    rows.append(table_row('linear_period', 'pendulum period 2π/ω of the linearised model [s]',
                          f'{SEED_PERIOD:.2f}', f'{linear:.4f}', f'scripts/multilift modal {SWING}',
                          linear))

    small = _swing_scenario(SMALL_RELEASE_DEG, SMALL_RELEASE_DEG)
    history = swing_history(small)
    period_small = swing_period(history.t, history.uav, history.payload)
    rows.append(table_row(
        'period_small', f'simulated period, released at α = β = {SMALL_RELEASE_DEG:g}° '
        '(formation DAE, Algorithm 1) [s]', '-',
        f'{period_small:.4f} ({(period_small / linear - 1) * 100:+.3f} % vs linear)',
        f'reproduce.single_lift_table (run_headless, {SWING}, α = β = 1°)', period_small))

    history = swing_history(scenario)
    period_large = swing_period(history.t, history.uav, history.payload)
    rows.append(table_row(
        'period_large', 'simulated period, released at α = 15°, β = 25° (formation DAE) [s]',
        f'{SEED_PERIOD:.2f}',
        f'{period_large:.4f} ({(period_large / linear - 1) * 100:+.2f} % vs linear)',
        f'scripts/multilift run {SWING} --headless --bag B; reproduce.swing_period',
        period_large))
    uav_ref, payload_ref = reduced_swing(scenario, history.t)
    period_reduced = swing_period(history.t, uav_ref, payload_ref)
    rows.append(table_row(
        'period_reduced', 'period of the nonlinear reduced model (Eq. 2.34) at 15°/25° [s]', '-',
        f'{period_reduced:.4f}', 'reproduce.single_lift_table (ReducedSingleLiftModel)',
        period_reduced))
    amplitude = release_amplitude(scenario)
    factor = amplitude_period_factor(amplitude)
    rows.append(table_row(
        'period_law', f'plane-pendulum amplitude law: linear period × 2K(sin²(θ_0/2))/π, '
        f'θ_0 = {math.degrees(amplitude):.1f}° [s]', '-',
        f'{linear * factor:.4f} (factor {factor:.4f})', 'reproduce.amplitude_period_factor',
        linear * factor))
    error = float(np.max(np.linalg.norm(history.payload - payload_ref, axis=1)))
    rows.append(table_row(
        'scenario_error', f'{SWING} as run (α_f = 20, RK4 1 ms) vs reduced model: max payload '
        f'position error over {history.t[-1]:.0f} s [m]', '-', f'{error:.0e}',
        f'scripts/multilift run {SWING} --headless --bag B', error))

    temporary = study_dir is None
    out = Path(tempfile.mkdtemp(prefix='multilift-baumgarte-')) if temporary else Path(study_dir)
    try:
        study = baumgarte_study(out, duration=BAUMGARTE_DURATION, gains=BAUMGARTE_GAINS)
    finally:
        if temporary:
            shutil.rmtree(out, ignore_errors=True)
    by_label = {r['integrator']: r for r in study['rows']}
    step = f'RK4 {study["dt"] * 1e3:g} ms, {BAUMGARTE_DURATION:g} s'
    seeds = {0.0: 'grows rapidly, "inaccurate"', 20.0: '< 1e-1', 100.0: '< 1e-1'}
    for gain in BAUMGARTE_GAINS:
        r = by_label[f'Baumgarte alpha_f = {gain:g}']
        rows.append(table_row(
            f'baumgarte_{gain:g}', f'Fig. 4.2: max \\|g\\| with α_f = {gain:g} ({step}) [m²]',
            seeds[gain], f'{r["max_abs_g"]:.1e} (final {r["final_abs_g"]:.1e})',
            f'scripts/multilift study baumgarte --duration {BAUMGARTE_DURATION:g}',
            r['max_abs_g']))
    r = by_label[f'Baumgarte alpha_f = {BAUMGARTE_GAINS[-1]:g}']
    rows.append(table_row(
        'dae_error', f'Fig. 4.3: α_f = 100 vs reduced model, max UAV / payload error ({step}) '
        '[m]', '"approximately equal", growing', f'{r["max_uav_error"]:.1e} / '
        f'{r["max_payload_error"]:.1e}',
        f'scripts/multilift study baumgarte --duration {BAUMGARTE_DURATION:g}',
        [r['max_uav_error'], r['max_payload_error']]))

    rest = swing_history(_swing_scenario(0.0, 0.0, REST_DURATION))
    weight = scenario.payload.mass * scenario.simulation.gravity
    tension = float(np.mean(rest.tension))
    rows.append(table_row(
        'static_tension', f'cable tension hanging at rest ({REST_DURATION:g} s) vs m_p g [N]',
        '- (Eq. 2.73)', f'{tension:.4f} vs {weight:.4f} (' + (
            'equal to 1e-9' if abs(tension / weight - 1) < 1e-9 else
            f'{(tension / weight - 1) * 100:+.2g} %') + ')',
        f'reproduce.single_lift_table (run_headless, {SWING}, α = β = 0)', [tension, weight]))
    return rows


def render_row(row: dict) -> str:
    """The markdown table line of a numbers-table row (deterministic: the test compares it)."""
    cells = [row['quantity'], row['seed'], row['ours'], f'`{row["command"]}`']
    return '| ' + ' | '.join(cells) + ' |'


TABLE_HEAD = ('| quantity | seed | ours | command |', '| --- | --- | --- | --- |')


def render_table(rows: Sequence[dict]) -> list[str]:
    """Header and one line per row (render_row)."""
    return [*TABLE_HEAD, *(render_row(r) for r in rows)]
