"""The int64 / float64 tables that describe a simulator's arrays to kernels/table_step.py (table_run_steps).

The table holds raw addresses: it is valid only while the arrays it lists are alive and not
reallocated, which the Simulator guarantees by owning them (its state and workspace are never
replaced, only copied into).
"""
from __future__ import annotations

import numpy as np

from .kernels.table_gen import SLOTS


def _arrays(*structs):
    """Every array of the NamedTuples, depth first (Workspace.prev expanded in place)."""
    out = []
    for struct in structs:
        for value in struct:
            if isinstance(value, np.ndarray):
                out.append(value)
            elif isinstance(value, tuple):
                out.extend(_arrays(value))
    return out


def pack_tables(m, s, ws, opt):
    """(tab, flt) for table_run_steps over model arrays m, State s, Workspace ws and options opt."""
    from .kernels.table_step import N_ARRAY_SLOTS, N_FLOATS, N_INT_SCALARS
    arrays = _arrays(m, s, ws)
    if len(arrays) * SLOTS != N_ARRAY_SLOTS:
        raise RuntimeError("kernels/table_step.py is out of date: run python -m planarsim.kernels.table_gen")
    tab = np.zeros(N_ARRAY_SLOTS + N_INT_SCALARS, np.int64)
    for k, a in enumerate(arrays):
        if a.dtype not in (np.float64, np.int64) or not a.flags.c_contiguous:
            raise TypeError(f"array {k} of the simulator is {a.dtype}, contiguous={a.flags.c_contiguous}; "
                            "the compiled step needs C-contiguous float64 / int64 arrays")
        tab[SLOTS * k] = a.ctypes.data
        tab[SLOTS * k + 1:SLOTS * k + 1 + a.ndim] = a.shape
    flt = np.zeros(N_FLOATS)
    flt[0] = m.dt
    set_options(tab, flt, opt)
    return tab, flt


def set_options(tab, flt, opt):
    """Write StepOptions opt (already checked) into the tables."""
    from .kernels.table_step import N_ARRAY_SLOTS
    ints = [v for v in opt if isinstance(v, int)]
    floats = [v for v in opt if isinstance(v, float)]
    tab[N_ARRAY_SLOTS:] = ints
    flt[1:] = floats
