"""A cached kernel loads without numba's lowering (`multilift_sim.kernels._load_without_lowering`):
in a fresh process the load imports none of numba's lowering modules and leaves the kernel's
linking bitcode unparsed; a function compiled afterwards that calls it links it (the bitcode
parsed then) and computes what the kernel's uncompiled run computes; and a twin-lift batch flies
the same bits whether the process loaded its kernels that way or with numba's full refresh and
every bitcode parsed first."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytest.importorskip('numba')

LINKED = r'''
import json, sys
import numba
import numpy as np
from multilift_sim import kernels, kinematics
from multilift_sim.physics import measurement
angles = np.random.default_rng(3).uniform(-1.4, 1.4, (50, 3))
kinematics.quaternion_from_euler(angles)  # loads the cached euler_quaternions
loaded = kernels.runnable(measurement.euler_quaternions)
library = loaded.overloads[loaded.signatures[0]].library
before = {'lowering': 'numba.typed.dictimpl' in sys.modules,
          'unparsed': isinstance(getattr(library, '_linking_bitcode', None), bytes)}


@numba.njit
def doubled(rows, out):
    loaded(rows, out)  # a compiled call: links the cached library into this one
    for k in range(out.shape[0]):
        for j in range(4):
            out[k, j] *= 2.0


out, reference = np.empty((50, 4)), np.empty((50, 4))
doubled(angles, out)
kernels.uncompiled(measurement.euler_quaternions)(angles, reference)
print(json.dumps({'before': before, 'lowering': 'numba.typed.dictimpl' in sys.modules,
                  'unparsed': isinstance(getattr(library, '_linking_bitcode', None), bytes),
                  'equal': bool(np.array_equal(out, 2.0 * reference))}))
'''

FLOWN = r'''
import json, sys
import numpy as np
from multilift_sim import kernels, scenario as scenario_io
if sys.argv[1] == 'eager':  # numba's own way: the whole refresh before the first load ...
    from numba.core.registry import cpu_target
    cpu_target.target_context.refresh()
from multilift_control.engine import Engine
engine = Engine(scenario_io.load('twin_lift'), batch=2)
if sys.argv[1] == 'eager':  # ... and every loaded library's bitcode parsed before it runs
    cpu_target.target_context.codegen()._engine.is_symbol_defined('no such symbol')
engine.step(300)
print(json.dumps({'lowering': 'numba.typed.dictimpl' in sys.modules,
                  'positions': np.asarray(engine.positions).tolist()}))
'''


def _child(source: str, *args: str) -> dict:
    done = subprocess.run([sys.executable, '-c', source, *args], capture_output=True, text=True,
                          timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_cached_kernel_loads_unlowered_and_links_into_a_later_compile():
    result = _child(LINKED)
    assert result['before'] == {'lowering': False, 'unparsed': True}
    assert result['equal']
    assert (result['lowering'], result['unparsed']) == (True, False)  # the compile did both


def test_a_batch_flies_the_same_bits_loaded_lazily_or_eagerly():
    lazy, eager = _child(FLOWN, 'lazy'), _child(FLOWN, 'eager')
    assert (lazy['lowering'], eager['lowering']) == (False, True)
    assert lazy['positions'] == eager['positions']
