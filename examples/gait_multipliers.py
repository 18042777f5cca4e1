"""Floquet multipliers of the actuated walkers' gaits: the Simple Biped and Ranger.

Each walker walks from rest until its gait has converged; the section state there (controller
touchdown for the Simple Biped, controller mid-stance for Ranger; see walkers/*/gait_map.py) is
taken as the fixed point, the map's residual |P(x*) - x*| is printed, and the multipliers are
the eigenvalues of the central finite-difference Jacobian of the stride map (two steps, back to
the same foot).

    python examples/gait_multipliers.py                 # both walkers
    python examples/gait_multipliers.py ranger --eps 3e-3 1e-2
"""
from __future__ import annotations

import argparse
import time

import numpy as np

WALKERS = ("simple-biped", "ranger")


def gait_map(name, dt=None, settle=None):
    """The walker's gait map at the analysis defaults (dt, settle time) of its module."""
    if name == "simple-biped":
        from walkers.simple_biped import gait_map as gm
        return gm.SimpleBipedGaitMap(settle=settle or gm.SETTLE, dt=dt or gm.DT), gm.EPS
    if name == "ranger":
        from walkers.ranger import gait_map as gm
        return gm.RangerGaitMap(settle=settle or gm.SETTLE, dt=dt or gm.DT), gm.EPS
    raise SystemExit(f"unknown walker {name!r}; use one of {WALKERS}")


def report(name, eps_list=None, dt=None, settle=None):
    t0 = time.perf_counter()
    g, eps_default = gait_map(name, dt, settle)
    print(f"== {name}: dt = {g.dt} s, settled {g.settle} s, section: {g.SECTION}")
    np.set_printoptions(precision=5, suppress=True, linewidth=120)
    print("  coordinates:", ", ".join(g.names))
    print("  fixed point x* =", g.x0)
    print(f"  residual |P(x*) - x*|_inf = {g.residual():.3e}  (per coordinate {np.abs(g.step_map()(g.x0) - g.x0)})")
    out = {}
    for eps in eps_list or [eps_default]:
        lam = g.multipliers(eps)
        out[eps] = lam
        print(f"  eps = {eps:g}: multipliers (largest modulus first)")
        for z in lam:
            print(f"      {z.real:+.5f} {z.imag:+.5f}j   |.| = {abs(z):.5f}")
        print(f"      spectral radius {np.max(np.abs(lam)):.5f} -> "
              f"{'stable' if np.max(np.abs(lam)) < 1 else 'NOT stable'}")
    print(f"  ({time.perf_counter() - t0:.1f} s)")
    return g, out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("walkers", nargs="*", default=list(WALKERS), help=f"any of {WALKERS}")
    ap.add_argument("--eps", type=float, nargs="*", help="finite-difference steps (default: the walker's)")
    ap.add_argument("--dt", type=float, help="step size [s] (default: the walker's analysis dt)")
    ap.add_argument("--settle", type=float, help="walking time before the section [s]")
    a = ap.parse_args(argv)
    for name in a.walkers:
        report(name, a.eps, a.dt, a.settle)


if __name__ == "__main__":
    main()
