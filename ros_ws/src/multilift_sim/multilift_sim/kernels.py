"""Loading the numba-compiled functions: the physics (`multilift_sim.physics`), the run
statistics (`multilift_sim.statistics`), the control laws (`multilift_control.laws`) and the
engine's tick (`multilift_control.engine`), each written once as numba functions over arrays;
each function's uncompiled run (`uncompiled`: its own source run by Python) is the reference.

How start-up stays low without numba's pycc (pending deprecation; it was used here until
issue 19): numba's own on-disk cache, `numba.njit(cache=True)`, the supported way.
scripts/setup compiles every kernel once into the cache (NUMBA_CACHE_DIR, by default
`~/.cache/multilift/numba/<digest of the kernels' sources>`), so a process loads them (tenths
of a second) instead of compiling (seconds); a process that runs no compiled code does not load
them, and `run --compose` runs every controller in one process, which loads them once.

MULTILIFT_KERNEL: `auto` (or unset) compiled just in time (from the cache) where numba imports,
else uncompiled; `jit` the same, numba required; `python` uncompiled (the reference).
"""
from __future__ import annotations

import hashlib
import importlib
import os
import shutil
import sys
import time
import types
from pathlib import Path
from typing import Any, Callable

# the subpackages of numba kernels, in any multilift_* package (physics and statistics here,
# the laws and the engine's tick above): numba compiles a kernel together with the kernels it
# calls from other files, but checks a cached kernel against its own file only
KERNEL_FOLDERS = ('physics', 'statistics', 'laws', 'engine', 'events', 'sensors',
                  'estimators', 'payload_estimators', 'obstacles', 'controllers',
                  'controllers/leaders', 'controllers/followers')
CACHE_ROOT = (Path(os.environ.get('XDG_CACHE_HOME') or Path.home() / '.cache')
              / 'multilift' / 'numba')


def _packages() -> dict[str, Path]:
    """The first multilift_* package of each name on sys.path (found, not imported)."""
    packages: dict[str, Path] = {}
    for entry in sys.path:
        for init in Path(entry or '.').glob('multilift_*/__init__.py'):
            packages.setdefault(init.parent.name, init.parent)
    return packages


def kernel_modules() -> list[str]:
    """The names of every module of the kernels' subpackages (KERNEL_FOLDERS of every
    multilift_* package), found, not imported."""
    return [f'{name}.{folder.replace("/", ".")}.{path.stem}'
            for name, package in sorted(_packages().items())
            for folder in KERNEL_FOLDERS for path in sorted((package / folder).glob('*.py'))
            if path.stem != '__init__']


def _sources_digest() -> str:
    """A digest of the kernels' sources: every KERNEL_FOLDERS subpackage of the first
    multilift_* package of each name on sys.path (found, not imported)."""
    packages = _packages()
    digest = hashlib.sha256()
    for name in sorted(packages):
        for folder in KERNEL_FOLDERS:
            for path in sorted((packages[name] / folder).glob('*.py')):
                digest.update(f'{name}/{folder}/{path.name}'.encode() + b'\0' + path.read_bytes())
    return digest.hexdigest()[:16]


# numba's on-disk cache of these sources: a folder named by their digest, so an edited kernel
# never leaves a caller's cached code stale (`prune_cache` removes the other folders)
os.environ.setdefault('NUMBA_CACHE_DIR', str(CACHE_ROOT / _sources_digest()))
CACHE_DIR = Path(os.environ['NUMBA_CACHE_DIR'])  # as this process found it (a test may restore
#                                                 the environment after the import)

PLAIN_COUNTS = 'MULTILIFT_PLAIN_REFCOUNTS'  # 1: plain reference counts (`plain_reference_counts`)
VARIABLE = 'MULTILIFT_KERNEL'  # auto (or unset), jit or python: see the docstring
PHYSICS = 'multilift_sim.physics.formation_dae'  # the physics' compiled module (the DAE)
MODES = ('auto', 'jit', 'python')
# compiled modules by (name, mode); None: the uncompiled reference
_modules: dict[tuple[str, str], Any] = {}


def prune_cache(days: float = 7.0) -> list[Path]:
    """Remove the cache folders of other sources (digest-named folders under CACHE_ROOT) that
    no process has written for `days`; returns them. Folders in use by other checkouts of
    other sources stay."""
    current = CACHE_DIR
    cutoff = time.time() - days * 86400.0
    stale = [path for path in CACHE_ROOT.glob('*')
             if path.is_dir() and path != current and len(path.name) == 16
             and all(c in '0123456789abcdef' for c in path.name)
             and max((p.stat().st_mtime for p in path.rglob('*')),
                     default=path.stat().st_mtime) < cutoff]
    for path in stale:
        shutil.rmtree(path, ignore_errors=True)
    return stale


