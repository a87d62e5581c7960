"""Reading a scenario file with checks: `Section` walks one mapping of the YAML, reads each
key as what it must be (a number in range, a vector, one of some words, a section), remembers
which keys were read and rejects the rest, so a typo is an error rather than a silently ignored
key. Every error is one `ScenarioError` naming the file, the key, the value and the rule."""
from __future__ import annotations

import math
from typing import Any, Callable

from multilift_sim.scenario.config import ScenarioError


class Section:
    def __init__(self, data: Any, path: str, where: str):
        if not isinstance(data, dict):
            raise ScenarioError(f'{where}: {path or "top level"}: expected a mapping, '
                                f'got {type(data).__name__}')
        self.data = data
        self.path = path
        self.where = where
        self.used: set[str] = set()

    def key(self, name: str) -> str:
        return f'{self.path}.{name}' if self.path else name

    def fail(self, name: str, value: Any, rule: str) -> ScenarioError:
        return ScenarioError(f'{self.where}: {self.key(name)}: {value!r} {rule}')

    def has(self, name: str) -> bool:
        return name in self.data

    def raw(self, name: str, default: Any = ...) -> Any:
        self.used.add(name)
        if name not in self.data:
            if default is ...:
                raise ScenarioError(f'{self.where}: {self.key(name)}: missing key')
            return default
        return self.data[name]

    def number(self, name: str, default: Any = ..., check: Callable[[float], bool] | None = None,
               rule: str = '') -> float:
        value = self.raw(name, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(name, value, 'must be a number')
        value = float(value)
        if not math.isfinite(value):
            raise self.fail(name, value, 'must be finite')
        if check is not None and not check(value):
            raise self.fail(name, value, rule)
        return value

    def positive(self, name: str, default: Any = ...) -> float:
        return self.number(name, default, lambda v: v > 0, 'must be > 0')

    def non_negative(self, name: str, default: Any = ...) -> float:
        return self.number(name, default, lambda v: v >= 0, 'must be >= 0')

    def vector(self, name: str, default: Any = ..., length: int = 3,
               check: Callable[[float], bool] | None = None, rule: str = '') -> tuple[float, ...]:
        value = self.raw(name, default)
        if (not isinstance(value, (list, tuple)) or len(value) != length
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)):
            raise self.fail(name, value, f'must be a list of {length} numbers')
        out = tuple(float(v) for v in value)
        if not all(math.isfinite(v) for v in out):
            raise self.fail(name, value, 'must be finite')
        if check is not None and not all(check(v) for v in out):
            raise self.fail(name, value, rule)
        return out

    def count(self, name: str, default: Any = ...) -> int:
        """An integer >= 0 (a seed, a number of ticks)."""
        value = self.raw(name, default)
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise self.fail(name, value, 'must be an integer >= 0')
        return value

    def text(self, name: str, default: Any = ..., choices: tuple[str, ...] | None = None) -> str:
        value = self.raw(name, default)
        if not isinstance(value, str):
            raise self.fail(name, value, 'must be a string')
        if choices is not None and value not in choices:
            raise self.fail(name, value, f'must be one of {", ".join(choices)}')
        return value

    def sequence(self, name: str, default: Any = ...) -> list:
        """A list (a missing or null key gives `default`)."""
        value = self.raw(name, default)
        if value is None and default is not ...:
            value = default
        if not isinstance(value, list):
            raise self.fail(name, value, 'must be a list')
        return value

    def section(self, name: str, default: Any = ...) -> 'Section':
        return Section(self.raw(name, default), self.key(name), self.where)

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise ScenarioError(f'{self.where}: {self.key(unknown[0])}: unknown key '
                                f'(known here: {", ".join(sorted(self.used))})')
