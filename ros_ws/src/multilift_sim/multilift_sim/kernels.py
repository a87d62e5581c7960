"""The float kernel of FormationModel (`_solve_floats`, `rk4_floats`, `_residuals_floats`)
compiled with numba: the same arithmetic in the same order, one control period per call.

The pure-Python kernel in dynamics.py stays the reference (tests/test_kernels.py holds them
equal); this one is used when numba imports and MULTILIFT_KERNEL is not `python`
(`MULTILIFT_KERNEL=python` forces the pure kernel). Compiled code is cached on disk
(`cache=True`) under NUMBA_CACHE_DIR, by default `$XDG_CACHE_HOME/multilift/numba`
(`~/.cache/multilift/numba`), set before numba is imported: the first process compiles
(about 1-2 s), later ones load the cache.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

_cache_home = os.environ.get('XDG_CACHE_HOME') or str(Path.home() / '.cache')
os.environ.setdefault('NUMBA_CACHE_DIR', str(Path(_cache_home) / 'multilift' / 'numba'))

_integrate = None  # the compiled function, once built
_unavailable = False


def enabled() -> bool:
    """Whether the compiled kernel is to be used (numba importable, not switched off)."""
    return os.environ.get('MULTILIFT_KERNEL', 'auto') != 'python' and _load() is not None


def _load():
    global _integrate, _unavailable
    if _integrate is None and not _unavailable:
        try:
            _import_numba_quietly()
            from multilift_sim._numba_kernel import integrate_period
        except ImportError:
            _unavailable = True
            return None
        _integrate = integrate_period
    return _integrate


def _import_numba_quietly() -> None:
    """Import numba's array implementations without scipy. Loading even a cached kernel
    imports numba.np.arraymath, whose import imports scipy.linalg only to learn whether BLAS
    is there for np.dot of vectors (0.1-0.4 s of every process's start here; our kernels call
    no BLAS). Hidden from that probe, numba takes its plain loop for such products; scipy
    imports normally afterwards."""
    hide = 'scipy' not in sys.modules
    if hide:
        sys.modules['scipy'] = None  # an import of scipy now raises ImportError
    try:
        import numba.np.arraymath  # noqa: F401 - the import is the point
    finally:
        if hide and sys.modules.get('scipy', False) is None:
            del sys.modules['scipy']


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
    """`steps` RK4 steps of dt [s] from x: (state, multipliers at x, g, g_dot at the end)."""
    return _load()(*constants, np.ascontiguousarray(x, dtype=np.float64),
                   np.ascontiguousarray(wrenches, dtype=np.float64), float(dt), int(steps))
