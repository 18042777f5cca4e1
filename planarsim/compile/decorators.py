"""The four decorators of planarsim's compiled code, the same in every mode (compile/mode.py).

    @jit                     compiled, callable from Python and from compiled code; its machine
                             code is cached on disk (rollouts, run_recorded, terrain queries)
    @jit_inline              the same, inlined into its compiled callers (a walker's controller
                             run every step: its rollout inlines it, the Python path calls it)
    @kernel                  compiled code only (the physics stages): inlined into its callers,
                             cached inside them; a call from Python raises a TypeError that says
                             so (fast mode; elsewhere it is an ordinary function)

Options, for speed only (every choice gives the same numbers):
    @jit(inline="force")     always inlined by LLVM where compiled code calls it (terrain
                             height and closest point, called in hot loops)
    @kernel(inline="always") inlined by numba before typing (the step's own stages)
    @kernel(inline="never")  one copy of its code that callers call: long code that runs
                             rarely, or a stage run a few times a step whose code would
                             otherwise be copied into each of its callers (build_rows,
                             eval_rows: a call costs nanoseconds, each copy seconds of the
                             first-ever compile)
    @part(types...)          a kernel(inline="never") compiled into a C function of its own
                             that callers call by address (fast mode: compiled beside the step
                             on a first-ever start; compile/parts.py). From Python, numba
                             refuses the call ("not usable in pure-python")

All never allocate and keep the NaN checks that fastmath would drop (fastmath=False).
Under NUMBA_DISABLE_JIT=1 each returns the function itself (its `py_func` is itself too).
"""
from __future__ import annotations

import numba

from .mode import FAST, MODE, PYTHON, TABLES
from .part_types import PART_ARGS

# the fast mode's compiler and the tables use numba internals that the other modes may lack
if MODE == FAST:
    from . import fast, parts
if TABLES:
    from . import refs

# plain numba: documented options only
PLAIN_OPTIONS = dict(cache=True, fastmath=False, nogil=True, error_model="numpy")


def options():
    """numba.njit keywords of this mode's compiled code (tests compile helpers with them)."""
    if MODE == FAST:
        return dict(fast._OPTIONS)
    return dict(PLAIN_OPTIONS)


_JIT_INLINE = (None, "force", "always")
_KERNEL_INLINE = ("force", "always", "never")


def _python(fn):
    fn.py_func = fn   # as a dispatcher has it (code that asks for the Python function)
    return fn


def _decorator(who, allowed, fn, inline):
    """The decorator `who` (jit or kernel) of this mode with `inline`, applied to fn if given."""
    if inline not in allowed:
        raise ValueError(f"{who}(inline={inline!r}): choose one of {allowed}")
    if MODE == PYTHON:
        decorate = _python
    elif MODE == FAST:
        decorate = getattr(fast, who)(inline)
    else:
        decorate = numba.njit(**dict(PLAIN_OPTIONS, **({"inline": "always"} if inline == "always" else {})))
    return decorate if fn is None else decorate(fn)


def jit(fn=None, *, inline=None):
    """Compile `fn`, callable from Python and from compiled code (see the module's docstring);
    use as ``@jit`` or ``@jit(inline="force")``."""
    return _decorator("jit", _JIT_INLINE, fn, inline)


def jit_inline(fn):
    """Compile `fn` as `jit`, inlined by numba into its compiled callers."""
    return jit(fn, inline="always")


def kernel(fn=None, *, inline="force"):
    """Compile `fn` for compiled callers only (see the module's docstring); use as ``@kernel``,
    ``@kernel(inline="always")`` or ``@kernel(inline="never")``."""
    return _decorator("kernel", _KERNEL_INLINE, fn, inline)


def part(*args, returns=None):
    """A kernel compiled on its own and called by address (compile/parts.py). args: the type of
    each argument, "model", "state", "workspace", "options", "float64", "int64" or "boolean";
    returns: "float64", "int64", or None. Elsewhere than the fast mode, kernel(inline="never")."""
    for a in args:
        if a not in PART_ARGS:
            raise ValueError(f"part: argument type {a!r} is none of {', '.join(PART_ARGS)}")
    if returns not in (None, "float64", "int64"):
        raise ValueError(f"part: returns {returns!r}; a part returns float64, int64 or None")

    def decorate(fn):
        dispatcher = kernel(fn, inline="never")
        if MODE != FAST:
            return dispatcher
        return parts.register(fn, dispatcher, args, returns)
    return decorate


def register(cls=None, *, readonly=False):
    """Let compiled code take NamedTuple class `cls` (of arrays, floats, ints and registered
    NamedTuples) as one pointer (compile/refs.py; under NUMBA_DISABLE_JIT=1 it stays a
    NamedTuple). readonly: its arrays are read-only in compiled code. Returns cls; use as
    ``@register`` or ``@register(readonly=True)``."""
    if cls is None:
        return lambda c: register(c, readonly=readonly)
    if TABLES:
        return refs.register(cls, readonly=readonly)
    return cls
