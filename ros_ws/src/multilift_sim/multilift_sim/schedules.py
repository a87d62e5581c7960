"""What a run schedules or draws before it flies, from its scenario (and its seeds): its events
as rows at their ticks (`event_array`, physics.layout EVENT_*), the unsteady wind of every
control period (`wind_series`: Dryden turbulence and gust events, docs/wind.md), and how a
summary records them (`event_records`, `run_seeds`); its sensors' draws: `sensors.arrays`
(docs/sensors.md). The engine and `FormationSimulator` both build their arrays here, so both
paths fly the same schedule."""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.events import EVENT_KINDS, kind_index, moves_air
from multilift_sim.physics.layout import (EVENT_COLUMNS, EVENT_KIND, EVENT_ROTOR, EVENT_TICK,
                                          EVENT_TIME, EVENT_UAV)
from multilift_sim.scenario import Scenario
from multilift_sim.wind import WIND_MODELS
from multilift_sim.wire.msgvalues import formation_event


def event_array(scenario: Scenario) -> np.ndarray:
    """The scenario's events as rows (k, EVENT_COLUMNS) (physics.layout EVENT_*), in time
    order, each at the first control tick at or after its time."""
    rows = np.zeros((len(scenario.events), EVENT_COLUMNS))
    rate = scenario.simulation.control_rate
    for k, event in enumerate(scenario.events):
        rows[k, EVENT_TICK] = math.ceil(event.time * rate - 1e-9)
        rows[k, EVENT_TIME] = event.time
        rows[k, EVENT_KIND] = kind_index(event.type)
        rows[k, EVENT_UAV] = event.uav - 1
        rows[k, EVENT_ROTOR] = max(event.rotor - 1, 0)
        EVENT_KINDS[event.type].pack(event, rows[k], rate)  # its own slots
    return rows


def wind_series(scenario: Scenario) -> np.ndarray:
    """The unsteady wind [m/s], world, of every control period of the run, (ticks + 1, 3), or
    (0, 3) where the wind is steady: tick k's is held over the period from it, added to the
    steady wind. Each wind model's samples at the ticks (`multilift_sim.wind`: the Dryden
    turbulence of `wind.turbulence`, a part's) plus what each event that blows air gives over
    the period (its kind's `unsteady_wind`: a gust's 1-cosine profile averaged over the
    period, docs/wind.md)."""
    sim = scenario.simulation
    blowing = [e for e in scenario.events if moves_air(e.type)]
    if not scenario.wind_models and not blowing:
        return np.zeros((0, 3))
    series = np.zeros((sim.tick_count + 1, 3))
    for name, config in scenario.wind_models:
        series += WIND_MODELS[name].series(config, scenario, sim.tick_count + 1,
                                           1.0 / sim.control_rate)
    starts = np.arange(sim.tick_count + 1) / sim.control_rate
    for event in blowing:
        series += EVENT_KINDS[event.type].unsteady_wind(event, starts, 1.0 / sim.control_rate)
    return series


def run_seeds(scenario: Scenario) -> dict[str, int]:
    """The seeds a run's random draws come from, by what they draw (`sensors`, `imu`, `mocap`,
    a wind model's), as its summary records them: none where it draws nothing."""
    seeds = {}
    if scenario.sensors is not None:
        seeds['sensors'] = scenario.sensors.seed
    for config in scenario.sensor_suite:  # `imu:`, `mocap:`: each its own stream
        seeds[config.model] = config.seed
    for name, config in scenario.wind_models:
        if hasattr(WIND_MODELS[name], 'seed'):
            seeds[name] = WIND_MODELS[name].seed(config)
    return seeds


def event_records(rows: np.ndarray) -> list[dict]:
    """Event rows (physics.layout EVENT_*) as a run's summary lists them: each with its
    scheduled time [s], type, uav (from 1), rotor (from 1; 0: none), value and description
    (msgvalues.formation_event, what /formation/events carries)."""
    keys = ('type', 'uav', 'rotor', 'value', 'time', 'description')
    return [dict(zip(keys, formation_event(row))) for row in rows]
