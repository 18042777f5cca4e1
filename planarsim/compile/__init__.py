"""planarsim's compiler layer: how compiled code becomes machine code. Generic: it imports
nothing from the rest of planarsim (the physics stages, planarsim/kernels, use its
decorators; the layer that links the step to its callers, planarsim/link, binds it).

Four decorators (decorators.py: jit, jit_inline, kernel, part) and ``register`` (NamedTuples
as one pointer: refs.py), in one of three modes, chosen on import (mode.py): ``fast``
(planarsim's own code library on numba internals, fast.py; the default), ``plain`` (numba's
public API only: PLANARSIM_PLAIN_NUMBA=1, or on its own when a numba release lacks an
internal, numba_check.py) and ``python`` (NUMBA_DISABLE_JIT=1: every kernel runs as Python,
for pdb). All three give the same numbers. The fast mode compiles with its own compile flags
(flags.py) and can compile long kernels beside their callers in a child process
(parts.py); caches.py has the machinery that clears numba caches whose sources changed.
"""
from .mode import FAST, MODE, PLAIN, PYTHON, TABLES
from .decorators import jit, jit_inline, kernel, options, part, register

__all__ = ["MODE", "FAST", "PLAIN", "PYTHON", "TABLES", "jit", "jit_inline", "kernel", "part", "register", "options"]
