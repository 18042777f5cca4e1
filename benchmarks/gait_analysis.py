"""Figures of the gait analysis (planarsim.analysis) on the passive walkers:

1. speed-up of a continuation on a MapPool: 1 worker vs all cores;
2. Floquet multipliers at the default eps ("auto") against dt for the simplest walker
   (against the independent scipy reference, beta -> 0), the compass gait (against the
   independent scipy reference, Goswami et al.'s model with the engine's leg inertia) and the
   rimless wheel (closed form eta^2);
3. the simplest walker's first period doubling and 2 -> 4 doubling against dt, with the
   same located on the scipy reference (beta -> 0);
3b. acceptance: what `planarsim analyze` locates at the walker's foot mass ratio (1e-3)
   against the scipy reference for that ratio, per dt, with the relative errors;
4. cost of transport over whole steps against the run's duration.

    python benchmarks/gait_analysis.py [--only speedup multipliers doubling acceptance cot]
"""
from __future__ import annotations

import argparse
import math
import time
import warnings

import numpy as np

from planarsim.analysis import (MapPool, MultiplierWarning, continue_branch, find_fixed_point,
                                match_distance, multipliers_with_error, period_doubling_branch)
from walkers.passive import CompassParams, PassiveWalker, RimlessParams, SimplestParams
from walkers.passive.family import WalkerFamily
from walkers.passive.reference import (compass_fixed_point, simplest_feet_doublings,
                                       simplest_fixed_point, simplest_map)

DTS = (1e-3, 5e-4, 2.5e-4, 1.25e-4)
BETA = 1e-5   # foot mass ratio: the reference is beta -> 0


def order(errs):
    return ["" if i == 0 else f"{math.log2(errs[i - 1] / errs[i]):.2f}" for i in range(len(errs))]


def speedup():
    print("== continuation speed-up (simplest walker, slope 0.009 -> 0.0145, 8 points, dt 1e-3)")
    fam = WalkerFamily("simplest-walker", "slope", dt=1e-3)
    times = {}
    for workers in (1, 2):
        with MapPool(fam, workers=workers, exact=False) as pool:
            pool.evaluate(fam.guess(0.009)[None, :], 0.009)   # numba cache loaded
            t0 = time.perf_counter()
            br = continue_branch(pool, fam.guess(0.009), 0.009, 0.0145, points=8, param="slope")
            times[workers] = time.perf_counter() - t0
            print(f"  {workers} worker(s): {times[workers]:6.1f} s, {br.evaluations} evaluations, {br.end}")
    print(f"  speed-up on 2 cores: {times[1] / times[2]:.2f}x")
    # how many cores the machine really gives now: one batch of 128 independent evaluations
    from planarsim.analysis import central_points
    X = np.concatenate([central_points(fam.guess(0.009), h) for h in 1e-4 * 0.5 ** np.arange(16)])
    raw = {}
    for workers in (1, 2):
        with MapPool(fam, workers=workers, exact=False) as pool:
            pool.evaluate(X[:3], 0.009)
            t0 = time.perf_counter()
            pool.evaluate(X, 0.009)
            raw[workers] = time.perf_counter() - t0
    print(f"  one batch of {len(X)} evaluations: {raw[1]:.2f} s on 1 worker, {raw[2]:.2f} s on 2 "
          f"({raw[1] / raw[2]:.2f}x; near 1x means the second core is busy with other work)")


def multipliers():
    print("== multipliers at the default eps ('auto') against dt; error = largest |lambda - ref|")
    ref = simplest_fixed_point(0.009)
    ref_c = compass_fixed_point(CompassParams())
    print(f"  compass-gait scipy reference: x* = {np.array2string(ref_c['x'], precision=8)}, "
          f"period {ref_c['period']:.6f} s, step {ref_c['step_length']:.6f} m, "
          f"multipliers {np.array2string(ref_c['multipliers'], precision=8)}")
    rows = {"simplest-walker": [], "compass-gait": [], "rimless-wheel": []}
    from walkers.passive.compass_gait import default_start
    from walkers.passive.rimless_wheel import closed_form
    rp = RimlessParams()
    eta2 = closed_form(rp)["eta"] ** 2
    for dt in DTS:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", MultiplierWarning)
            w = PassiveWalker(SimplestParams(foot_mass_ratio=BETA), dt=dt)
            fp = find_fixed_point(w.step_map(), ref["x"], tol=1e-10, eps=1e-4, exact=False)
            m = multipliers_with_error(w.step_map(), fp.x)
            rows["simplest-walker"].append((dt, m, match_distance(m.values[:2], ref["multipliers"][:2])))
            w = PassiveWalker(CompassParams(), dt=dt)
            fp = find_fixed_point(w.step_map(), default_start(), tol=1e-10, eps=1e-4, exact=False)
            m = multipliers_with_error(w.step_map(), fp.x)
            rows["compass-gait"].append((dt, m, match_distance(m.values, ref_c["multipliers"])))
            w = PassiveWalker(rp, dt=dt)
            fp = find_fixed_point(w.step_map(), [-closed_form(rp)["omega_after"]], tol=1e-10, eps=1e-4, exact=False)
            m = multipliers_with_error(w.step_map(), fp.x)
            rows["rimless-wheel"].append((dt, m, abs(m.values[0] - eta2)))
        n_warn = len(caught)
        if n_warn:
            print(f"  (dt {dt:g}: {n_warn} MultiplierWarning)")
    for name, r in rows.items():
        refname = {"simplest-walker": f"scipy reference (beta -> 0), engine beta {BETA:g}",
                   "compass-gait": "scipy reference (Goswami et al., leg gyration 1e-3 m)",
                   "rimless-wheel": "closed form eta^2"}[name]
        print(f"  {name}: against the {refname}")
        print(f"    {'dt [s]':>9} {'largest multiplier':>26} {'eps':>9} {'est. error':>10} {'error':>9} order")
        errs = [e for _, _, e in r]
        for (dt, m, e), o in zip(r, order(errs)):
            lam = m.values[0]
            print(f"    {dt:9.3g} {lam.real:+.6f}{lam.imag:+.6f}j {m.eps:9.2g} {m.error:10.1e} {e:9.2e} {o}")


