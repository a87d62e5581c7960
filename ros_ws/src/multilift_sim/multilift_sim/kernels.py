"""Loading the numba-compiled functions: the physics (multilift_sim.physics, each function's
uncompiled run the reference: `uncompiled`, `runnable`) and the control laws
(multilift_control._numba_laws, their methods the reference). `compiled_module` loads a module
of compiled functions in one of two forms, under MULTILIFT_KERNEL:

- ahead of time (`build_ahead_of_time`, run by scripts/setup for a module with an
  `AHEAD_OF_TIME` dict; the physics has none yet): numba's pycc compiles the
  module's `AHEAD_OF_TIME` functions into a plain extension module under
  `$XDG_CACHE_HOME/multilift/aot` (`~/.cache/multilift/aot`), its file named by a hash of the
  module's source, Python and numpy, so a changed source is never served stale code. It loads
  in about a millisecond without numba (whose import costs every process about 0.5 s). Its
  functions trust their argument types (a wrong one reads wrong memory), so each call is
  checked first (`_Checked`): a TypeError, never a crash.
- just in time: `numba.njit(cache=True)`, the cache under NUMBA_CACHE_DIR, by default
  `~/.cache/multilift/numba`; the first process compiles (1-2 s), later ones load the cache.

MULTILIFT_KERNEL: `auto` (or unset) ahead of time where built, else just in time where numba
imports, else the pure reference; `aot` ahead of time or the pure reference (controller
nodes' default: multilift_control.runtime.prepare_node_laws); `jit` just in time or the
pure reference; `python` the pure reference.
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.machinery
import importlib.util
import json
import os
import shutil
import sys
import tempfile
import types
from pathlib import Path
from types import ModuleType
from typing import Any, Callable

import numpy as np

_cache_home = os.environ.get('XDG_CACHE_HOME') or str(Path.home() / '.cache')
os.environ.setdefault('NUMBA_CACHE_DIR', str(Path(_cache_home) / 'multilift' / 'numba'))

VARIABLE = 'MULTILIFT_KERNEL'  # auto (or unset), aot, jit or python: see the docstring
PHYSICS = 'multilift_sim.physics.formation_dae'  # the physics' compiled module (the DAE)
MODES = ('auto', 'aot', 'jit', 'python')
AHEAD_OF_TIME_DIR = Path(_cache_home) / 'multilift' / 'aot'
_BUILD_FORMAT = 2  # of the files build_ahead_of_time writes: part of their names
# compiled modules by (name, mode); None: the pure reference
_modules: dict[tuple[str, str], Any] = {}


def mode() -> str:
    """MULTILIFT_KERNEL, checked: one of MODES."""
    value = os.environ.get(VARIABLE) or 'auto'
    if value not in MODES:
        raise ValueError(f'{VARIABLE}={value!r}: expected one of {", ".join(MODES)}')
    return value


def enabled() -> bool:
    """Whether the compiled physics is to be used (built or numba importable, not switched
    off)."""
    return compiled_module(PHYSICS) is not None


def runnable(function: Callable) -> Callable:
    """A compiled function of a module of compiled functions (a numba dispatcher, or a plain
    function where numba does not import), as MULTILIFT_KERNEL says: its module's compiled
    function (`compiled_module`), else its uncompiled run (`uncompiled`)."""
    module = compiled_module(function.__module__)
    return uncompiled(function) if module is None else getattr(module, function.__name__)


def compiled_module(name: str) -> Any:
    """The compiled functions of module `name` (loaded once per mode): ahead of time or just in
    time as MULTILIFT_KERNEL says, or None when the pure-Python reference is to be used."""
    key = (name, mode())
    if key not in _modules:
        compiled = None
        if key[1] in ('auto', 'aot'):
            compiled = load_ahead_of_time(name)
        if compiled is None and key[1] in ('auto', 'jit'):
            try:
                _import_numba_quietly()
                compiled = importlib.import_module(name)
            except ImportError:
                compiled = None
        _modules[key] = compiled
    return _modules[key]


def ahead_of_time_files(name: str) -> tuple[Path, Path]:
    """(extension module, its argument checks) built from module `name` as it is now."""
    source = Path(importlib.util.find_spec(name).origin).read_bytes()
    digest = hashlib.sha256(
        source + f'|{sys.version}|{np.__version__}|{_BUILD_FORMAT}'.encode()).hexdigest()
    stem = f'{name}-{digest[:16]}'
    return (AHEAD_OF_TIME_DIR / f'{stem}{importlib.machinery.EXTENSION_SUFFIXES[0]}',
            AHEAD_OF_TIME_DIR / f'{stem}.json')


def _extension_name(name: str) -> str:
    return 'aot_' + name.replace('.', '_')


class _Checked:
    """A function compiled ahead of time behind a check of its array arguments: numba's
    ahead-of-time wrappers do not check them (a float32 or strided array reads wrong memory,
    or crashes), the just-in-time dispatcher compiles for what it gets.

    An array object that passed is remembered by position and not checked again (a
    controller's constants and memory come back every tick). That trusts an array not to be
    reshaped or retyped in place (`a.shape = ...`, `a.dtype = ...`), which no caller does.
    Each caller gets a checker of its own (`_AheadOfTimeModule`), so what it remembers is that
    caller's arrays."""

    def __init__(self, function: Callable, arrays: list[tuple[int, str, int, bool]]) -> None:
        self.function = function
        self.__name__ = function.__name__
        self.arrays = [(index, np.dtype(dtype), ndim, writes)
                       for index, dtype, ndim, writes in arrays]
        self._passed: dict[int, np.ndarray] = {}

    def __call__(self, *args):
        passed = self._passed
        for index, dtype, ndim, writes in self.arrays:
            value = args[index]
            if value is passed.get(index):
                continue
            if (type(value) is not np.ndarray or value.dtype != dtype or value.ndim != ndim
                    or not value.flags.c_contiguous or (writes and not value.flags.writeable)):
                raise TypeError(f'{self.__name__}: argument {index} must be a C-contiguous'
                                f'{" writable" if writes else ""} {ndim}-d {dtype} array, got '
                                f'{_describe(value)}')
            passed[index] = value
        return self.function(*args)


def _describe(value: object) -> str:
    if isinstance(value, np.ndarray):
        layout = 'C-contiguous' if value.flags.c_contiguous else 'strided'
        access = '' if value.flags.writeable else ' read-only'
        return f'a {layout}{access} {value.ndim}-d {value.dtype} array'
    return type(value).__name__


def load_ahead_of_time(name: str) -> Any:
    """Module `name`'s functions compiled ahead of time for its current source (checked:
    `_Checked`), or None when they were not built."""
    extension_path, checks_path = ahead_of_time_files(name)
    if not (extension_path.is_file() and checks_path.is_file()):
        return None
    extension_name = _extension_name(name)
    loader = importlib.machinery.ExtensionFileLoader(extension_name, str(extension_path))
    spec = importlib.util.spec_from_file_location(extension_name, extension_path,
                                                  loader=loader)
    try:
        extension = importlib.util.module_from_spec(spec)
        loader.exec_module(extension)
        checks = json.loads(checks_path.read_text())
    except (ImportError, OSError, ValueError) as error:  # a damaged build: the fallback runs
        print(f'warning: {extension_path} does not load ({error}); compiling just in time',
              file=sys.stderr)
        return None
    return _AheadOfTimeModule(extension, checks)


class _AheadOfTimeModule:
    """An extension module built ahead of time, seen through its checks: each attribute
    access gives a fresh `_Checked` function (a controller keeps the one it took)."""

    def __init__(self, extension: ModuleType, checks: dict[str, list]) -> None:
        self._extension = extension
        self._checks = checks

    def __getattr__(self, function: str) -> _Checked:
        if function.startswith('_') or function not in self._checks:
            raise AttributeError(function)
        return _Checked(getattr(self._extension, function), self._checks[function])


def build_ahead_of_time(name: str) -> Path:
    """Compile module `name`'s `AHEAD_OF_TIME` functions ({name: numba signature}) into an
    extension module under AHEAD_OF_TIME_DIR (numba's pycc; a C compiler is needed). Returns
    its path; the files appear whole (written aside, then renamed)."""
    from numba.np.numpy_support import as_dtype
    from numba.pycc import CC
    from numba.core import types
    module = importlib.import_module(name)
    extension_path, checks_path = ahead_of_time_files(name)
    AHEAD_OF_TIME_DIR.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix='.build-', dir=AHEAD_OF_TIME_DIR))
    try:
        compiler = CC(_extension_name(name))
        compiler.output_dir = str(work)
        checks = {}
        for function, signature in module.AHEAD_OF_TIME.items():
            compiler.export(function, signature)(getattr(module, function).py_func)
            # (position, dtype, dimensions, whether the compiled code may write it)
            checks[function] = [(index, as_dtype(arg.dtype).str, arg.ndim, arg.mutable)
                                for index, arg in enumerate(signature.args)
                                if isinstance(arg, types.Array)]
        compiler.compile()
        built = next(work.glob(f'{_extension_name(name)}*'))
        (work / 'checks.json').write_text(json.dumps(checks))
        os.replace(work / 'checks.json', checks_path)
        os.replace(built, extension_path)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return extension_path


