"""Parts a scenario brings along (`parts:`, issue 31): Python files that register parts of any
kind (a vehicle frame, an event kind, ...) in their kind's registry when imported. A scenario
names them, so every process that reads the scenario (the simulator and controller nodes, the
headless loop, a sweep's workers) imports them before it validates the rest: a part defined in
one file flies headless and through ROS with no other file changed (docs/extending.md).

An entry is a path to a `.py` file, relative to the scenario file's folder (or absolute). A
file is imported once per process, under its stem as pytest names a test module (numba's cache
of a part's compiled function names its module, so every process must import it under one
name), and its `register_parts()`, if it has one, called once: a file that registers at import
registers wherever it is imported; a test file that must leave pytest's process as it was puts
its registrations in `register_parts()`, which only a scenario's `parts:` calls.
"""
from __future__ import annotations

import hashlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType


_registered: set[Path] = set()  # the files whose register_parts() this process called


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
    """Import the part file `path` (absolute) once in this process and call its
    `register_parts()` once; returns its module."""
    module = _loaded(path)
    if module is None:
        module = _import(path)
    if path not in _registered:
        _registered.add(path)
        register = getattr(module, 'register_parts', None)
        if register is not None:
            register()
    return module


def _import(path: Path) -> ModuleType:
    name = _module_name(path)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        del sys.modules[name]
        raise PartsError(f'failed to import ({path}): {type(exc).__name__}: {exc}') from exc
    return module


def _module_name(path: Path) -> str:
    """The file's stem, as pytest names a test module (numba's cache of a compiled function
    is kept by its file and names its module: every process must import a part under one
    name), unless another module has that name; then one from the stem and the path."""
    try:
        taken = path.stem in sys.modules or importlib.util.find_spec(path.stem) is not None
    except (ImportError, ValueError):
        taken = True
    if path.stem.isidentifier() and not taken:
        return path.stem
    digest = hashlib.sha256(str(path).encode()).hexdigest()[:12]
    return f'multilift_parts_{path.stem}_{digest}'


def import_parts(paths: tuple[str, ...]) -> None:
    """Import each part file of a scenario (its `Scenario.parts`, absolute paths) once."""
    for path in paths:
        import_part(Path(path))
