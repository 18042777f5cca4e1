"""Benchmark: the planar quadruped (A1-like robot dog) trotting 60 s on flat ground through its
compiled rollout (physics + puppet/IK controller + recording every 10 steps), on one core.

Prints first-call time (numba compile or cache load), then the warm real-time factor
(simulated seconds per wall second), steps per second, distance, steps taken and falls; median
and spread of `--repeats` runs, each from the same standing start, for both contact-mode
strategies.

    python benchmarks/quadruped.py [--seconds 60] [--repeats 5] [--speed 0.3] [--gait walk]
"""
import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from walkers import quadruped as qd  # noqa: E402


def one_run(seconds, gait, speed, strategy):
    dog = qd.Quadruped(gait=gait, speed=speed, strategy=strategy)
    t0 = time.perf_counter()
    dog.run(seconds)
    wall = time.perf_counter() - t0
    return wall, dog.summary(), int(dog.state.step[0])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated seconds per run")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--speed", type=float, default=0.3, help="commanded speed [m/s]")
    ap.add_argument("--gait", default="walk", choices=qd.GAITS)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    one_run(0.01, args.gait, args.speed, "all")
    print(f"first call (compile or cache load): {time.perf_counter() - t0:.2f} s")
    for strategy in ("all", "alternating"):
        walls, summary, n = [], None, 0
        for _ in range(args.repeats):
            wall, summary, n = one_run(args.seconds, args.gait, args.speed, strategy)
            walls.append(wall)
        walls = np.array(walls)
        med = float(np.median(walls))
        print(f"{strategy:11s}: {args.seconds:g} s {args.gait} at {args.speed:g} m/s: real-time factor "
              f"{summary['time'] / med:,.1f}x  ({n / med:,.0f} steps/s; wall median {med:.2f} s, "
              f"min {walls.min():.2f}, max {walls.max():.2f}); distance {summary['distance']:.2f} m, "
              f"mean speed {summary['mean_speed']:.3f} m/s, pair steps {summary['steps']}, "
              f"falls {summary['falls']}, max pitch {summary['max_pitch_deg']:.2f} deg")


if __name__ == "__main__":
    main()