def uncompiled(function: Callable) -> Callable:
    """The pure-Python run of a compiled function's own source: numba's `py_func`, with every
    compiled function it calls by a global name (of its module or imported by name) replaced by
    that function's uncompiled run too, recursively. The reference the compiled code is tested
    against, with no second copy of an equation. `function` may be a numba dispatcher or a plain
    function (returned as it is when it calls nothing compiled)."""
    return _uncompiled(function, {})


def _uncompiled(function: Callable, done: dict[int, Callable]) -> Callable:
    python = getattr(function, 'py_func', function)
    if id(python) in done:
        return done[id(python)]
    if not isinstance(python, types.FunctionType):
        return function
    names = dict(python.__globals__)
    copy = types.FunctionType(python.__code__, names, python.__name__, python.__defaults__,
                              python.__closure__)
    copy.__kwdefaults__ = python.__kwdefaults__
    copy.__doc__ = python.__doc__
    done[id(python)] = copy
    for name in python.__code__.co_names:
        value = names.get(name)
        if hasattr(value, 'py_func'):
            names[name] = _uncompiled(value, done)
    return copy


def _import_numba_quietly() -> None:
    """Import numba's array implementations without scipy or coverage. Loading even a cached
    kernel imports numba.np.arraymath, whose import imports scipy.linalg only to learn whether
    BLAS is there for np.dot of vectors (0.1-0.4 s of every process's start here; our kernels
    call no BLAS), and numba imports `coverage` (installed for the tests) to extend it to
    compiled lines (70 ms, `python -X importtime`). Hidden from those imports, numba takes its
    plain loop for such products and no coverage hook; both import normally afterwards."""
    hidden = [name for name in ('scipy', 'coverage') if name not in sys.modules]
    for name in hidden:
        sys.modules[name] = None  # an import of it now raises ImportError
    try:
        import numba.np.arraymath  # noqa: F401 - the import is the point
    finally:
        for name in hidden:
            if sys.modules.get(name, False) is None:
                del sys.modules[name]
