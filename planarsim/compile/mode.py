"""How planarsim's code is compiled in this process: one of three modes, chosen on import.

    fast    planarsim's own code library and pipeline on numba internals (fast.py), the step
            one C function that all compiled code calls (fast_step.py): the quickest
            first-ever compile. The default whenever the installed numba has every internal
            used (numba_check.py).
    plain   numba's public API (numba.njit) and its low-level extension API (refs.py: model,
            state and workspace passed as one pointer each): the same numbers and steps/s, a
            slower first compile. Chosen by PLANARSIM_PLAIN_NUMBA=1, or on its own, with a
            warning naming what changed, when a numba release lacks an internal that the fast
            mode uses: such a release costs a slower cold start, not a broken import. Should
            the extension API change too, the NamedTuples go to numba as they are (TABLES is
            False: correct, with a much slower first compile).
    python  numba's NUMBA_DISABLE_JIT=1: every kernel runs as Python (the same numbers to
            rounding), so that pdb can stop inside the step.
"""
from __future__ import annotations

import os
import warnings

from .numba_check import changed_internals, changed_tables

FAST, PLAIN, PYTHON = "fast", "plain", "python"
PLAIN_SWITCH = "PLANARSIM_PLAIN_NUMBA"


def choose_mode(environ, jit_disabled: bool, missing) -> str:
    """The mode for environment `environ`, numba's DISABLE_JIT flag and `missing`, a callable
    returning the numba internals the fast mode lacks (called only when that matters)."""
    if jit_disabled:
        return PYTHON
    if environ.get(PLAIN_SWITCH, "") not in ("", "0"):
        return PLAIN
    changed = missing()
    if changed:
        import numba
        warnings.warn(f"numba {numba.__version__} changed internals that planarsim's fast "
                      f"compile builds on ({', '.join(changed)}); planarsim runs on plain "
                      "numba (the same numbers; a slower first compile)",
                      RuntimeWarning, stacklevel=3)
        return PLAIN
    return FAST


def _mode() -> str:
    from numba import config
    return choose_mode(os.environ, bool(config.DISABLE_JIT), changed_internals)


def _tables(mode) -> bool:
    if mode == PYTHON:
        return False
    if mode == FAST:
        return True
    changed = changed_tables()
    if changed:
        warnings.warn(f"numba lacks {', '.join(changed)}: planarsim passes its NamedTuples to "
                      "numba as they are (the same numbers; a first compile of many minutes)",
                      RuntimeWarning, stacklevel=3)
    return not changed


MODE = _mode()
TABLES = _tables(MODE)   # model, state, workspace and options reach compiled code as one pointer
