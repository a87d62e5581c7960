"""The run figures' public face: classes that are views over the accumulator arrays
(`layout`), adding through the compiled functions of `accumulators` (or, under
MULTILIFT_KERNEL=python, their uncompiled run: `kernels.runnable`), and the payload swing on
plain inputs (`swing`). Importing this module does not import numba; the first use does.
"""
from __future__ import annotations

import functools
import importlib
import math
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from multilift_sim import kernels
from multilift_sim.statistics.layout import (
    FORMATION_MAX_ABS, FORMATION_NORM_SUM, FORMATION_SAMPLES, FORMATION_SIZE, PEAK_MAX,
    PEAK_SAMPLES, PEAK_SIZE, PEAK_SUM_SQ, RUN_COMPRESSED_TIME, RUN_MAX_ABS_G, RUN_MAX_ABS_G_DOT,
    RUN_LEAST_THRUST_MARGIN, RUN_LONGEST_CABLE, RUN_MAX_GUST_SPEED, RUN_MAX_ROTOR_SPEED,
    RUN_MAX_SAG, RUN_MAX_STRETCH, RUN_SHORTEST_CABLE, RUN_ATTITUDE_ERROR_SQ, RUN_ATTITUDE_NEES,
    RUN_ESTIMATION_SAMPLES, RUN_PAYLOAD_NEES, RUN_PAYLOAD_POSITION_SQ, RUN_PAYLOAD_VELOCITY_SQ,
    RUN_POSITION_ERROR_SQ, RUN_POSITION_NEES,
    RUN_MAX_TENSION, RUN_MIN_TENSION, RUN_PEAK_TENSION, RUN_SATURATED_TIME, RUN_SCALARS,
    RUN_SIMULATED_TIME, RUN_SLACK_TIME, RUN_SWING, RUN_UAV_COLUMNS, SWING_FROM, TRACKING_ERROR,
    TRACKING_SIZE, run_size)


def compiled(module: str, name: str) -> Callable:
    """Function `name` of `multilift_sim.statistics.<module>` as MULTILIFT_KERNEL says:
    compiled, or its uncompiled run (`kernels.runnable`); loaded once per mode."""
    return _compiled(module, name, kernels.mode())


@functools.cache
def _compiled(module: str, name: str, mode: str) -> Callable:
    del mode  # part of the cache key only
    function = getattr(importlib.import_module(f'multilift_sim.statistics.{module}'), name)
    return kernels.runnable(function)


# -- the payload swing on plain inputs --------------------------------------------------------
def _points(uav_positions: ArrayLike, cable_lengths: ArrayLike) -> tuple[np.ndarray,
                                                                       np.ndarray]:
    return (np.ascontiguousarray(uav_positions, dtype=np.float64).reshape(-1, 3),
            np.ascontiguousarray(cable_lengths, dtype=np.float64).reshape(-1))


def equilibrium_payload_position(uav_positions: ArrayLike, cable_lengths: ArrayLike
                                 ) -> np.ndarray | None:
    """Where the payload would hang at rest under UAVs held at `uav_positions` (n, 3) [m] on
    cables of `cable_lengths` (n,) [m]: the lowest point within reach of every cable (the
    minimum of the potential m_p g z over |r_p - r_i| <= l_i), world [m]. None when the cables
    cannot all reach one point. The search: `swing.equilibrium_point`."""
    uavs, lengths = _points(uav_positions, cable_lengths)
    x, y, z = compiled('swing', 'equilibrium_point')(uavs, lengths)
    return None if math.isnan(z) else np.array((x, y, z))


def payload_swing_at(uav_positions: ArrayLike, payload_position: ArrayLike,
                     cable_lengths: ArrayLike) -> float:
    """`payload_swing` at one instant: uav_positions (n, 3), payload_position (3,) [m]."""
    uavs, lengths = _points(uav_positions, cable_lengths)
    payload = np.ascontiguousarray(payload_position, dtype=np.float64).reshape(3)
    return float(compiled('swing', 'swing_at')(uavs, payload, lengths))


