"""The float kernel of FormationModel (`_solve_floats`, `rk4_floats`, `_residuals_floats`)
compiled with numba: the same arithmetic in the same order, one control period per call.

The pure-Python kernel in dynamics.py stays the reference (tests/test_kernels.py holds them
equal); this one is used when numba imports and MULTILIFT_KERNEL is not `python`
(`MULTILIFT_KERNEL=python` forces the pure kernel). Compiled code is cached on disk
(`cache=True`) under NUMBA_CACHE_DIR, by default `$XDG_CACHE_HOME/multilift/numba`
(`~/.cache/multilift/numba`), set before numba is imported: the first process compiles
(about 1-2 s), later ones load the cache. `compiled_module` loads the control laws' compiled
functions (multilift_control._numba_laws) the same way, under the same switch; controller
nodes default it to `python` (multilift_control.runtime.prepare_node_laws).
"""
from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path
from types import ModuleType

import numpy as np

_cache_home = os.environ.get('XDG_CACHE_HOME') or str(Path.home() / '.cache')
os.environ.setdefault('NUMBA_CACHE_DIR', str(Path(_cache_home) / 'multilift' / 'numba'))

VARIABLE = 'MULTILIFT_KERNEL'  # auto (or unset): compiled where numba imports; python: pure
_modules: dict[str, ModuleType | None] = {}  # compiled modules by name (None: no numba)


def enabled() -> bool:
    """Whether the compiled kernel is to be used (numba importable, not switched off)."""
    return compiled_module('multilift_sim._numba_kernel') is not None


def compiled_module(name: str) -> ModuleType | None:
    """The module of compiled functions `name` (imported once), or None when the pure-Python
    reference is to be used: numba does not import, or MULTILIFT_KERNEL=python."""
    if os.environ.get(VARIABLE, 'auto') == 'python':
        return None
    if name not in _modules:
        try:
            _import_numba_quietly()
            _modules[name] = importlib.import_module(name)
        except ImportError:
            _modules[name] = None
    return _modules[name]


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


def model_constants(model) -> tuple:
    """The arrays and scalars the kernel reads from a FormationModel (float kernel)."""
    params = model.params
    uavs = np.array(model._uav_constants, dtype=float).reshape(-1, 8)
    gusts = np.array([(*g.center, *g.direction, g.gradient_distance, g.reference_speed)
                      for g in params.gusts], dtype=float).reshape(-1, 7)
    return (uavs, gusts, float(model.payload_mass), float(model._inv_payload_mass),
            float(model.gravity), float(model._two_alpha), float(model._beta_sq),
            bool(model._has_drag), float(params.payload_drag_coefficient))


def integrate(constants: tuple, x: np.ndarray, wrenches: np.ndarray, dt: float,
              steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """`steps` RK4 steps of dt [s] from x: (state, multipliers at x, g, g_dot at the end);
    after `enabled()` said yes."""
    kernel = _modules['multilift_sim._numba_kernel'].integrate_period
    return kernel(*constants, np.ascontiguousarray(x, dtype=np.float64),
                  np.ascontiguousarray(wrenches, dtype=np.float64), float(dt), int(steps))
