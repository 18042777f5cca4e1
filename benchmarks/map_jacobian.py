"""The passive walkers' step map with its exact Jacobian (walkers.passive.map_jacobian).

    python benchmarks/map_jacobian.py                  # every part (about 10 min on one core)
    python benchmarks/map_jacobian.py --only newton    # parts: check newton convergence doublings

- check: the exact Jacobian against centred differences of the map (step 1e-6) at the gait,
  and its time against the fits' (multipliers_by_fit: 17 samples per coordinate) and the
  differences' (multipliers_with_error).
- newton: iterations of find_fixed_point from guesses around the gait, with the exact
  Jacobian, with central differences (steps 1e-4, as the gait tests take, and 1e-6) and with
  the fitted Jacobian (multipliers_by_fit's, the continuation's default).
- convergence: the multipliers from the exact Jacobian at the gait as dt halves (1e-3, 5e-4,
  2.5e-4 s), against the rimless wheel's closed form eta^2 and the scipy reference's
  variational equations for the simplest walker (foot mass ratio 1e-3), with Richardson's
  extrapolation at the map's order (second for both: the wheel's pivot is a held contact,
  which aims at its gap to second order).
- doublings: the simplest walker's first three period doublings by continuation with the
  exact Jacobians, and the ratio of their spacings.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from planarsim.analysis import (find_fixed_point, match_distance, multipliers_by_fit,
                                multipliers_exact, multipliers_with_error, sort_multipliers)
from planarsim.analysis.stepmap import StepMap, jacobian
from walkers.passive import PassiveWalker, RimlessParams, SimplestParams
from walkers.passive.reference import (simplest_feet_map, simplest_feet_step_jacobian,
                                       simplest_fixed_point)
from walkers.passive.rimless_wheel import closed_form

DTS = (1e-3, 5e-4, 2.5e-4)


def references():
    """{walker: (params, gait x, multipliers)} from the closed form and the scipy reference."""
    rp = RimlessParams()
    cf = closed_form(rp)
    sp = SimplestParams()
    x = find_fixed_point(simplest_feet_map(sp), simplest_fixed_point()["x"], tol=1e-13,
                         eps=1e-7).x
    lam = sort_multipliers(np.linalg.eigvals(simplest_feet_step_jacobian(x, sp)[1]))
    return {"rimless-wheel": (rp, np.array([-cf["omega_after"]]), np.array([cf["eta"] ** 2])),
            "simplest-walker": (sp, x, lam)}


def gait(params, x0, dt):
    w = PassiveWalker(params, dt=dt)
    f = w.step_map()
    return w, f, find_fixed_point(f, x0, tol=1e-13, exact=False)


def check(refs):
    print("== the exact Jacobian at the gait (dt 1e-3) against differences, and its time")
    for name, (params, x0, _) in refs.items():
        w, f, fp = gait(params, x0, 1e-3)
        t = time.perf_counter()
        J = f.jacobian(fp.x)
        t_exact = time.perf_counter() - t
        t = time.perf_counter()
        D = jacobian(f, fp.x, 1e-6)
        t_diff = time.perf_counter() - t
        t = time.perf_counter()
        multipliers_by_fit(f, fp.x, warn=False)
        t_fit = time.perf_counter() - t
        t = time.perf_counter()
        multipliers_with_error(f, fp.x, warn=False)
        t_ladder = time.perf_counter() - t
        print(f"  {name:16s} |J - D| / |D| = {np.abs(J - D).max() / np.abs(D).max():.2e}; "
              f"exact {t_exact:.2f} s, fits {t_fit:.2f} s, difference ladder {t_ladder:.2f} s, "
              f"one central difference Jacobian {t_diff:.2f} s")


def newton(refs):
    print("== Newton iterations from guesses around the gait (dt 1e-3; tol 1e-12)")
    print(f"  {'walker':16s} {'guess offset':>28s} {'exact':>6s} {'fd 1e-4':>8s} {'fd 1e-6':>8s} "
          f"{'fit':>6s}")
    rng = np.random.default_rng(7)
    for name, (params, x0, _) in refs.items():
        w = PassiveWalker(params, dt=1e-3)
        f = w.step_map()
        # Newton on the fitted Jacobian (multipliers_by_fit's, the continuation's default)
        fit = StepMap(f.advance, f.dim, names=f.names, derivative=lambda x, f=f: (
            f(x), multipliers_by_fit(f, x, warn=False).jacobian))
        scale = np.full(x0.size, 0.01) if x0.size > 1 else np.array([0.2])
        for _ in range(4):
            d = scale * rng.uniform(-1.0, 1.0, x0.size)
            counts = []
            for g, kw in ((f, dict(exact=True)), (f, dict(exact=False, eps=1e-4)),
                          (f, dict(exact=False, eps=1e-6)), (fit, dict(exact=True))):
                try:
                    fp = find_fixed_point(g, x0 + d, tol=1e-12, **kw)
                    counts.append(f"{fp.iterations}{'' if fp.converged else '!'}")
                except Exception as exc:         # (a guess from which the walker falls)
                    counts.append(type(exc).__name__[:6])
            print(f"  {name:16s} {np.array2string(d, precision=3):>28s} "
                  f"{counts[0]:>6s} {counts[1]:>8s} {counts[2]:>8s} {counts[3]:>6s}")
    print("  (! not converged)")


def convergence(refs):
    print("== multipliers from the exact Jacobian against dt, and Richardson's extrapolation")
    for name, (params, x0, truth) in refs.items():
        order = 2
        lams = []
        for dt in DTS:
            t = time.perf_counter()
            w, f, fp = gait(params, x0, dt)
            lam = multipliers_exact(f, fp.x).values
            lams.append(lam[0])
            print(f"  {name:16s} dt {dt:7.2e}  lambda {lam[0]:.12f}  error "
                  f"{match_distance(lam, truth):.3e}  ({time.perf_counter() - t:.1f} s)")
        e = [abs(lam - truth[0]) for lam in lams]
        print(f"  {'':16s} error ratios per halving: {e[0] / e[1]:.3f}, {e[1] / e[2]:.3f} "
              f"(order {order}: {2 ** order})")
        k = 2.0 ** order
        r1 = [(k * lams[i + 1] - lams[i]) / (k - 1) for i in range(2)]
        r2 = (2 * k * r1[1] - r1[0]) / (2 * k - 1)
        print(f"  {'':16s} Richardson (order {order}): {abs(r1[0] - truth[0]):.2e}, "
              f"{abs(r1[1] - truth[0]):.2e}; both orders {order} and {order + 1}: "
              f"{abs(r2 - truth[0]):.2e}")


def doublings(refs):
    """The simplest walker's period doublings (foot mass ratio 1e-3, dt 1e-3) by continuation
    with the exact Jacobians (the period-1 gait from slope 0.009, the period-2 and -4 orbits
    born at its doublings), and the ratio of their spacings beside Feigenbaum's 4.669."""
    from planarsim.analysis import MapPool, continue_branch, period_doubling_branch
    from walkers.passive.family import WalkerFamily
    print("== the simplest walker's period doublings, continuation with exact Jacobians "
          "(dt 1e-3, foot mass ratio 1e-3)")
    fam = WalkerFamily("simplest-walker", "slope", dt=1e-3, base=SimplestParams())
    t = time.perf_counter()
    with MapPool(fam, workers=1, exact=True) as pool:
        branches = [continue_branch(pool, fam.guess(0.009), 0.009, 0.0195, 24, param="slope")]
        while branches[-1].first("period-doubling") is not None and branches[-1].period < 4:
            pd = branches[-1].first("period-doubling")
            branches.append(period_doubling_branch(pool, pd, 0.0195, 12, param="slope"))
    found = [br.first("period-doubling") for br in branches]
    for br, pd in zip(branches, found):
        where = f"at slope {pd.p:.9f} rad (bracket {pd.bracket:.1e})" if pd else "not found"
        print(f"  period {br.period} -> {2 * br.period}: {where}")
    slopes = [pd.p for pd in found if pd is not None]
    if len(slopes) == 3:
        print(f"  spacing ratio (p2 - p1) / (p3 - p2) = "
              f"{(slopes[1] - slopes[0]) / (slopes[2] - slopes[1]):.3f} (Feigenbaum's delta "
              f"4.669 is the limit of such ratios)")
    print(f"  ({time.perf_counter() - t:.0f} s, {pool.evaluations} map evaluations)")


PARTS = {"check": check, "newton": newton, "convergence": convergence, "doublings": doublings}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", choices=sorted(PARTS), default=list(PARTS))
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    refs = references()
    for part in args.only:
        PARTS[part](refs)
    print(f"({time.perf_counter() - t0:.1f} s wall)")


if __name__ == "__main__":
    main()
