"""Stepping through the engine in pdb (under NUMBA_DISABLE_JIT=1, where every kernel is Python).

    debugger = break_in("solver.solve.solve_impulses")   # a module of planarsim/kernels, a function
    debugger.runcall(sim.step)                    # 'c' runs on to the breakpoint
"""
from __future__ import annotations

import importlib
import pdb

from ..compile.mode import MODE, PYTHON


def break_in(where: str, debugger: pdb.Pdb | None = None) -> pdb.Pdb:
    """`debugger` (a new pdb.Pdb by default) with a breakpoint where engine function `where`
    starts: "folder.module.function" below planarsim/kernels (say
    "solver.solve.solve_impulses", the contact solve). Compiled code has no line to stop on:
    outside NUMBA_DISABLE_JIT=1 this raises a RuntimeError saying so; an unknown module or
    function is a ValueError naming it."""
    if MODE != PYTHON:
        raise RuntimeError("break_in: the engine is compiled in this process; run it with "
                           "NUMBA_DISABLE_JIT=1 to stop inside a kernel")
    module, _, name = where.rpartition(".")
    try:
        fn = getattr(importlib.import_module(f"planarsim.kernels.{module}"), name)
        code = fn.__code__
    except (ImportError, AttributeError, ValueError):
        raise ValueError(f"break_in({where!r}): no function {name!r} in planarsim/kernels/"
                         f"{module.replace('.', '/') or '?'}.py") from None
    debugger = pdb.Pdb() if debugger is None else debugger
    debugger.set_break(code.co_filename, code.co_firstlineno, funcname=code.co_name)
    return debugger
