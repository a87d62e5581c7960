"""Dryden turbulence (multilift_sim.wind.turbulence): the series against the specification's form
(MIL-F-8785C): variances sigma^2, the autocorrelations sigma^2 e^(-V tau / L) (u) and
sigma^2 e^(-V tau / L) (1 - V tau / (2 L)) (v, w), the one-sided spectra in bands; seeded; the
u axis along the mean wind."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import welch

from multilift_sim.wind.turbulence import dryden_series, dryden_spectrum

DT = 0.01                       # [s], a 100 Hz control loop
SIGMA = (1.0, 0.8, 0.5)         # [m/s]
LENGTH = (20.0, 10.0, 5.0)       # [m]
AIRSPEED = 10.0                 # [m/s]


@pytest.fixture(scope='module')
def series():
    return dryden_series(300_000, DT, SIGMA, LENGTH, AIRSPEED, (0.0, 0.0, 0.0), seed=11)


def test_variances_and_autocorrelations_are_the_specification_s(series):
    for k, (sigma, length) in enumerate(zip(SIGMA, LENGTH)):
        values = series[:, k]
        assert values.std() == pytest.approx(sigma, rel=0.05)
        for tau in (0.5, 1.0, 2.0, 4.0):
            lag = int(round(tau / DT))
            measured = np.mean(values[:-lag] * values[lag:])
            decay = math.exp(-AIRSPEED * tau / length)
            expected = sigma ** 2 * decay * (1.0 if k == 0 else
                                             1.0 - AIRSPEED * tau / (2.0 * length))
            assert measured == pytest.approx(expected, abs=0.06 * sigma ** 2)


def test_spectra_follow_the_dryden_forms(series):
    """Welch's estimate against Phi(omega) averaged over octave bands from 0.05 Hz to a fifth
    of the Nyquist frequency (the sampled spectrum is the continuous one there)."""
    for k, (sigma, length) in enumerate(zip(SIGMA, LENGTH)):
        f, psd = welch(series[:, k], fs=1.0 / DT, nperseg=2 ** 13)
        omega = 2.0 * math.pi * f
        measured = psd / (2.0 * math.pi)  # per Hz -> per rad/s
        expected = dryden_spectrum(omega, sigma, length, AIRSPEED, lateral=k > 0)
        edges = 0.05 * 2.0 ** np.arange(0, 7)
        for low, high in zip(edges[:-1], edges[1:]):
            band = (f >= low) & (f < high)
            assert measured[band].mean() == pytest.approx(expected[band].mean(), rel=0.15), \
                (k, low)


def test_the_series_is_seeded_and_turns_with_the_mean_wind():
    a = dryden_series(500, DT, SIGMA, LENGTH, AIRSPEED, (3.0, 0.0, 0.0), seed=3)
    assert np.array_equal(a, dryden_series(500, DT, SIGMA, LENGTH, AIRSPEED, (3.0, 0.0, 0.0),
                                           seed=3))
    assert not np.array_equal(a, dryden_series(500, DT, SIGMA, LENGTH, AIRSPEED,
                                               (3.0, 0.0, 0.0), seed=4))
    turned = dryden_series(500, DT, SIGMA, LENGTH, AIRSPEED, (0.0, 2.0, 0.0), seed=3)
    # the same draws, u now along +y and v along -x
    assert np.allclose(turned[:, 1], a[:, 0]) and np.allclose(turned[:, 0], -a[:, 1])
    assert np.array_equal(turned[:, 2], a[:, 2])
    calm = dryden_series(10, DT, (0.0, 0.0, 0.0), LENGTH, AIRSPEED, (0.0, 0.0, 0.0), seed=3)
    assert not calm.any()