def payload_swing(uav_positions: ArrayLike, payload_position: ArrayLike,
                  cable_lengths: ArrayLike) -> np.ndarray:
    """Payload swing [m]: the horizontal distance of the payload from its static-equilibrium
    place under the UAVs (`equilibrium_payload_position`) at the same instant.

    uav_positions (..., n, 3), payload_position (..., 3), world [m]; cable_lengths (n,) [m].
    Returns shape (...) (NaN where the cables cannot meet).
    """
    uavs = np.asarray(uav_positions, dtype=np.float64)
    payload = np.asarray(payload_position, dtype=np.float64)
    lead = payload.shape[:-1]
    uavs = np.ascontiguousarray(uavs.reshape(-1, *uavs.shape[-2:]))
    flat = np.ascontiguousarray(payload.reshape(-1, 3))
    lengths = np.ascontiguousarray(cable_lengths, dtype=np.float64)
    swing_at = compiled('swing', 'swing_at')
    out = np.empty(len(flat))
    for k in range(len(flat)):
        out[k] = swing_at(uavs[k], flat[k], lengths)
    return out.reshape(lead)


# -- the accumulators -------------------------------------------------------------------------
class PeakRms:
    """Max and root mean square of a non-negative signal sampled once per tick: a view of the
    peak/rms block at `block` of `acc` (its own array by default)."""

    def __init__(self, acc: np.ndarray | None = None, block: int = 0):
        self.acc = np.zeros(PEAK_SIZE) if acc is None else acc
        self.block = block

    def add(self, value: float) -> None:
        compiled('accumulators', 'peak_rms_add')(self.acc, self.block, float(value))

    @property
    def max(self) -> float:
        return float(self.acc[self.block + PEAK_MAX])

    @property
    def sum_sq(self) -> float:
        return float(self.acc[self.block + PEAK_SUM_SQ])

    @property
    def samples(self) -> int:
        return int(self.acc[self.block + PEAK_SAMPLES])

    @property
    def rms(self) -> float:
        samples = self.samples
        return math.sqrt(self.sum_sq / samples) if samples else 0.0


class TrackingStatistics:
    """The leader's tracking error |r_ref - r_1| [m]; `acc`: TRACKING_SIZE floats (layout)."""

    def __init__(self) -> None:
        self.acc = np.zeros(TRACKING_SIZE)
        self.error = PeakRms(self.acc, TRACKING_ERROR)
        self._add = compiled('accumulators', 'tracking_add')

    def add(self, reference_position: ArrayLike, position: ArrayLike) -> None:
        self._add(self.acc, np.asarray(reference_position, dtype=np.float64),
                  np.asarray(position, dtype=np.float64))

    def as_dict(self) -> dict:
        return {'max_tracking_error': self.error.max, 'rms_tracking_error': self.error.rms,
                'answered_states': self.error.samples}


class FormationErrorStatistics:
    """A follower's virtual-constraint residual g_vc [m] (its rows, seed Eq. 3.7-3.8);
    `acc`: FORMATION_SIZE floats (layout)."""

    def __init__(self) -> None:
        self.acc = np.zeros(FORMATION_SIZE)
        self._add = compiled('accumulators', 'formation_error_add')

    def add(self, residual: ArrayLike) -> None:
        self._add(self.acc, np.asarray(residual, dtype=np.float64).ravel())

    @property
    def max_abs(self) -> float:
        return float(self.acc[FORMATION_MAX_ABS])

    @property
    def norm_sum(self) -> float:
        return float(self.acc[FORMATION_NORM_SUM])

    @property
    def samples(self) -> int:
        return int(self.acc[FORMATION_SAMPLES])

    def as_dict(self) -> dict:
        return {'max_abs_formation_error': self.max_abs,
                'mean_formation_error_norm': self.norm_sum / max(self.samples, 1),
                'answered_states': self.samples}


def _rows(values, dtype: type) -> np.ndarray:
    """A value or a sequence per UAV as one C-contiguous (n, k) array, rows padded with zeros
    (False) where their lengths differ."""
    try:
        rows = np.asarray(values, dtype=dtype)
    except ValueError:                                  # ragged
        rows = None
    if rows is not None and rows.ndim in (1, 2):
        return np.ascontiguousarray(rows.reshape(len(rows), -1))
    rows = [np.asarray(row, dtype=dtype).ravel() for row in values]
    out = np.zeros((len(rows), max(len(row) for row in rows)), dtype=dtype)
    for out_row, row in zip(out, rows):
        out_row[:len(row)] = row
    return out


