"""Where scenarios are and how they load: a name in `scenarios/` ($MULTILIFT_SCENARIOS, else
the repository's) or a YAML path, read and validated (`parse.scenario_of`)."""
from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import yaml

from multilift_sim.scenario.config import Scenario, ScenarioError
from multilift_sim.scenario.parse import scenario_of


def scenario_dir() -> Path:
    """The `scenarios/` folder: $MULTILIFT_SCENARIOS, else the repository's."""
    env = os.environ.get('MULTILIFT_SCENARIOS')
    if env:
        return Path(env)
    root = os.environ.get('ML_ROOT')
    if root:
        return Path(root) / 'scenarios'
    return Path.cwd() / 'scenarios'


def resolve(name_or_path: str) -> Path:
    """A scenario name (a file in scenarios/) or a YAML path -> the file."""
    candidate = Path(name_or_path)
    if candidate.suffix in ('.yaml', '.yml') or os.sep in name_or_path:
        if not candidate.is_file():
            raise ScenarioError(f'{name_or_path}: no such scenario file')
        return candidate
    path = scenario_dir() / f'{name_or_path}.yaml'
    if not path.is_file():
        known = sorted(p.stem for p in scenario_dir().glob('*.yaml'))
        raise ScenarioError(f'{name_or_path}: unknown scenario (known: {", ".join(known)})')
    return path


class _ScenarioYaml(yaml.SafeLoader):
    """PyYAML's safe loader (YAML 1.1), but a number in exponent form without a dot or a sign in
    its exponent (`1.5e5`, `2e-3` has one, `1e5`) is a float, as YAML 1.2, JSON and a reader
    take it: YAML 1.1 makes `1.5e5` a string, which the validation refused as not a number."""


_ScenarioYaml.add_implicit_resolver(
    'tag:yaml.org,2002:float',
    re.compile(r'^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$'),
    list('-+0123456789.'))


def read_yaml(text: str) -> Any:
    """A scenario file's text as its mapping (`_ScenarioYaml`); raises yaml.YAMLError."""
    return yaml.load(text, Loader=_ScenarioYaml)  # noqa: S506 - a SafeLoader


def load(name_or_path: str) -> Scenario:
    """Load and validate a scenario by name or path. Raises ScenarioError."""
    path = resolve(name_or_path)
    try:
        data = read_yaml(path.read_text())
    except yaml.YAMLError as exc:
        raise ScenarioError(f'{path}: not valid YAML: {exc}'.replace('\n', ' ')) from None
    return scenario_of(data, str(path))


def anchored(data: Any, folder: Path) -> Any:
    """A scenario's mapping with its `parts:` files, its `mission.file` and its UAVs'
    `trajectory` files made absolute against
    `folder` (the file's own), for a copy validated elsewhere (a sweep's runs, `loads`)."""
    if isinstance(data, dict) and isinstance(data.get('parts'), list):
        data = dict(data, parts=[str((folder / p).resolve()) if isinstance(p, str) else p
                                 for p in data['parts']])
    mission = data.get('mission') if isinstance(data, dict) else None
    if isinstance(mission, dict) and isinstance(mission.get('file'), str):  # mission.type file
        data = dict(data, mission=dict(mission, file=str((folder / mission['file']).resolve())))
    uavs = data.get('uavs') if isinstance(data, dict) else None
    if isinstance(uavs, list) and any(isinstance(u, dict) and isinstance(u.get('trajectory'), str)
                                      for u in uavs):  # prescribed motion (issue 34)
        data = dict(data, uavs=[dict(u, trajectory=str((folder / u['trajectory']).resolve()))
                                if isinstance(u, dict) and isinstance(u.get('trajectory'), str)
                                else u for u in uavs])
    return data


def loads(text: str, where: str = '<string>') -> Scenario:
    """Validate a scenario given as YAML text (tests, tools)."""
    return scenario_of(read_yaml(text), where)


def from_mapping(data: Any, where: str = '<mapping>') -> Scenario:
    """Validate a scenario given as the mapping a YAML file loads to (a sweep's edited copy:
    no round trip through text)."""
    return scenario_of(data, where)
