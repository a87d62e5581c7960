"""The decorator of every physics function: numba's njit, or the function itself where numba
does not import (then only its uncompiled run exists)."""
from multilift_sim import kernels  # sets NUMBA_CACHE_DIR before numba loads

try:
    kernels._import_numba_quietly()
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the pure run still works
    def jit(function):
        return function
else:
    jit = numba.njit(cache=True, fastmath=False, nogil=True)
