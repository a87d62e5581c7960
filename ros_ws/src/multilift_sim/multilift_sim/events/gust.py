"""`gust`: a 1-cosine gust of the whole formation's air from `time` for `duration` [s], peak
`velocity` [m/s] (world, not zero), on every body with a drag (docs/wind.md). No UAV: the row's
uav is -1, the message's 0. It changes no physics memory at its tick: it blows through the
run's wind series (`unsteady_wind`, which `schedules.wind_series` sums)."""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.layout import EVENT_DURATION, EVENT_VALUE, EVENT_VELOCITY

NAME = 'gust'
KEYS = ('velocity', 'duration')


def parse(e, uavs, earlier):
    """Its keys as EventConfig fields (uav 0: the whole formation's air)."""
    velocity = e.vector('velocity')
    if not any(velocity):
        raise e.fail('velocity', list(velocity), 'must not be zero')
    return dict(uav=0, velocity=velocity, duration=e.positive('duration'))


def pack(event, row, rate):
    """Its slots: the peak speed [m/s], the duration [s], the peak velocity [m/s], world."""
    row[EVENT_VALUE] = math.sqrt(sum(v * v for v in event.velocity))
    row[EVENT_DURATION] = event.duration
    row[EVENT_VELOCITY:EVENT_VELOCITY + 3] = event.velocity


@jit
def apply(row, tick, effectiveness, taut, released, silent_until, reel):
    """Nothing at its tick (the wind series carries it)."""


def describe(row):
    """(uav 0, rotor 0, the peak speed [m/s], sentence)."""
    value = float(row[EVENT_VALUE])
    velocity = ', '.join(f'{v:g}' for v in row[EVENT_VELOCITY:EVENT_VELOCITY + 3])
    return 0, 0, value, (f'gust of {value:.3g} m/s ({velocity}) for '
                         f'{float(row[EVENT_DURATION]):g} s (1-cosine)')


def unsteady_wind(event, starts: np.ndarray, period: float) -> np.ndarray:
    """Its air velocity [m/s], world, over each control period from `starts` (K,) [s]: the
    peak velocity times the profile's mean over the period (`profile_mean`), (K, 3)."""
    return np.outer(profile_mean(starts, period, event.time, event.duration), event.velocity)


def profile_mean(starts: np.ndarray, period: float, onset: float,
                 duration: float) -> np.ndarray:
    """The mean over each period [s, s + period] (starts (K,) [s]) of a 1-cosine gust's
    profile p(t) = (1 - cos(2 pi (t - onset) / D)) / 2 for onset <= t <= onset + D, 0 outside
    (the time form of seed Eq. 2.55's 1-cosine shape): its integral over the period's overlap
    with the gust, in closed form, divided by the period."""
    a = np.clip(starts, onset, onset + duration)
    b = np.clip(starts + period, onset, onset + duration)
    w = 2.0 * math.pi / duration
    integral = 0.5 * (b - a) - (np.sin(w * (b - onset)) - np.sin(w * (a - onset))) / (2.0 * w)
    return integral / period
