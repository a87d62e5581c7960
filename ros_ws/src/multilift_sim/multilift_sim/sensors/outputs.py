"""The slots every sensor an estimator reads (`imu`, `mocap`, `gnss`: issue 33) keeps first in
its memory (one UAV's, `SENSOR_MODELS`' `memory`): its latest output and when it came, which
the estimators (`multilift_sim.estimators`) read. Such a sensor leaves what the controllers
receive alone (they read the estimate, or the state without an estimator).

A sensor whose samples arrive late (`mocap`, `gnss`, `cable_sensor`) keeps, after its output,
the tick it measured last and a delay line of its truths (`delayed_memory`); `delayed_sample`
decides, at a tick, which row takes the truth and which sample (if any) arrives: the one place
that logic is written; `keep_truth` writes slots of the truth into that row and `deliver` the
arrived sample's slots plus their drawn errors into the output."""
from dataclasses import dataclass, replace

import numpy as np

from multilift_sim.kernels import jit

ARRIVED = 0      # the control tick its latest output arrived at (-1: none yet)
TAKEN = 1        # the control tick that output was sampled at (its latency: ARRIVED - TAKEN)
OUTPUT = 2       # the output itself, its model's slots (the model's OUTPUT_* names them)
# -- EVERY = 0, LATENCY = 1: a delayed sensor's constants row ----------------------------------
EVERY = 0        # control ticks between two samples
LATENCY = 1      # control ticks from a sample to its arrival
DELAYED_CONSTANT_COLUMNS = 2


@dataclass(frozen=True, kw_only=True)
class DelayedSettings:
    """The keys every delayed sensor has (its own settings add theirs)."""
    latency: float                   # [s] from a sample to its arrival
    dropout: float                   # probability a sample is lost, in [0, 1)
    latency_ticks: int = 0           # the latency in control ticks (`with_simulation`)


def delayed_protocol(output_columns: int, presets: dict):
    """(preset_values, with_simulation, constants, memory): the protocol functions
    (`SENSOR_MODELS`) of a delayed sensor whose output has `output_columns` slots, whose
    presets are `presets` (name -> key values) and whose settings are DelayedSettings."""
    def preset_values(d) -> dict:
        """The key values of the section's `preset` (none: {})."""
        return presets.get(d.text('preset', 'none', choices=('none', *presets)), {})

    def with_simulation(settings, simulation, every: int):
        """The settings with the latency in control ticks (the nearest)."""
        return replace(settings,
                       latency_ticks=int(round(settings.latency * simulation.control_rate)))

    def constants(settings, every: int) -> np.ndarray:
        return delayed_constants(settings.latency_ticks, every)

    def memory(settings) -> np.ndarray:
        return delayed_memory(output_columns, settings.latency_ticks)

    return preset_values, with_simulation, constants, memory


def read_dropout(d, preset: dict) -> float:
    """A delayed sensor's `dropout`: the probability a sample is lost, in [0, 1)."""
    return d.number('dropout', preset.get('dropout', 0.0), lambda v: 0 <= v < 1,
                    'must be within [0, 1)')


def delayed_constants(latency_ticks: int, every: int) -> np.ndarray:
    """A delayed sensor's constants row (EVERY, LATENCY)."""
    row = np.zeros(DELAYED_CONSTANT_COLUMNS)
    row[EVERY], row[LATENCY] = every, latency_ticks
    return row


def delayed_memory(output_columns: int, latency_ticks: int) -> np.ndarray:
    """One UAV's memory of a delayed sensor at the run's start: ARRIVED, TAKEN, its output
    (output_columns), the tick measured last, then latency_ticks + 1 delay-line rows of
    output_columns (nothing arrived, nothing measured: -1)."""
    row = np.zeros(OUTPUT + output_columns + 1 + (latency_ticks + 1) * output_columns)
    row[ARRIVED] = row[TAKEN] = row[OUTPUT + output_columns] = -1.0
    return row


@jit
def delayed_sample(constants, delivered, memory, tick, output_columns):
    """At control tick `tick`, for a delayed sensor's memory (`delayed_memory`'s slots):
    (line, source, sample): `line` the delay line's row [memory index] the tick's truth goes
    into, `source` the row of the sample that arrives now and `sample` its index (-1, -1 when
    none arrives: none taken `latency` ticks ago, or lost, `delivered[sample]` 0.0, the first
    sample, tick 0's, arrives at once and always). ARRIVED and TAKEN are set when one arrives.
    A second call at one tick: (-1, -1, -1), nothing to do."""
    last_tick = OUTPUT + output_columns
    if memory[last_tick] == tick:
        return -1, -1, -1
    memory[last_tick] = tick
    every = int(constants[EVERY])
    slots = int(constants[LATENCY]) + 1
    line = last_tick + 1 + (tick % slots) * output_columns
    taken = 0 if tick == 0 else tick - slots + 1
    if taken < 0 or taken % every != 0 or (taken == 0 and tick > 0):  # tick 0's: at once
        return line, -1, -1
    sample = taken // every
    if sample >= delivered.shape[0] or (delivered[sample] == 0.0 and tick > 0):
        return line, -1, -1
    memory[ARRIVED] = tick
    memory[TAKEN] = taken
    return line, last_tick + 1 + (taken % slots) * output_columns, sample


@jit
def keep_truth(memory, line, slot, truth, first, count):
    """truth[first:first + count] into the delay line's row `line` (`delayed_sample`'s
    memory index) at its output slot `slot`."""
    for j in range(count):
        memory[line + slot + j] = truth[first + j]


@jit
def deliver(memory, source, slot, draws, sample, first, count):
    """The arrived sample's output slots slot .. slot + count - 1 (its delay line row
    `source`, `delayed_sample`'s) plus its errors draws[sample, first:first + count] (in the
    output's units) into the output."""
    for j in range(count):
        memory[OUTPUT + slot + j] = memory[source + slot + j] + draws[sample, first + j]
