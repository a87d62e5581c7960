"""YAML as rosbag2 (yaml-cpp) writes it, for `metadata.yaml` and MCAP channel metadata (no rclpy).

rosbag2 emits its YAML with yaml-cpp's block style, which differs from PyYAML's: a sequence under
a map key is indented by two more columns (`key:\\n  - item`), empty strings are `""`, null is
`~`, and `YAML::Dump` ends without a newline. `dump()` reproduces that layout for the plain data
rosbag2 writes (maps, lists, str, int, bool, None).

QoS profiles: Jazzy stores each offered profile as a map (metadata version 9), policies as the
lower-case strings of `rmw_qos_*_policy_to_str` and durations as `{sec, nsec}`; an infinite
duration (RMW_DURATION_INFINITE) is `sec: 9223372036, nsec: 854775807`.
"""

from __future__ import annotations

import copy
import functools
import json
import re
from dataclasses import dataclass
from typing import Any, Sequence

import yaml

INFINITE_NS = 2**63 - 1  # RMW_DURATION_INFINITE [ns]

# Strings yaml-cpp leaves unquoted (our names, types, hashes, words separated by single spaces).
_PLAIN = re.compile(r'^[A-Za-z0-9_/.]+(?:[ \-][A-Za-z0-9_/.]+)*-?$')


def _scalar(value: Any) -> str:
    if value is None:
        return '~'
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return value if _plain(value) else json.dumps(value, ensure_ascii=False)
    raise TypeError(f'cannot write {type(value).__name__} {value!r} to rosbag2 YAML')


@functools.lru_cache(maxsize=4096)
def _plain(text: str) -> bool:
    """Whether yaml-cpp writes `text` unquoted: it reads back as itself (a bag writes the same
    names, types and hashes many times: each parsed once)."""
    return bool(_PLAIN.match(text)) and yaml.safe_load(text) == text


def _is_block(value: Any) -> bool:
    return isinstance(value, (dict, list)) and len(value) > 0


def _map_lines(data: dict, column: int) -> list[str]:
    pad = ' ' * column
    lines = []
    for key, value in data.items():
        if isinstance(value, dict) and value:
            lines.append(f'{pad}{key}:')
            lines.extend(_map_lines(value, column + 2))
        elif isinstance(value, list) and value:
            lines.append(f'{pad}{key}:')
            lines.extend(_seq_lines(value, column + 2))
        elif isinstance(value, (dict, list)):
            lines.append(f'{pad}{key}: {"{}" if isinstance(value, dict) else "[]"}')
        else:
            lines.append(f'{pad}{key}: {_scalar(value)}')
    return lines


def _seq_lines(items: list, column: int) -> list[str]:
    pad = ' ' * column
    lines = []
    for item in items:
        if _is_block(item):
            inner = (_map_lines(item, column + 2) if isinstance(item, dict)
                     else _seq_lines(item, column + 2))
            lines.append(f'{pad}- {inner[0][column + 2:]}')
            lines.extend(inner[1:])
        elif isinstance(item, (dict, list)):
            lines.append(f'{pad}- {"{}" if isinstance(item, dict) else "[]"}')
        else:
            lines.append(f'{pad}- {_scalar(item)}')
    return lines


def dump(data: Any) -> str:
    """`data` in yaml-cpp's `YAML::Dump` layout, without a final newline."""
    if isinstance(data, dict) and data:
        return '\n'.join(_map_lines(data, 0))
    if isinstance(data, list) and data:
        return '\n'.join(_seq_lines(data, 0))
    if isinstance(data, (dict, list)):
        return '{}' if isinstance(data, dict) else '[]'
    return _scalar(data)


def _duration(ns: int) -> dict[str, int]:
    return {'sec': ns // 1_000_000_000, 'nsec': ns % 1_000_000_000}


@dataclass(frozen=True)
class OfferedQos:
    """One QoS profile a publisher offered, in rosbag2's terms.

    Policies are the strings rosbag2 writes (`keep_last`, `keep_all`, `unknown`,
    `reliable`, `best_effort`, `transient_local`, `volatile`, `automatic`, ...). Fast DDS reports
    `history: unknown, depth: 0` for remote endpoints, which is what `ros2 bag record` then stores.
    """

    history: str = 'unknown'
    depth: int = 0
    reliability: str = 'reliable'
    durability: str = 'transient_local'
    deadline_ns: int = INFINITE_NS  # [ns]
    lifespan_ns: int = INFINITE_NS  # [ns]
    liveliness: str = 'automatic'
    liveliness_lease_duration_ns: int = INFINITE_NS  # [ns]
    avoid_ros_namespace_conventions: bool = False

    def to_dict(self) -> dict[str, Any]:
        """The profile as the map rosbag2 (metadata version 9) writes."""
        return {
            'history': self.history,
            'depth': self.depth,
            'reliability': self.reliability,
            'durability': self.durability,
            'deadline': _duration(self.deadline_ns),
            'lifespan': _duration(self.lifespan_ns),
            'liveliness': self.liveliness,
            'liveliness_lease_duration': _duration(self.liveliness_lease_duration_ns),
            'avoid_ros_namespace_conventions': self.avoid_ros_namespace_conventions,
        }


def qos_yaml(profiles: Sequence[OfferedQos]) -> str:
    """`offered_qos_profiles` string of an MCAP channel, as rosbag2 writes it."""
    return dump([p.to_dict() for p in profiles])


@functools.lru_cache(maxsize=64)
def _parsed(text: str) -> Any:
    """`text` parsed (once: every topic of a bag offers the same profiles); not to be changed."""
    return yaml.safe_load(text)


def parse_qos_yaml(text: str) -> list[dict[str, Any]]:
    """The list of QoS profile maps in an `offered_qos_profiles` string ('' = no profile)."""
    data = copy.deepcopy(_parsed(text)) if text.strip() else []
    if data is None:
        data = []
    if not isinstance(data, list) or not all(isinstance(p, dict) for p in data):
        raise ValueError(f'offered_qos_profiles must be a YAML list of maps, got {text!r}')
    return data