class RunStatistics:
    """The simulator's figures of a run, accumulated tick by tick: a view of `run`
    (`layout.run_size(n)` floats, RUN_*), which the compiled functions update in place."""

    def __init__(self, n_uavs: int, run: np.ndarray | None = None):
        """Empty figures of n UAVs, or a view of `run` (run_size(n_uavs),), another's."""
        self.n_uavs = n_uavs
        if run is None:
            run = np.zeros(run_size(n_uavs))
            run[RUN_MIN_TENSION] = math.inf
            run[RUN_MAX_TENSION] = -math.inf
            run[RUN_SCALARS + RUN_LEAST_THRUST_MARGIN:run_size(n_uavs):RUN_UAV_COLUMNS] = math.inf
            for column in (RUN_MAX_STRETCH, RUN_PEAK_TENSION, RUN_LONGEST_CABLE, RUN_MAX_SAG):
                run[RUN_SCALARS + column:run_size(n_uavs):RUN_UAV_COLUMNS] = -math.inf
            run[RUN_SCALARS + RUN_SHORTEST_CABLE:run_size(n_uavs):RUN_UAV_COLUMNS] = math.inf
        self.run = run
        self.swing = PeakRms(self.run, RUN_SWING)      # payload swing [m]
        self._functions = {name: compiled('accumulators', name) for name in (
            'run_add_commands', 'run_add_tensions', 'run_add_slack', 'run_add_gust_speed',
            'run_check')}

    def _per_uav(self, column: int) -> list[float]:
        start = RUN_SCALARS + column
        return self.run[start:start + RUN_UAV_COLUMNS * self.n_uavs:RUN_UAV_COLUMNS].tolist()

    @property
    def max_abs_constraint(self) -> float:
        """max_i,t |g_i| [m^2]."""
        return float(self.run[RUN_MAX_ABS_G])

    @property
    def max_abs_constraint_rate(self) -> float:
        """max_i,t |g_i_dot| [m^2/s]."""
        return float(self.run[RUN_MAX_ABS_G_DOT])

    @property
    def max_rotor_speed(self) -> list[float]:
        """Per UAV [rad/s]."""
        return self._per_uav(RUN_MAX_ROTOR_SPEED)

    @property
    def saturated_time(self) -> list[float]:
        """Per UAV, time with a rotor held at a speed limit the allocator wanted it beyond
        [s] (not a failed rotor, nor one the reallocation pins at its minimum)."""
        return self._per_uav(RUN_SATURATED_TIME)

    @property
    def least_thrust_margin(self) -> list[float | None]:
        """Per UAV, the least share of its largest thrust its commands left, 1 - u_T / u_T,max
        (rotor effectiveness included; None before a command)."""
        return [v if math.isfinite(v) else None for v in self._per_uav(RUN_LEAST_THRUST_MARGIN)]

    @property
    def chain_figures(self) -> dict:
        """Heavy cables' (cable_model: chain) per cable: {'max_sag': [m]} (an inner node's
        largest distance from the chord UAV -> payload), at every control tick; {} in any
        other run."""
        sag = self._per_uav(RUN_MAX_SAG)
        return {'max_sag': sag} if any(math.isfinite(v) for v in sag) else {}

    @property
    def rope_figures(self) -> dict:
        """Elastic ropes' (cable_model: elastic) per cable: {'max_stretch': [m] (L_i - l_i),
        'peak_tension': [N]}, sampled at every control tick; {} in any other run."""
        stretch, peak = self._per_uav(RUN_MAX_STRETCH), self._per_uav(RUN_PEAK_TENSION)
        if not any(math.isfinite(v) for v in stretch):
            return {}
        return {'max_stretch': stretch, 'peak_tension': peak}

    @property
    def reel_figures(self) -> dict:
        """Winches' (`uavs[i].winch`) per cable: {'shortest_cable', 'longest_cable'}: the
        least and largest length [m] its reel gave it at the control ticks (a UAV without a
        winch: its length); {} in a run without winches."""
        shortest, longest = self._per_uav(RUN_SHORTEST_CABLE), self._per_uav(RUN_LONGEST_CABLE)
        if not any(math.isfinite(v) for v in shortest):
            return {}
        return {'shortest_cable': shortest, 'longest_cable': longest}

    @property
    def min_tension(self) -> float:
        """[N] (inf before the first tension)."""
        return float(self.run[RUN_MIN_TENSION])

    @property
    def max_tension(self) -> float:
        """[N] (-inf before the first tension)."""
        return float(self.run[RUN_MAX_TENSION])

    @property
    def simulated_time(self) -> float:
        """The time of the last state checked [s]."""
        return float(self.run[RUN_SIMULATED_TIME])

    @property
    def compressed_time(self) -> float:
        """Time with a cable pushing (a rigid cable's T_i < 0) [s]."""
        return float(self.run[RUN_COMPRESSED_TIME])

    @property
    def max_gust_speed(self) -> float:
        """Peak gust speed met by the payload [m/s]."""
        return float(self.run[RUN_MAX_GUST_SPEED])

    @property
    def slack_time(self) -> list[float]:
        """Per cable, time slack [s]."""
        return self._per_uav(RUN_SLACK_TIME)

    def add_slack(self, taut: ArrayLike, period: float) -> None:
        """A control period [s] ending with these cables taut (cable_model: slack)."""
        self._functions['run_add_slack'](self.run, np.asarray(taut, dtype=np.bool_), period)

    def add_commands(self, rotor_speeds, saturated, period: float) -> None:
        """One control period [s] of commands: each UAV's rotor speeds [rad/s] ((n, n_r), or
        a sequence per UAV; or its peak speed, (n,)) and its saturation flags (the same)."""
        self._functions['run_add_commands'](self.run, _rows(rotor_speeds, np.float64),
                                            _rows(saturated, np.bool_), period)

    def add_tensions(self, tension: ArrayLike) -> None:
        """One tick's cable tensions [N]."""
        self._functions['run_add_tensions'](self.run, np.asarray(tension, dtype=np.float64))

    def add_gust_speed(self, speed: float) -> None:
        """The gust speed the payload meets at one tick [m/s]."""
        self._functions['run_add_gust_speed'](self.run, speed)

    def check(self, state: np.ndarray, g: np.ndarray, g_dot: np.ndarray, taut: np.ndarray,
              constraint_tolerance: float, rate_tolerance: float, t: float, tick: int,
              swing_every: int, reach: np.ndarray) -> tuple[int, int]:
        """Seed Algorithm 1's check of one state, its figures accumulated:
        `accumulators.run_check` (its arguments and (status, cable))."""
        return self._functions['run_check'](self.run, state, g, g_dot, taut,
                                            constraint_tolerance, rate_tolerance, t, tick,
                                            swing_every, reach)

    def as_dict(self) -> dict:
        return {'n_uavs': self.n_uavs,
                'max_abs_constraint': self.max_abs_constraint,
                'max_abs_constraint_rate': self.max_abs_constraint_rate,
                'max_rotor_speed': self.max_rotor_speed,
                'saturated_time': self.saturated_time,
                'least_thrust_margin': self.least_thrust_margin,
                'min_tension': self.min_tension,
                'max_tension': self.max_tension,
                'simulated_time': self.simulated_time,
                'max_gust_speed': self.max_gust_speed,
                'slack_time': self.slack_time,
                'max_payload_swing': self.swing.max,
                'rms_payload_swing': self.swing.rms,
                'swing_from': SWING_FROM,
                'compressed_time': self.compressed_time, **self.rope_figures, **self.chain_figures,
                **self.reel_figures, **self.estimation_figures}

    @property
    def estimation_figures(self) -> dict:
        """With an estimator (issue 33 item 6): {'estimation': {'position_rms': [m] and
        'attitude_rms': [rad] per UAV, 'position_nees', 'attitude_nees': their mean NEES
        (3 dof: 3 when consistent), and with a payload estimator 'payload_position_rms' [m],
        'payload_velocity_rms' [m/s], 'payload_nees'}}, over every tick flown; {} without."""
        samples = float(self.run[RUN_ESTIMATION_SAMPLES])
        if samples == 0.0:
            return {}
        figures = {'position_rms': [math.sqrt(v / samples)
                                    for v in self._per_uav(RUN_POSITION_ERROR_SQ)],
                   'attitude_rms': [math.sqrt(v / samples)
                                    for v in self._per_uav(RUN_ATTITUDE_ERROR_SQ)],
                   'position_nees': [v / samples for v in self._per_uav(RUN_POSITION_NEES)],
                   'attitude_nees': [v / samples for v in self._per_uav(RUN_ATTITUDE_NEES)]}
        if self.run[RUN_PAYLOAD_NEES] != 0.0:
            figures.update(
                payload_position_rms=math.sqrt(self.run[RUN_PAYLOAD_POSITION_SQ] / samples),
                payload_velocity_rms=math.sqrt(self.run[RUN_PAYLOAD_VELOCITY_SQ] / samples),
                payload_nees=float(self.run[RUN_PAYLOAD_NEES]) / samples)
        return {'estimation': figures}
