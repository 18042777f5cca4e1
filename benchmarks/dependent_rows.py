"""What the rows a pile's velocity solve drops as dependent cost its sparse factorisation.

    python benchmarks/dependent_rows.py                 # pyramid20 and pyramid45
    python benchmarks/dependent_rows.py wall40x10 --steps 5

A pile at rest has far more contact rows than its bodies have degrees of freedom (a 45-row
pyramid: 7,816 rows on 1,035 boxes, rank 3 x 1,035); the solve eliminates them all and drops
the ones that depend on earlier rows (kernels/solver/sparse_factor.py), whose fill stays in the
elimination tree. This runs a world of benchmarks/worlds.py a few steps from rest, then
times the solve's structure (arrange: nested-dissection order and elimination tree), its
assembly and its factorisation of (a) every row, as the step makes them, and (b) only the
rows (a) kept, the same rows in the same order, so the factors of (b) drop none. The gap
is what a solve that knew the dependent rows beforehand would save (not a test; prints ms).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps                                            # noqa: E402
from planarsim.compiled import jit                                # noqa: E402
from planarsim.kernels.solver.matrix import arrange, assemble, factor_ws  # noqa: E402

from benchmarks.worlds import WORLDS                             # noqa: E402

PIVOT_TOL = ps.StepOptions().pivot_tol


@jit
def _arrange(q, ws, n):
    return arrange(q, ws, n, q.shape[0], ws.start.contact_dependent, False)


@jit
def _assemble(m, ws, n):
    assemble(m, ws, ws.row_J, ws.row_F, n, True)


@jit
def _factor(ws, n, tol):
    return factor_ws(ws, n, tol, True)


def _time_solve_parts(sim, n, repeats):
    """(dropped, arrange ms, assemble ms, factor ms) of rows 0..n-1, best of repeats."""
    ws, m, q = sim.ws, sim.model.arrays, sim.state.q
    best = [np.inf, np.inf, np.inf]
    dropped = -1
    for _ in range(repeats):
        t0 = time.perf_counter()
        if not _arrange(q, ws, n):
            raise RuntimeError("the rows do not fit the workspace's sparse storage")
        t1 = time.perf_counter()
        _assemble(m, ws, n)
        t2 = time.perf_counter()
        dropped = _factor(ws, n, PIVOT_TOL)
        t3 = time.perf_counter()
        for k, dt in enumerate((t1 - t0, t2 - t1, t3 - t2)):
            best[k] = min(best[k], dt * 1e3)
    return dropped, *best


def measure(name, steps, repeats):
    sim = ps.Simulator(WORLDS[name]())
    sim.steps(steps)
    ws = sim.ws
    n = int(ws.n_row[0])
    if n < 1024:
        return f"{name:11s} {n} rows: below the sparse factorisation's 1,024, not measured"
    full = _time_solve_parts(sim, n, repeats)
    kept = np.flatnonzero(ws.sp_pivot[ws.sp_iperm[:n]] != 0.0)
    for field in ("row_kind", "row_owner", "row_body", "row_J", "row_F"):
        array = getattr(ws, field)
        array[:kept.size] = array[kept].copy()
    alone = _time_solve_parts(sim, kept.size, repeats)
    return (f"{name:11s} every row {n:6,d} (drops {full[0]:5,d}): arrange {full[1]:7.2f}  "
            f"assemble {full[2]:6.2f}  factor {full[3]:8.2f} ms | the {kept.size:,d} it keeps "
            f"(drops {alone[0]}): arrange {alone[1]:6.2f}  assemble {alone[2]:6.2f}  "
            f"factor {alone[3]:7.2f} ms")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("worlds", nargs="*", default=["pyramid20", "pyramid45"],
                    help=f"of {list(WORLDS)}")
    ap.add_argument("--steps", type=int, default=3, help="steps from rest before timing")
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args(argv)
    unknown = [w for w in a.worlds if w not in WORLDS]
    if unknown:
        ap.error(f"unknown world(s) {unknown}; the worlds are {list(WORLDS)}")
    for name in a.worlds:
        print(measure(name, a.steps, a.repeats), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
