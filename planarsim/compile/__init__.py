"""planarsim's compiler layer: how the physics stages (planarsim/kernels) become machine code.

Four decorators (decorators.py: jit, jit_inline, kernel, part) and one of three modes, chosen on
import (mode.py): ``fast`` (planarsim's own code library on numba internals; the default),
``plain`` (numba's public API only: PLANARSIM_PLAIN_NUMBA=1, or on its own when a numba
release lacks an internal) and ``python`` (NUMBA_DISABLE_JIT=1: every kernel runs as Python,
for pdb). All three give the same numbers. The step's linkage is link.py (fast mode:
fast_step.py, its parts compiled beside it in parts.py); caches.py clears numba caches whose
engine sources changed.
"""
from .mode import FAST, MODE, PLAIN, PYTHON, TABLES
from .decorators import jit, jit_inline, kernel, options, part, register
from .caches import drop_stale_caches

__all__ = ["MODE", "FAST", "PLAIN", "PYTHON", "TABLES", "jit", "jit_inline", "kernel", "part", "register", "options",
           "drop_stale_caches"]