def jit(function: Callable | None = None, *, inline: bool = False) -> Callable:
    """The decorator of every kernel (physics, statistics, the laws, the engine's tick):
    numba's njit with its on-disk cache and IEEE arithmetic in the source's order (no
    fastmath), or the function itself where numba does not import (then only its uncompiled
    run exists). `@jit(inline=True)`: numba inlines it into its compiled callers (its IR, the
    same arithmetic), which spares a call that passes a batch's tuples of arrays (each array's
    reference counted in and out)."""
    if function is None:
        return lambda f: jit(f, inline=inline)
    try:
        _import_numba_quietly()
        import numba
    except ImportError:  # pragma: no cover - numba is a dependency; the pure run still works
        return function
    return numba.njit(cache=True, fastmath=False, nogil=True,
                      inline='always' if inline else 'never')(function)


def mode() -> str:
    """MULTILIFT_KERNEL, checked: one of MODES."""
    value = os.environ.get(VARIABLE) or 'auto'
    if value not in MODES:
        raise ValueError(f'{VARIABLE}={value!r}: expected one of {", ".join(MODES)}')
    return value


def enabled() -> bool:
    """Whether the compiled physics is to be used (numba importable, not switched off)."""
    return compiled_module(PHYSICS) is not None


def runnable(function: Callable, kernel: str | None = None) -> Callable:
    """A compiled function (a numba dispatcher, or a plain function where numba does not
    import) as `kernel` (one of MODES; default: MULTILIFT_KERNEL now) says: compiled, else its
    uncompiled run (`uncompiled`). Resolve it once and keep it: the environment is read here."""
    module = compiled_module(function.__module__, kernel)
    return uncompiled(function) if module is None else getattr(module, function.__name__)


def compiled_module(name: str, kernel: str | None = None) -> Any:
    """Module `name` of compiled functions (imported once per mode), or None when the
    uncompiled reference is to be used (`kernel` (default MULTILIFT_KERNEL) python, or numba
    missing under auto)."""
    key = (name, mode() if kernel is None else kernel)
    if key not in _modules:
        compiled = None
        if key[1] != 'python':
            try:
                _import_numba_quietly()
                compiled = importlib.import_module(name)
            except ImportError:
                if key[1] == 'jit':
                    raise
        _modules[key] = compiled
    return _modules[key]


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


def _compile_in_turn() -> None:
    """One process at a time compiles a cached kernel: numba's `Dispatcher.compile` (which
    loads a signature from the on-disk cache, or compiles and saves it) runs holding an
    exclusive lock (`fcntl.flock`) on a file beside the kernel's cache index. A kernel
    scripts/setup left to its first use (the engine's, the learning calls') asked for by
    several processes at once (pytest-xdist workers, a run's nodes) is compiled by the first;
    the others wait and load what it saved, instead of each compiling it (numba's cache is
    safe to share, writes replace whole files, but every process would pay the compile). The
    locks follow the call graph (a kernel's compile takes its callees' locks inside its own),
    which has no cycles, so no two processes wait for each other; a lock a process already
    holds (a recursive call's other signature) is not taken again; the system releases the
    locks of a process that dies."""
    import fcntl

    from numba.core import dispatcher
    from numba.core.compiler_lock import global_compiler_lock
    if getattr(dispatcher.Dispatcher.compile, 'in_turn', False):
        return
    compile_signature = dispatcher.Dispatcher.compile
    held: set[str] = set()

    def compile_in_turn(self, sig):
        index = getattr(getattr(self._cache, '_cache_file', None), '_index_path', None)
        if index is None:  # not cached (NullCache)
            return compile_signature(self, sig)
        with global_compiler_lock:  # numba's own lock first: this process's threads in turn
            if index in held:
                return compile_signature(self, sig)
            try:
                lock = open(f'{index}.lock', 'a')
            except OSError:  # a folder this process cannot write: numba's cache as it is
                return compile_signature(self, sig)
            with lock:
                fcntl.flock(lock, fcntl.LOCK_EX)
                held.add(index)
                try:
                    return compile_signature(self, sig)
                finally:
                    held.discard(index)
                    fcntl.flock(lock, fcntl.LOCK_UN)

    compile_in_turn.in_turn = True
    dispatcher.Dispatcher.compile = compile_in_turn


def plain_reference_counts() -> bool:
    """Whether this process counts the kernels' arrays' references with plain adds, not atomic
    ones: where MULTILIFT_PLAIN_REFCOUNTS is 1 when numba's runtime (NRT) is built (the
    process's first kernel loaded or compiled), which our commands (`multilift`) and nodes set
    for themselves and the processes they start. NRT counts every array's references with a
    locked add (`lock incq`), thread-safe and slow; a tick passes the batch's tuples of arrays
    through its calls, so those counts took over a third of a twin-lift tick here (perf:
    NRT_incref and NRT_decref; `python benchmarks/refcounts.py`). Plain counts are exact while
    no two threads run compiled code on the same arrays at once: our processes run kernels from
    one thread (single-threaded executors, process pools); a library user's process (which may
    share arrays between threads, numba's `parallel=True`) keeps numba's default. NRT builds
    its add and sub from `nrtdynmod._define_atomic_inc_dec`, which this replaces by
    `_plain_add_sub`: a deliberate use of a private name, as `_compile_in_turn`."""
    from numba.core.runtime import nrt, nrtdynmod
    if os.environ.get(PLAIN_COUNTS) == '1' and not nrt.rtsys._init:
        nrtdynmod._define_atomic_inc_dec = _plain_add_sub
    return nrtdynmod._define_atomic_inc_dec is _plain_add_sub


