"""Dryden turbulence (MIL-F-8785C; MIL-HDBK-1797 §B.4.8.2), the continuous von Karman
approximation of the military specifications, as a seeded series of wind velocities at the
control rate (issue 21 item 3): the wind model `wind.turbulence` (multilift_sim.wind's registry). No ROS,
no numba: the series is drawn once per run, before it flies, and the physics holds each sample
over its control period (docs/wind.md).

With airspeed V (the speed at which the frozen turbulence field passes the formation), length
scales L and intensities sigma, the one-sided spectra of the three components, over the
temporal frequency omega [rad/s], are

    Phi_u(omega) = sigma_u^2 2 L_u / (pi V) / (1 + (L_u omega / V)^2)
    Phi_v(omega) = sigma_v^2 L_v / (pi V) (1 + 3 (L_v omega / V)^2) / (1 + (L_v omega / V)^2)^2

and Phi_w as Phi_v with L_w, sigma_w (`dryden_spectrum`). Each integrates to sigma^2. The
components are the outputs of the specification's forming filters driven by white noise,
H_u(s) ~ 1 / (1 + T s) and H_v(s) ~ (1 + sqrt(3) T s) / (1 + T s)^2 with T = L / V, sampled
exactly (`dryden_series`): the states' transition e^(A dt) and the covariance the noise adds
over a sample, Van Loan's matrix exponential, so the series' autocorrelation is the
continuous process's at the samples and its variance sigma^2 whatever the rate (the
recursion run as linear filters, scipy.signal.lfilter).

Axes: u along the mean wind's horizontal direction (world x when there is none), v horizontal
to its left, w up (z up, world frame).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np


def dryden_spectrum(omega: np.ndarray, sigma: float, length: float, airspeed: float,
                    lateral: bool) -> np.ndarray:
    """One-sided PSD [(m/s)^2 / (rad/s)] of a Dryden component at omega [rad/s]: the
    longitudinal form (u), or the lateral/vertical one (v, w) when `lateral`."""
    x = (length * np.asarray(omega, dtype=float) / airspeed) ** 2
    if lateral:
        return sigma ** 2 * length / (math.pi * airspeed) * (1.0 + 3.0 * x) / (1.0 + x) ** 2
    return sigma ** 2 * 2.0 * length / (math.pi * airspeed) / (1.0 + x)


def _forming_filter(time_constant: float, lateral: bool) -> tuple[np.ndarray, np.ndarray,
                                                                   np.ndarray]:
    """(A, B, C) of the forming filter with time constant T [s] (unit gain at s = 0)."""
    t = time_constant
    if lateral:  # (1 + sqrt(3) T s) / (1 + T s)^2, controllable canonical form
        return (np.array([[0.0, 1.0], [-1.0 / t ** 2, -2.0 / t]]), np.array([[0.0], [1.0]]),
                np.array([[1.0 / t ** 2, math.sqrt(3.0) / t]]))
    return np.array([[-1.0 / t]]), np.array([[1.0]]), np.array([[1.0 / t]])


def _component(rng: np.random.Generator, samples: int, dt: float, sigma: float,
               length: float, airspeed: float, lateral: bool) -> np.ndarray:
    """`samples` values of one component, dt [s] apart, from the stationary process."""
    if sigma == 0.0:
        return np.zeros(samples)
    # scipy on demand: a run without turbulence (every kernel load) imports none of it
    from scipy.linalg import expm, solve_continuous_lyapunov
    from scipy.signal import lfilter
    a, b, c = _forming_filter(length / airspeed, lateral)
    k = a.shape[0]
    stationary = solve_continuous_lyapunov(a, -b @ b.T)  # A P + P A^T + B B^T = 0
    gain = sigma / math.sqrt((c @ stationary @ c.T).item())
    # Van Loan: expm([[-A, B B^T], [0, A^T]] dt) = [[., F^-1 Q], [0, F^T]]
    block = np.zeros((2 * k, 2 * k))
    block[:k, :k], block[:k, k:], block[k:, k:] = -a, b @ b.T, a.T
    exp = expm(block * dt)
    transition = exp[k:, k:].T
    added = transition @ exp[:k, k:]
    added = 0.5 * (added + added.T)
    lower = np.linalg.cholesky(added + 1e-300 * np.eye(k))
    # the recursion x_{n+1} = F x_n + L e_n (e white, unit) from the stationary x_0, as linear
    # filters: started from rest one sample earlier with the input L^-1 x_0, so its state
    # there is x_0; y = g c x through c (zI - F)^-1 L, whose denominator is det(zI - F)
    start = np.linalg.cholesky(stationary) @ rng.standard_normal(k)
    inputs = np.vstack([np.linalg.solve(lower, start), rng.standard_normal((samples, k))])
    if k == 1:
        denominator = np.array([1.0, -transition[0, 0]])
        adjugate = np.zeros((1, 1))
    else:  # adj(zI - F) = z I + [[-F11, F01], [F10, -F00]]
        denominator = np.array([1.0, -np.trace(transition), np.linalg.det(transition)])
        adjugate = np.array([[-transition[1, 1], transition[0, 1]],
                             [transition[1, 0], -transition[0, 0]]])
    out = np.zeros(samples + 1)
    for j in range(k):
        numerator = [0.0, (c @ lower[:, j]).item(), (c @ adjugate @ lower[:, j]).item()][:k + 1]
        out += lfilter(numerator, denominator, inputs[:, j])
    return gain * out[1:]


def dryden_series(samples: int, dt: float, intensity, length_scale, airspeed: float,
                  mean_wind, seed: int) -> np.ndarray:
    """(samples, 3) turbulence velocities [m/s], world, dt [s] apart: components u, v, w of
    `intensity` (sigma_u, sigma_v, sigma_w) [m/s] and `length_scale` (L_u, L_v, L_w) [m] at
    `airspeed` V [m/s], u along `mean_wind`'s horizontal direction, drawn from
    numpy.random.default_rng(seed) (the same seed, the same series)."""
    rng = np.random.default_rng(seed)
    components = [_component(rng, samples, dt, float(s), float(l), float(airspeed), lateral)
                  for s, l, lateral in zip(intensity, length_scale, (False, True, True))]
    heading = np.asarray(mean_wind, dtype=float)[:2]
    norm = math.hypot(*heading)
    along = heading / norm if norm > 0.0 else np.array([1.0, 0.0])
    left = np.array([-along[1], along[0]])
    out = np.zeros((samples, 3))
    out[:, :2] = np.outer(components[0], along) + np.outer(components[1], left)
    out[:, 2] = components[2]
    return out


# -- the wind model `wind.turbulence` (multilift_sim.wind) -------------------------------------
NAME = 'turbulence'
UNITS = {'intensity': 'm/s', 'length_scale': 'm', 'airspeed': 'm/s', 'seed': ''}


@dataclass(frozen=True)
class TurbulenceConfig:
    """Dryden turbulence on top of the steady wind (`wind.turbulence`): components u (along
    the mean wind), v (to its left), w (up)."""
    intensity: tuple[float, float, float]     # sigma_u, sigma_v, sigma_w [m/s]
    length_scale: tuple[float, float, float]  # L_u, L_v, L_w [m]
    airspeed: float                           # V [m/s]: how fast the field passes
    seed: int                                 # of the series (a run's seed)


def parse(section) -> TurbulenceConfig:
    """`wind.turbulence`'s keys (a `scenario.reading.Section`)."""
    return TurbulenceConfig(
        intensity=section.vector('intensity', check=lambda v: v >= 0, rule='must be >= 0'),
        length_scale=section.vector('length_scale', check=lambda v: v > 0, rule='must be > 0'),
        airspeed=section.positive('airspeed'), seed=section.count('seed', 0))


def series(config: TurbulenceConfig, scenario: Any, samples: int, dt: float) -> np.ndarray:
    """`dryden_series` of the config, u along the scenario's steady wind."""
    return dryden_series(samples, dt, config.intensity, config.length_scale, config.airspeed,
                         scenario.wind, config.seed)


def seed(config: TurbulenceConfig) -> int:
    return config.seed
