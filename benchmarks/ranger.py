"""Benchmark: Cornell Ranger walking 60 s on level ground through its compiled rollout
(physics + controller + motor model + recording every 10 steps), on one core.

Prints first-call time (numba compile or cache load), then for each contact-mode strategy the
warm real-time factor (simulated seconds per wall second, median and spread of `--repeats`
runs from the same start), steps per second, and the walk's figures: steps, falls, speed, step
length and cost of transport (total with the 4.5 W overhead, motors' electrical, mechanical).
With ``--steps N`` it also walks until N steps (or a fall) and prints the same figures.

    python benchmarks/ranger.py [--seconds 60] [--repeats 5] [--steps 1000]
"""
import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from walkers.ranger import Run  # noqa: E402


def one_run(seconds, strategy, record_every=10):
    rs = Run(gait="walk", strategy=strategy, record_every=record_every)
    t0 = time.perf_counter()
    rs.run(seconds)
    return time.perf_counter() - t0, rs


def figures(rs):
    s = rs.summary()
    return (f"steps {s['steps']}, fell {s['fell']}, time {s['time']:.1f} s, distance {s['distance']:.2f} m, "
            f"mean speed {s['mean_speed']:.3f} m/s, step speed {s['step_speed']:.3f} m/s, "
            f"step length {s['step_length']:.3f} m, step period {s['step_period']:.3f} s\n"
            f"    CoT total (motors + 4.5 W) {s['cost_of_transport']:.3f}, motors electrical "
            f"{s['cost_of_transport_electrical']:.3f} (net {s['cost_of_transport_electrical_net']:.3f}), "
            f"mechanical positive {s['cost_of_transport_mechanical']:.3f} "
            f"(net {s['cost_of_transport_mechanical_net']:.4f}), mean push current {s['push_current_mean']:.2f} A")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated seconds per run")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--steps", type=int, default=0, help="also walk until this many steps")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    one_run(0.01, "alternating")
    print(f"first call (compile or cache load): {time.perf_counter() - t0:.2f} s")
    for strategy in ("alternating", "all"):
        walls, rs = [], None
        for _ in range(args.repeats):
            wall, rs = one_run(args.seconds, strategy)
            walls.append(wall)
        w = np.median(walls)
        n = int(rs.state.step[0])
        print(f"[{strategy}] {args.seconds:.0f} s walk: real-time factor {args.seconds / w:.1f} "
              f"(median of {args.repeats}, spread {args.seconds / max(walls):.1f}..{args.seconds / min(walls):.1f}), "
              f"{n / w:,.0f} steps/s")
        print("   ", figures(rs))
        if args.steps:
            rs = Run(gait="walk", strategy=strategy, record_every=1000)
            t1 = time.perf_counter()
            while rs.steps < args.steps and not rs.fell and rs.time < 10.0 * args.steps:
                rs.run(50.0)
            print(f"[{strategy}] walk to {args.steps} steps ({time.perf_counter() - t1:.1f} s wall):")
            print("   ", figures(rs))


if __name__ == "__main__":
    main()