def _plain_add_sub(module, op: str, ordering: str):
    """NRT's reference count add or sub (`op`) into the LLVM `module`, as numba's
    `nrtdynmod._define_atomic_inc_dec` defines it (`nrt_atomic_<op>`, returning the new count)
    with a plain load, add and store (the `ordering` unused). numba's own switch,
    `_disable_atomicity`, is not used: it returns the old count, so nothing is ever freed
    (measured: NRT's frees stayed at 4 of 5.3 million allocations)."""
    from numba.core.runtime.nrtdynmod import _word_type, ir  # llvmlite's ir, as numba's
    function = ir.Function(module, ir.FunctionType(_word_type, [_word_type.as_pointer()]),
                           name=f'nrt_atomic_{op}')
    [count] = function.args
    builder = ir.IRBuilder(function.append_basic_block())
    new = getattr(builder, op)(builder.load(count), ir.Constant(_word_type, 1))
    builder.store(new, count)
    builder.ret(new)
    return function


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
    _compile_in_turn()
    _load_without_lowering()
    plain_reference_counts()


def _load_without_lowering() -> None:
    """Load a cached kernel with what running it needs, not what compiling needs (`run
    twin_lift --headless` from 1.07-1.08 s to 0.72-0.77 s here, benchmarks/results.md). Two of
    numba's steps are for compiling, and a later compile does them itself:
    - `Cache.load_overload` refreshes the target context first: imports numba's lowering
      (numba.cpython, numba.typed, numba.np.random, ...) and installs its registries, 0.3 s
      here, of which loading object code needs only NRT (`rtsys.initialize`); a compile
      refreshes anyway (numba's `CompilerBase` does), and numba.np.arraymath is imported
      first, quietly (`_import_numba_quietly`), so a compile's code does not change.
    - Unserialising a library of object code parses the LLVM bitcode saved beside it (for
      linking into another library's compile) and reads its symbols into the JIT engine's
      table (`JitEngine.is_symbol_defined`): 0.15 s for the tick's 4.5 MB. Here the bitcode is
      kept as bytes and parsed when a compile links the library (`_get_module_for_linking`);
      the table asks the engine, whose loaded objects hold the same symbols, then parses
      what is pending before it answers no.
    Private names of numba 0.68 (pinned), as `_compile_in_turn`."""
    from numba.core import caching, codegen
    from numba.core.runtime import nrt
    if getattr(caching.Cache.load_overload, 'without_lowering', False):
        return
    library_class, engine_class = codegen.CPUCodeLibrary, codegen.JitEngine
    unserialize = library_class._unserialize.__func__
    module_for_linking = library_class._get_module_for_linking
    symbol_defined = engine_class.is_symbol_defined

    def load_overload(self, sig, target_context):
        nrt.rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    def unserialize_unparsed(cls, codegen_, state):
        name, kind, data = state
        if kind != 'object':
            return unserialize(cls, codegen_, state)
        object_code, linking_bitcode = data
        library = codegen_.create_library(name)
        library.enable_object_caching()
        library._set_compiled_object(object_code)
        library._linking_bitcode = linking_bitcode
        library._finalize_final_module()
        engine = codegen_._engine
        engine._unparsed = [*getattr(engine, '_unparsed', ()), library]
        return library

    def parse(library) -> None:
        if getattr(library, '_linking_bitcode', None) is not None:
            library._shared_module = codegen.ll.parse_bitcode(library._linking_bitcode)
            library._linking_bitcode = None
            library._codegen._engine._load_defined_symbols(library._shared_module)

    def parsed_module_for_linking(library):
        parse(library)
        return module_for_linking(library)

    def is_symbol_defined(engine, name: str) -> bool:
        if symbol_defined(engine, name):
            return True
        unparsed = getattr(engine, '_unparsed', ())
        if not unparsed:
            return False
        if engine._ee.get_global_value_address(name):
            return True
        engine._unparsed = []
        for library in unparsed:
            parse(library)
        return symbol_defined(engine, name)

    load_overload.without_lowering = True
    caching.Cache.load_overload = load_overload
    library_class._unserialize = classmethod(unserialize_unparsed)
    library_class._get_module_for_linking = parsed_module_for_linking
    engine_class.is_symbol_defined = is_symbol_defined
