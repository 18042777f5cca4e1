"""The simplest walker's basin of attraction (Schwab and Wisse 2001): which starts just after a
heel strike walk on to the period-one gait, over a grid of the stance leg's angle and rate,
on every core or on a dask cluster.

    python examples/basin_map.py --out docs/figures                   # 256 x 256, ~3 min on 2 cores
    python examples/basin_map.py --size 32                            # quick and coarse
    python examples/basin_map.py --rate=-0.3:-0.1                     # (a negative range: with =)
    python examples/basin_map.py --scheduler tcp://host:8786          # on a dask cluster

Each cell starts with the legs as a heel strike leaves them (swing angle 2 theta, its rate
theta_dot (1 - cos 2 theta): Garcia et al. 1998) and walks up to --steps steps, until it comes
within --tol of the gait or falls. Writes simplest_basin.png (cells that reach the gait in
colour, the others by the steps they survived) and prints the share that reaches the gait.
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from planarsim.analysis import MapPool, basin_of_attraction, find_fixed_point, plot_basin
from walkers.passive.family import WalkerFamily, initial_guess
from walkers.passive import SimplestParams


def heel_strike_state(theta, theta_dot):
    """Section coordinates of a start just after a heel strike (module docstring)."""
    return [theta, theta_dot, 2.0 * theta, theta_dot * (1.0 - math.cos(2.0 * theta))]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=256, help="grid cells per side")
    ap.add_argument("--theta", default="0.12:0.30", help="stance angles A:B [rad]")
    ap.add_argument("--rate", default="-0.35:-0.10", help="stance rates A:B [sqrt(g / l)]")
    ap.add_argument("--slope", type=float, default=0.009, help="slope [rad]")
    ap.add_argument("--dt", type=float, default=2e-3, help="step size [s]")
    ap.add_argument("--steps", type=int, default=20, help="steps walked from each cell at most")
    ap.add_argument("--tol", type=float, default=1e-3, help="within this of the gait: reached")
    ap.add_argument("--workers", type=int, default=None,
                    help="processes (default: every core); with --scheduler, chunks per dask thread")
    ap.add_argument("--scheduler", default=None, help="dask scheduler address (tcp://host:port)")
    ap.add_argument("--out", default=".", help="directory of the figure")
    a = ap.parse_args(argv)
    if a.size < 2:
        ap.error(f"--size {a.size} must be at least 2")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (t0, t1), (r0, r1) = (map(float, s.split(":")) for s in (a.theta, a.rate))
    family = WalkerFamily("simplest-walker", "slope", dt=a.dt)
    t = time.perf_counter()
    gait = find_fixed_point(family(a.slope), initial_guess("simplest-walker",
                                                           SimplestParams(slope=a.slope)))
    if not gait.converged:
        raise SystemExit(f"no period-one gait at slope {a.slope} (residual {gait.residual:.2g})")
    print(f"gait at slope {a.slope}: x = {np.array2string(gait.x, precision=4)}, "
          f"multipliers |.| <= {np.max(np.abs(gait.multipliers)):.3f}")
    thetas, rates = np.linspace(t0, t1, a.size), np.linspace(r0, r1, a.size)
    step = max(1, a.size * a.size // 20)

    def progress(done, total):
        if done % step == 0 or done == total:
            print(f"  {done} / {total} cells ({time.perf_counter() - t:.0f} s)", flush=True)

    with MapPool(family, workers=a.workers, scheduler=a.scheduler) as pool:
        basin = basin_of_attraction(pool, a.slope, thetas, rates, heel_strike_state, gait.x,
                                    n_steps=a.steps, tol=a.tol, names=("theta", "theta_dot"),
                                    progress=progress)
    path = out / "simplest_basin.png"
    plot_basin(basin, path, attractor=gait.x[:2],
                      title=f"simplest walker, slope {a.slope}")
    print(f"{a.size} x {a.size} cells: {100 * basin.fraction:.1f}% reach the gait, "
          f"{100 * np.mean(basin.fell):.1f}% fall within {a.steps} steps "
          f"({time.perf_counter() - t:.0f} s, {pool.evaluations} steps); wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
