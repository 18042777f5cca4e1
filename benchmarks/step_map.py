"""Time of step-map evaluations and of a full finite-difference Jacobian (central, 2d
evaluations) for the passive walkers; every evaluation runs the compiled rollout.

    python benchmarks/step_map.py [--dt 1e-3] [--repeats 5]
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from planarsim.analysis import jacobian
from walkers.passive import PassiveWalker, RimlessParams, SimplestParams
from walkers.passive.rimless_wheel import closed_form
from walkers.passive.simplest import garcia_start


def bench(name, walker, x, repeats):
    f = walker.step_map()
    t0 = time.perf_counter()
    f(x)                                  # compile or load the cache
    first = time.perf_counter() - t0
    evals, jacs = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f(x)
        evals.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        jacobian(f, x, 1e-3)
        jacs.append(time.perf_counter() - t0)
    steps = int(round(walker.last_period / walker.dt))
    print(f"{name:16s} d={len(x)} dt={walker.dt:g} s  ~{steps} steps per map evaluation | first call "
          f"{first:6.2f} s | evaluation {statistics.median(evals) * 1e3:7.2f} ms | "
          f"{2 * len(x)}-evaluation Jacobian {statistics.median(jacs) * 1e3:7.1f} ms "
          f"(min {min(jacs) * 1e3:.1f}, max {max(jacs) * 1e3:.1f})")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dt", type=float, default=1e-3)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args(argv)
    bench("simplest-walker", PassiveWalker(SimplestParams(), dt=a.dt), garcia_start(), a.repeats)
    p = RimlessParams()
    bench("rimless-wheel", PassiveWalker(p, dt=a.dt), np.array([-closed_form(p)["omega_after"]]), a.repeats)


if __name__ == "__main__":
    main()
