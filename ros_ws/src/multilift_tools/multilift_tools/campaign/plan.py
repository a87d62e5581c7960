"""A checked campaign (`build_campaign`): the scenario's YAML mapping, its grid axes and samples,
and every run laid out with its parameters and seed.

Runs: the cartesian product of the --set values (grid order: the last --set varies fastest),
each repeated for --samples N draws when --sample is given; run i (0-based, the table's input
order) draws its sampled values, in --sample order, from its own generator
`np.random.default_rng(seed_i)`, seed_i = the first 63 bits of
`np.random.SeedSequence(S).spawn(...)[i]` (the row's `seed` column): the same --seed gives the
same campaign on any cluster, in any completion order.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import yaml

from multilift_sim import scenario as scenario_io
from multilift_tools.campaign.spec import (GridAxis, SampleSpec, SweepError, _label, edited,
                                           format_value)


@dataclass(frozen=True)
class RunSpec:
    """One run of a campaign: its index (input order), parameters (key -> value, --set keys
    then --sample keys) and its seed."""
    index: int
    params: dict = field(hash=False)
    seed: int


@dataclass(frozen=True)
class Campaign:
    """A checked campaign: the scenario's YAML mapping, its axes and its runs."""
    source: str
    base: dict = field(hash=False)
    grid: tuple
    samples: tuple
    seed: int
    runs: tuple

    @property
    def keys(self) -> list[str]:
        return [a.key for a in self.grid] + [s.key for s in self.samples]

    def edits(self, run: RunSpec) -> list[tuple[str, tuple, Any]]:
        edited = {a.key: a for a in (*self.grid, *self.samples)}
        return [edited[key].edit(value) for key, value in run.params.items()]

    def metadata(self) -> dict:
        """What the table's Parquet metadata says of the campaign (plot-sweep reads it)."""
        return {'scenario': self.source, 'seed': self.seed,
                'grid': {a.key: [format_value(v) for v in a.values] for a in self.grid},
                'sample': {s.key: s.text() for s in self.samples},
                'runs': len(self.runs)}


def run_seeds(seed: int, count: int) -> list[int]:
    """One 63-bit seed per run, spawned from `seed`: default_rng(seeds[i]) is run i's stream."""
    children = np.random.SeedSequence(seed).spawn(count)
    return [int(c.generate_state(1, np.uint64)[0] >> np.uint64(1)) for c in children]


def build_campaign(source: str, base: dict, grid: list[GridAxis], samples: list[SampleSpec],
                   n_samples: int | None, seed: int) -> Campaign:
    """Check the axes against the scenario loader and lay out every run (SweepError or
    ScenarioError, one line, on the first bad one). Grid points are checked whole; a sampled
    key is checked with representative values (the mean, the range's middle or ends, each
    choice: one must load), the drawn values only when their run starts (a rejected draw is
    that run's `error` row)."""
    keys = [a.key for a in grid] + [s.key for s in samples]
    dup = next((k for k in keys if keys.count(k) > 1), None)
    if dup is not None:
        raise SweepError(f'{dup}: given twice (list every value in one --set or --sample)')
    if samples and n_samples is None:
        raise SweepError('--sample needs --samples N (how many draws)')
    if n_samples is not None and not samples:
        raise SweepError('--samples without --sample: nothing to draw')
    if n_samples is not None and n_samples < 1:
        raise SweepError(f'--samples: {n_samples} must be >= 1')
    if not 0 <= seed < 2 ** 63:
        raise SweepError(f'--seed: {seed} must be in [0, 2^63)')
    points = list(itertools.product(*[a.values for a in grid]))
    for combo in points:
        _check(source, base, [a.edit(v) for a, v in zip(grid, combo)])
    for spec in samples:
        first_error = None
        for value in spec.candidates():
            try:
                _check(source, base, [spec.edit(value)])
                break
            except (SweepError, scenario_io.ScenarioError) as exc:
                first_error = first_error or exc
        else:
            raise type(first_error)(f'--sample {spec.key}={spec.text()}: {first_error}')
    repeats = n_samples or 1
    seeds = run_seeds(seed, len(points) * repeats)
    runs = []
    for g, combo in enumerate(points):
        for j in range(repeats):
            index = g * repeats + j
            params = {a.key: v for a, v in zip(grid, combo)}
            rng = np.random.default_rng(seeds[index])
            params |= {s.key: s.draw(rng) for s in samples}
            runs.append(RunSpec(index, params, seeds[index]))
    return Campaign(source, base, tuple(grid), tuple(samples), seed, tuple(runs))


def _check(source: str, base: dict, edits) -> None:
    data = edited(base, edits)
    scenario_io.loads(yaml.safe_dump(data, sort_keys=False), _label(source, edits))


def load_base(name_or_path: str) -> tuple[str, dict]:
    """The scenario file (by name or path) -> (its path as text, its YAML mapping)."""
    path = scenario_io.resolve(name_or_path)
    try:
        base = scenario_io.read_yaml(path.read_text())
    except yaml.YAMLError as exc:
        raise scenario_io.ScenarioError(f'{path}: not valid YAML: {exc}'
                                        .replace('\n', ' ')) from None
    if not isinstance(base, dict):
        raise scenario_io.ScenarioError(f'{path}: top level: expected a mapping')
    return str(path), scenario_io.anchored(base, path.parent)
