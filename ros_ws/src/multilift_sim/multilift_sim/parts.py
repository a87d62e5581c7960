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

Shipped parts of a higher layer (the leader and follower controllers are multilift_control's;
their names are what this package's scenario validation reads) are found through the
`multilift.parts` entry point group (`load`: multilift_control's setup.py names
`multilift_control.controllers`). The static imports still go one way
(tests/unit/test_architecture.py): a lower layer finds parts by name at run time, as pytest
finds its plugins.

Compiled dispatch: numba cannot call a function picked from a Python registry at run time, so
a registry writes a dispatcher's source from its parts (one branch per part) to a file under
numba's cache folder named by a digest of the parts' sources (`generated_module`) and its
callers call that. A caller links the code of what it calls and numba checks a cached
function against its own file only, so while any registry holds parts other than the shipped
ones numba's cache is a folder of those registries (`cache_folder`: `parts-<digest>` inside
the kernels' folder), and every loaded compiled function that reaches a regenerated dispatcher
is compiled anew (`recompile_callers`). The event kinds and the sensor models generate
theirs through `multilift_sim.part_dispatch`, whose registries this folder's choice counts too.
"""
from __future__ import annotations

import hashlib
import importlib.metadata
import importlib.util
import inspect
import os
import sys
from pathlib import Path
from types import ModuleType
from typing import Any, Callable, Protocol

from multilift_sim import kernels  # sets NUMBA_CACHE_DIR, the kernels' folder

ENTRY_POINTS = 'multilift.parts'
BASE_CACHE = kernels.CACHE_DIR
_entries: set[str] = set()


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


def load() -> None:
    """Import the shipped parts of the `multilift.parts` entry points, once per process (the
    scan of the installed packages' metadata costs tens of milliseconds)."""
    if _entries:
        return
    _entries.add(ENTRY_POINTS)
    for entry in importlib.metadata.entry_points(group=ENTRY_POINTS):
        if entry.value not in _entries:
            _entries.add(entry.value)
            entry.load()


class Dispatched(Protocol):
    """A registry with a compiled dispatcher (`part_dispatch.GeneratedDispatcher`,
    multilift_control's `controllers.compiled`)."""

    def shipped(self) -> bool:
        """Whether it holds its shipped parts only, in their order."""

    def digest(self) -> str:
        """A digest of its parts: names, order and sources."""


DISPATCHED: dict[str, Dispatched] = {}  # name -> registry, each added once by its module


def python(function: Callable) -> Callable:
    """A compiled function's Python original (itself when uncompiled)."""
    return getattr(function, 'py_func', function)


def source_digest(named: dict[str, Callable]) -> str:
    """A digest of parts' names, order and their functions' source files."""
    digest = hashlib.sha256()
    for name, function in named.items():
        original = python(function)
        digest.update(f'{name}\0{original.__module__}.{original.__name__}\0'.encode())
        digest.update(Path(inspect.getsourcefile(original)).read_bytes())
    return digest.hexdigest()[:16]


def cache_folder() -> Path:
    """numba's cache folder for the registries as they are: the kernels' with every registry
    as shipped, else a folder of the registries that are not (these `DISPATCHED` and
    `part_dispatch.DISPATCHERS`: one choice for every kind of part)."""
    from multilift_sim import part_dispatch  # (it imports this module)
    changed = [f'{name}:{registry.digest()}' for name, registry in sorted(DISPATCHED.items())
               if not registry.shipped()]
    changed += [f'{d.label}:{d.digest()}' for d in part_dispatch.DISPATCHERS
                if not d.is_shipped()]
    if not changed:
        return BASE_CACHE
    return BASE_CACHE / f'parts-{hashlib.sha256(" ".join(changed).encode()).hexdigest()[:16]}'


def generated_module(folder: str, stem: str, source: str) -> ModuleType:
    """`source` written to `<numba's cache>/<folder>/<stem>.py` (once, whole: another process
    may import it at the same time) and imported (numba's on-disk cache needs a real file)."""
    path = BASE_CACHE / folder / f'{stem}.py'
    if not path.exists() or path.read_text() != source:
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix(f'.{os.getpid()}.tmp')
        partial.write_text(source)
        os.replace(partial, path)
    name = f'multilift_generated_{folder}_{stem}'
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


def point_cache() -> None:
    """numba's cache at `cache_folder()` for the functions compiled from now on."""
    try:
        from numba.core import config
    except ImportError:  # pragma: no cover - the uncompiled run has no cache
        return
    config.CACHE_DIR = str(cache_folder())


def recompile_callers(targets: list[Any]) -> None:
    """After a registry changed: numba's cache at its folder (`point_cache`) and every loaded
    compiled function that reaches one of `targets` (the old dispatchers, by global name or a
    module's attribute) compiled anew at its next call."""
    point_cache()
    try:
        from numba.core.dispatcher import Dispatcher
    except ImportError:  # pragma: no cover - the uncompiled run reads the globals each time
        return
    for function in callers(targets, Dispatcher):
        function.enable_caching()  # at the registries' folder
        function._reset_overloads()


def callers(targets: list[Any], kind: type) -> list[Any]:
    """`targets` and every compiled function (a `kind` of dispatcher) of a loaded multilift
    module that calls one, directly or through others (by a global name, or a module's
    attribute)."""
    functions = []
    for name, module in list(sys.modules.items()):
        if name.startswith('multilift_') and module is not None:
            functions += [value for value in vars(module).values() if isinstance(value, kind)]
    reached = {id(target): target for target in targets}
    grew = True
    while grew:
        grew = False
        for function in functions:
            if id(function) in reached:
                continue
            if any(id(value) in reached for value in _referenced(function)):
                reached[id(function)] = function
                grew = True
    return [value for value in reached.values() if isinstance(value, kind)]


def _referenced(function: Any) -> list[Any]:
    original = python(function)
    names = original.__code__.co_names
    found = []
    for name in names:
        value = original.__globals__.get(name)
        found.append(value)
        if isinstance(value, ModuleType):
            found += [getattr(value, other, None) for other in names]
    return found