def doubling():
    print(f"== simplest walker (beta {BETA:g}): period doublings against dt")
    t0 = time.perf_counter()
    with MapPool(simplest_map) as pool:
        br = continue_branch(pool, simplest_fixed_point(0.009)["x"], 0.009, 0.0154, points=9,
                             param="slope", p_tol=1e-8)
        x0 = br.x[-2]   # at slope 0.0146
        pd = br.first("period-doubling")
        b2 = period_doubling_branch(pool, pd, 0.0180, points=5, param="slope", tol=1e-9, p_tol=1e-8)
        pd2 = b2.first("period-doubling")
    ref = (pd.p, pd2.p if pd2 else math.nan)
    print(f"  scipy reference: 1 -> 2 at {ref[0]:.7f}, 2 -> 4 at {ref[1]:.7f} rad "
          f"({time.perf_counter() - t0:.0f} s)")
    out = []
    for dt in DTS:
        t0 = time.perf_counter()
        fam = WalkerFamily("simplest-walker", "slope", dt=dt, base=SimplestParams(foot_mass_ratio=BETA))
        with MapPool(fam, exact=False) as pool:
            br = continue_branch(pool, x0, 0.0146, 0.0154, points=3, param="slope", p_tol=1e-8)
            pd = br.first("period-doubling")
            b2 = period_doubling_branch(pool, pd, 0.0180, points=5, param="slope", p_tol=1e-8)
            pd2 = b2.first("period-doubling")
        out.append((dt, pd.p, pd2.p if pd2 else math.nan, pd.bracket, time.perf_counter() - t0))
    e1 = [abs(o[1] - ref[0]) for o in out]
    e2 = [abs(o[2] - ref[1]) for o in out]
    print(f"    {'dt [s]':>9} {'1 -> 2':>10} {'error':>9} order {'2 -> 4':>10} {'error':>9} order  time")
    for o, a, oa, b, ob in zip(out, e1, order(e1), e2, order(e2)):
        print(f"    {o[0]:9.3g} {o[1]:10.7f} {a:9.2e} {oa:>5} {o[2]:10.7f} {b:9.2e} {ob:>5} {o[4]:5.0f} s")


def acceptance():
    """`planarsim analyze simplest-walker --param slope` (the command's own calls: 5 points over
    0.0138:0.0182, the period-2 orbit followed; at dt <= 2.5e-4 only the period-1 branch over
    0.0138:0.0156, 4 points) against the scipy reference at the walker's foot mass ratio."""
    beta = SimplestParams().foot_mass_ratio
    t0 = time.perf_counter()
    ref = simplest_feet_doublings(beta)
    print(f"== analyze simplest-walker (foot mass ratio {beta:g}) against the scipy reference: "
          f"1 -> 2 at {ref[0]:.10f}, 2 -> 4 at {ref[1]:.10f} rad ({time.perf_counter() - t0:.0f} s)")
    print(f"    {'dt [s]':>9} {'1 -> 2':>13} {'rel. error':>11} order {'2 -> 4':>13} {'rel. error':>11} order  time")
    rows = []
    for dt in DTS:
        follow = dt >= 5e-4
        a, b, points = (0.0138, 0.0182, 5) if follow else (0.0138, 0.0156, 4)
        fam = WalkerFamily("simplest-walker", "slope", dt=dt)
        t0 = time.perf_counter()
        with MapPool(fam, exact=False) as pool:
            br = continue_branch(pool, fam.guess(a), a, b, points, param="slope")
            pd = br.first("period-doubling")
            p24 = math.nan
            if follow:
                b2 = period_doubling_branch(pool, pd, b, max(4, points // 2), param="slope")
                pd2 = b2.first("period-doubling")
                p24 = pd2.p if pd2 else math.nan
        rows.append((dt, pd.p, p24, time.perf_counter() - t0))
    e1 = [abs(r[1] / ref[0] - 1) for r in rows]
    e2 = [abs(r[2] / ref[1] - 1) for r in rows]
    o1, o2 = order(e1), order(e2)
    for r, a, oa, b, ob in zip(rows, e1, o1, e2, o2):
        print(f"    {r[0]:9.3g} {r[1]:13.10f} {a:11.2e} {oa:>5} {r[2]:13.10f} {b:11.2e} {ob:>5} {r[3]:5.0f} s")


def cot():
    import walkers
    print("== cost of transport over whole steps / sin(slope) against the run's duration")
    slopes = {"simplest-walker": SimplestParams().slope, "compass-gait": CompassParams().slope,
              "rimless-wheel": RimlessParams().slope}
    durs = (3.0, 4.1, 7.3, 10.0, 20.0)
    print(f"    {'walker':16s} " + " ".join(f"{d:>8g}s" for d in durs))
    for name, g in slopes.items():
        vals = [walkers.load(name).simulate(d)[1]["cost_of_transport"] / math.sin(g) for d in durs]
        print(f"    {name:16s} " + " ".join(f"{v:9.5f}" for v in vals))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="*", default=["speedup", "multipliers", "doubling", "acceptance", "cot"])
    a = ap.parse_args(argv)
    for name in a.only:
        globals()[name]()


if __name__ == "__main__":
    main()
