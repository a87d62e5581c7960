"""Parts a scenario brings along (`parts:`, issue 31): Python files that register parts of any
kind (a vehicle frame, an event kind, ...) in their kind's registry when imported. A scenario
names them, so every process that reads the scenario (the simulator and controller nodes, the
headless loop, a sweep's workers) imports them before it validates the rest: a part defined in
one file flies headless and through ROS with no other file changed (docs/extending.md).

An entry is a path to a `.py` file, relative to the scenario file's folder (or absolute). A
file is imported once per process: a file already imported under another name (a test module
pytest collected) is not imported again, so its registrations happen once.
"""
from __future__ import annotations

import hashlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType


class PartsError(ValueError):
    """A `parts:` entry that is no file or fails to import (the message says why; the caller
    names the entry)."""


def resolve_part(entry: str, base: Path) -> Path:
    """The file of a `parts:` entry, relative to `base` (the scenario's folder)."""
    path = Path(entry).expanduser()
    if not path.is_absolute():
        path = base / path
    path = path.resolve()
    if path.suffix != '.py' or not path.is_file():
        raise PartsError(f'is no Python file (looked for {path})')
    return path


def _loaded(path: Path) -> ModuleType | None:
    for module in list(sys.modules.values()):
        file = getattr(module, '__file__', None)
        if file and Path(file).resolve() == path:
            return module
    return None


def import_part(path: Path) -> ModuleType:
    """Import the part file `path` (absolute) once in this process; returns its module."""
    module = _loaded(path)
    if module is not None:
        return module
    digest = hashlib.sha256(str(path).encode()).hexdigest()[:12]
    name = f'multilift_parts_{path.stem}_{digest}'
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        del sys.modules[name]
        raise PartsError(f'failed to import ({path}): {type(exc).__name__}: {exc}') from exc
    return module


def import_parts(paths: tuple[str, ...]) -> None:
    """Import each part file of a scenario (its `Scenario.parts`, absolute paths) once."""
    for path in paths:
        import_part(Path(path))
