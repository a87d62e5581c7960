"""The input of a sweep campaign: --set (grid axes) and --sample (distributions) parsed, and the
edits they make to a scenario's YAML mapping; `SweepError` for bad input.

KEY is a dotted path into the scenario's YAML (world frame, SI units, as the file), with list
indices in brackets: payload.mass, formation.alpha_vc, uavs[0].cable_length. A `uavs` list the
file does not have is made (formation.n empty entries) so that per-UAV keys can be set.
"""
from __future__ import annotations

import copy
import json
import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
import yaml

DISTRIBUTIONS = ('uniform', 'normal', 'choice')
_STEP = re.compile(r'([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$')
_SAMPLE = re.compile(r'\s*([A-Za-z_]+)\s*\((.*)\)\s*$', re.S)


class SweepError(ValueError):
    """Bad sweep input; the message is the one line printed."""


def parse_key(key: str, option: str = '--set') -> list[str | int]:
    """'uavs[0].cable_length' -> ['uavs', 0, 'cable_length']."""
    path: list[str | int] = []
    for part in key.split('.'):
        match = _STEP.match(part)
        if not match:
            raise SweepError(f'{option} {key}: {part!r} is not a key (letters, digits, _ and '
                             '[index])')
        path.append(match.group(1))
        path += [int(i) for i in re.findall(r'\[(\d+)\]', match.group(2))]
    return path


def split_values(text: str) -> list[str]:
    """Split at commas outside brackets: '1,[1,2,3],x' -> ['1', '[1,2,3]', 'x']."""
    items, depth, current = [], 0, ''
    for ch in text:
        if ch == ',' and depth == 0:
            items.append(current)
            current = ''
            continue
        depth += {'[': 1, ']': -1}.get(ch, 0)
        current += ch
    items.append(current)
    return [item.strip() for item in items]


def parse_value(text: str) -> Any:
    """A number (1e-3 too), true/false, a YAML list, or the string itself."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError:
        return text


@dataclass(frozen=True)
class EditedKey:
    """A scenario key a campaign edits, as given ('uavs[1].mass') and as the path into the
    scenario's YAML data that `apply_edit` follows (('uavs', 1, 'mass'))."""
    key: str
    path: tuple

    def edit(self, value: Any) -> tuple[str, tuple, Any]:
        """The edit (key, path, value) that sets this key to `value` (`apply_edit`)."""
        return self.key, self.path, value


@dataclass(frozen=True)
class GridAxis(EditedKey):
    """One --set: a key and its values."""
    values: tuple


@dataclass(frozen=True)
class SampleSpec(EditedKey):
    """One --sample: a key and its distribution (uniform(a, b), normal(mu, sigma) or
    choice(v1, ...)), in the units of the key."""
    kind: str
    args: tuple

    def draw(self, rng: np.random.Generator) -> Any:
        """One value from `rng` (exactly one draw from the stream per spec)."""
        if self.kind == 'uniform':
            return float(rng.uniform(self.args[0], self.args[1]))
        if self.kind == 'normal':
            return float(rng.normal(self.args[0], self.args[1]))
        return self.args[int(rng.integers(len(self.args)))]

    def candidates(self) -> list[Any]:
        """Values to check the key with before anything runs (one must load)."""
        if self.kind == 'uniform':
            a, b = self.args
            return [(a + b) / 2, a, b]
        if self.kind == 'normal':
            return [self.args[0]]
        return list(self.args)

    def text(self) -> str:
        return f'{self.kind}({", ".join(format_value(a) for a in self.args)})'


def parse_set(option: str) -> GridAxis:
    """'payload.mass=0.4,0.8' -> GridAxis."""
    key, sep, values = option.partition('=')
    key = key.strip()
    if not sep or not key:
        raise SweepError(f'--set {option}: expected KEY=V1,V2,...')
    items = split_values(values)
    if not values.strip() or any(item == '' for item in items):
        raise SweepError(f'--set {option}: an empty value')
    return GridAxis(key, tuple(parse_key(key)), tuple(parse_value(item) for item in items))


