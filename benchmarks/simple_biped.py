"""Benchmark: the Simple Biped walking 60 s on flat ground (and on hills) through its compiled
rollout (physics + controller + recording every 10 steps), on one core.

Prints first-call time (numba compile or cache load), then the warm real-time factor
(simulated seconds per wall second), steps per second, steps taken and falls; median and
spread of `--repeats` runs, each from the same standing start.

    python benchmarks/simple_biped.py [--seconds 60] [--repeats 5] [--speed 1.0]
"""
import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from planarsim import terrain as T  # noqa: E402
from walkers import simple_biped as sb  # noqa: E402


def one_run(seconds, speed, terrain):
    w = sb.Run(gait="walk", speed=speed, terrain=terrain)
    t0 = time.perf_counter()
    w.run(seconds)
    wall = time.perf_counter() - t0
    return wall, w.summary(), int(w.state.step[0])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated seconds per run")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--speed", type=float, default=1.0, help="target walking speed [m/s]")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    one_run(0.01, args.speed, None)
    print(f"first call (compile or cache load): {time.perf_counter() - t0:.2f} s")
    for name, terr in (("flat", None), ("hills", T.default_hills())):
        walls, summary, n = [], None, 0
        for _ in range(args.repeats):
            wall, summary, n = one_run(args.seconds, args.speed, terr)
            walls.append(wall)
        walls = np.array(walls)
        med = float(np.median(walls))
        print(f"{name:5s}: {args.seconds:g} s walk at {args.speed:g} m/s target: "
              f"real-time factor {args.seconds / med:,.0f}x  ({n / med:,.0f} steps/s; wall median "
              f"{med * 1e3:.1f} ms, min {walls.min() * 1e3:.1f}, max {walls.max() * 1e3:.1f}); "
              f"distance {summary['distance']:.1f} m, mean speed {summary['mean_speed']:.3f} m/s, "
              f"walking steps {summary['steps']}, falls {summary['falls']}")


if __name__ == "__main__":
    main()
