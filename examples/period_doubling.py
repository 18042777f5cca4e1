"""The simplest walker's route to chaos (Garcia, Chatterjee, Ruina, Coleman 1998): a stable
period-one gait on a shallow slope, period doubling as the slope grows, 2 -> 4, chaos, then
falling. Continuation of the period-1, -2 and -4 gaits with their multipliers, a brute-force
bifurcation diagram over the same slopes, all on every core.

    python examples/period_doubling.py --out docs/figures            # ~10 min on 2 cores
    python examples/period_doubling.py --slopes 40 --transient 80     # quicker, coarser
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from planarsim.analysis import (MapPool, StepMapError, bifurcation_diagram, continue_branch,
                                period_doubling_branch, plot_bifurcation_diagram,
                                plot_branch_multipliers)
from walkers.passive import SimplestParams
from walkers.passive.family import WalkerFamily


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dt", type=float, default=1e-3, help="step size [s]")
    ap.add_argument("--beta", type=float, default=1e-3, help="foot mass ratio")
    ap.add_argument("--range", default="0.009:0.0195", help="slopes A:B [rad]")
    ap.add_argument("--points", type=int, default=24, help="continuation points (period 1)")
    ap.add_argument("--slopes", type=int, default=120, help="slopes of the brute-force diagram")
    ap.add_argument("--transient", type=int, default=150, help="diagram: steps dropped")
    ap.add_argument("--keep", type=int, default=32, help="diagram: section values kept")
    ap.add_argument("--out", default="out/period_doubling", help="folder for figures and CSV")
    ap.add_argument("--exact", action="store_true",
                    help="multipliers from the step map's exact Jacobian instead of fits (slower)")
    a = ap.parse_args(argv)
    lo, hi = (float(v) for v in a.range.split(":"))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    fam = WalkerFamily("simplest-walker", "slope", dt=a.dt, base=SimplestParams(foot_mass_ratio=a.beta))
    t0 = time.perf_counter()
    with MapPool(fam, exact=a.exact) as pool:
        branches = [continue_branch(pool, fam.guess(lo), lo, hi, a.points, param="slope")]
        while branches[-1].first("period-doubling") is not None and branches[-1].period < 4:
            pd = branches[-1].first("period-doubling")
            try:
                branches.append(period_doubling_branch(pool, pd, hi, max(6, a.points // 2), param="slope"))
            except StepMapError as e:
                print(f"  period-{2 * pd.period} orbit not followed: {e}")
                break
        for br in branches:
            print(f"period-{br.period} gait: {len(br.points)} points, slope {br.p[0]:.5f} .. "
                  f"{br.p[-1]:.5f} ({br.end})")
            for bf in br.bifurcations:
                print(f"  {bf.kind} at slope {bf.p:.6f} rad (bracket {bf.bracket:.1e})")
        print(f"  continuation: {time.perf_counter() - t0:.0f} s")
        t1 = time.perf_counter()
        # each slope from the period-1 gait nearest in slope (continued, or its last point)
        d = bifurcation_diagram(pool, np.linspace(lo, hi, a.slopes), branches[0].nearest,
                                a.transient, a.keep, param="slope")
        print(f"  brute-force diagram: {a.slopes} slopes x {a.transient + a.keep} steps, "
              f"{time.perf_counter() - t1:.0f} s on {pool.workers} workers")
    per = d.periods(1e-6)
    changes = [(p, k) for i, (p, k) in enumerate(zip(d.p, per)) if i == 0 or k != per[i - 1]]
    print("apparent period along the diagram (0: none up to 16, chaos; -1: fell):")
    print("  " + ", ".join(f"{k} from {p:.5f}" for p, k in changes))
    onset = d.fall_onset()
    print(f"falls from slope {onset:.5f} rad" if onset is not None else "no falls in the range")
    bifs = [bf for br in branches for bf in br.bifurcations if bf.kind == "period-doubling"]
    plot_bifurcation_diagram(d, 0, out / "simplest_period_doubling.png", branches=branches,
                             bifurcations=bifs, label="stance angle theta after heel strike [rad]",
                             title=f"simplest walker (beta {a.beta:g}, dt {a.dt:g} s)")
    plot_branch_multipliers(branches[0], out / "simplest_multipliers_branch.png")
    d.to_csv(out / "simplest_diagram.csv", 0, "theta")
    from planarsim.analysis import write_csv
    write_csv(out / "simplest_branches.csv", [r for br in branches for r in br.rows(fam.names)])
    print("wrote", ", ".join(str(out / n) for n in ("simplest_period_doubling.png",
          "simplest_multipliers_branch.png", "simplest_diagram.csv", "simplest_branches.csv")))


if __name__ == "__main__":
    main()