def _number(option: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise SweepError(f'--sample {option}: {text.strip()!r} is not a number') from None
    if not math.isfinite(value):
        raise SweepError(f'--sample {option}: {text.strip()} is not finite')
    return value


def parse_sample(option: str) -> SampleSpec:
    """'payload.mass=uniform(0.4, 1.2)' -> SampleSpec (SweepError naming what is wrong)."""
    key, sep, dist = option.partition('=')
    key = key.strip()
    if not sep or not key:
        raise SweepError(f'--sample {option}: expected KEY=uniform(a,b), KEY=normal(mu,sigma) '
                         'or KEY=choice(v1,v2,...)')
    path = tuple(parse_key(key, '--sample'))
    match = _SAMPLE.match(dist)
    if not match or match.group(1) not in DISTRIBUTIONS:
        raise SweepError(f'--sample {option}: {dist.strip()!r} is not uniform(a,b), '
                         'normal(mu,sigma) or choice(v1,v2,...)')
    kind, inner = match.group(1), match.group(2)
    items = split_values(inner)
    if any(item == '' for item in items):
        raise SweepError(f'--sample {option}: an empty argument')
    if kind == 'choice':
        return SampleSpec(key, path, kind, tuple(parse_value(item) for item in items))
    if len(items) != 2:
        raise SweepError(f'--sample {option}: {kind} takes 2 numbers, got {len(items)}')
    a, b = (_number(option, item) for item in items)
    if kind == 'uniform' and not a < b:
        raise SweepError(f'--sample {option}: uniform(a,b) needs a < b')
    if kind == 'normal' and not b > 0:
        raise SweepError(f'--sample {option}: normal(mu,sigma) needs sigma > 0')
    return SampleSpec(key, path, kind, (a, b))


def apply_edit(data: dict, key: str, path, value: Any) -> None:
    """Set `value` at `path` in the YAML data (in place). Missing mappings are made (the
    loader then names an unknown key); a missing `uavs` list becomes formation.n entries."""
    node: Any = data
    for depth, step in enumerate(path[:-1]):
        nxt = path[depth + 1]
        if isinstance(step, int):
            if not isinstance(node, list):
                raise SweepError(f'{key}: {_where(path, depth)} is not a list')
            if step >= len(node):
                raise SweepError(f'{key}: index {step} is out of range ({len(node)} '
                                 f'entries in {_where(path, depth)})')
            if node[step] is None and not isinstance(nxt, int):
                node[step] = {}
            node = node[step]
            continue
        if not isinstance(node, dict):
            raise SweepError(f'{key}: {_where(path, depth)} is not a mapping')
        if step not in node or node[step] is None:
            if step == 'uavs' and depth == 0:
                formation = data.get('formation')
                n = formation.get('n', 1) if isinstance(formation, dict) else 1
                node[step] = [{} for _ in range(n if isinstance(n, int) and n > 0 else 1)]
            elif isinstance(nxt, int):
                raise SweepError(f'{key}: the scenario has no list {_where(path, depth + 1)}')
            else:
                node[step] = {}
        node = node[step]
    last = path[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise SweepError(f'{key}: index {last} is out of range')
        node[last] = value
    else:
        if not isinstance(node, dict):
            raise SweepError(f'{key}: {_where(path, len(path) - 1)} is not a mapping')
        node[last] = value


def _where(path, upto: int) -> str:
    text = ''
    for step in path[:upto]:
        text += f'[{step}]' if isinstance(step, int) else (f'.{step}' if text else step)
    return text or 'the top level'


def format_value(value: Any) -> str:
    """A parameter as the table and messages show it (lists and mappings as JSON)."""
    return json.dumps(value) if isinstance(value, (list, dict)) else str(value)


def edited(base: dict, edits: list[tuple[str, tuple, Any]]) -> dict:
    """A deep copy of `base` with every (key, path, value) applied."""
    data = copy.deepcopy(base)
    for key, path, value in edits:
        apply_edit(data, key, path, value)
    return data


def _label(source: str, edits) -> str:
    if not edits:
        return source
    return f'{source} with ' + ', '.join(f'{k}={format_value(v)}' for k, _, v in edits)
