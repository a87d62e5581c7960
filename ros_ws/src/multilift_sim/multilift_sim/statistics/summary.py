"""A run's summary as one flat row: the columns of `sweep` (no numba)."""
from __future__ import annotations

import math


def summary_row(summary: dict) -> dict:
    """One flat row of a run's summary ({'sim': ..., 'leader': ..., 'follower2': ...}, as
    `run`, `run --headless` and the headless runner leave it): the columns of `sweep`.
    Figures a run does not have (no leader tracking, no followers) are None."""
    sim = summary.get('sim', {})
    followers = [v for k, v in summary.items() if k.startswith('follower')]
    leader = summary.get('leader', {})
    tracked = leader.get('answered_states', 0) > 0

    def finite(value: float | None) -> float | None:
        return value if value is not None and math.isfinite(value) else None

    def over_cables(key: str, pick=max) -> float | None:
        """The largest (or least) of a per-cable figure; None where the run has none."""
        values = [v for v in sim.get(key) or [] if finite(v) is not None]
        return pick(values) if values else None

    return {
        'simulated_time': sim.get('simulated_time'),
        'max_abs_g': sim.get('max_abs_constraint'),
        'max_abs_g_dot': sim.get('max_abs_constraint_rate'),
        'max_rotor_speed': max(sim['max_rotor_speed']) if sim.get('max_rotor_speed') else None,
        'saturated_time': sum(sim['saturated_time']) if sim.get('saturated_time') else None,
        'least_thrust_margin': min((m for m in sim.get('least_thrust_margin') or []
                                    if m is not None), default=None),
        'min_tension': finite(sim.get('min_tension')),
        'max_tension': finite(sim.get('max_tension')),
        'payload_swing_max': sim.get('max_payload_swing'),
        'payload_swing_rms': sim.get('rms_payload_swing'),
        'max_gust_speed': sim.get('max_gust_speed'),
        'slack_time': sum(sim['slack_time']) if sim.get('slack_time') else None,
        'compressed_time': sim.get('compressed_time'),
        'tracking_error_max': leader.get('max_tracking_error') if tracked else None,
        'tracking_error_rms': leader.get('rms_tracking_error') if tracked else None,
        'formation_error_max': (max(f['max_abs_formation_error'] for f in followers)
                                if followers else None),
        'formation_error_mean': (sum(f['mean_formation_error_norm'] for f in followers)
                                 / len(followers) if followers else None),
        'least_clearance': sim.get('least_clearance'),
        'max_stretch': over_cables('max_stretch'),           # elastic cables and links
        'peak_tension': over_cables('peak_tension'),
        'max_sag': over_cables('max_sag'),                   # chains
        'shortest_cable': over_cables('shortest_cable', min),  # winches
        'longest_cable': over_cables('longest_cable'),
    }
