"""Benchmark: the planar quadruped (A1-like robot dog) trotting 60 s on flat ground through its
compiled rollout (physics + puppet/IK controller + recording every 10 steps), on one core.

Prints first-call time (numba compile or cache load), then the warm real-time factor
(simulated seconds per wall second), steps per second, distance, steps taken and falls; median
and spread of `--repeats` runs, each from the same standing start, for both contact-mode
strategies.

    python benchmarks/quadruped.py [--seconds 60] [--repeats 5] [--speed 0.3] [--gait walk]
    python benchmarks/quadruped.py --ablation      # what each feedback of the controller buys

--ablation runs, for the controller as shipped, without the Raibert placement (feet planted
under the hips: placement_gain = stance_time = 0) and "seed-like" (no placement and a loose
torso tie, torso_track_max = 0.5 m): the largest 0.2 s horizontal push at the torso (steps of
20 N, after 10 s of walking at --speed) survived for 4 s, forward and backward, and 20 s walks
at 0.5 / 0.6 / -0.4 / -0.5 m/s.
"""
import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from walkers import quadruped as qd  # noqa: E402


def one_run(seconds, gait, speed, strategy):
    dog = qd.Run(gait=gait, speed=speed, strategy=strategy)
    t0 = time.perf_counter()
    dog.run(seconds)
    wall = time.perf_counter() - t0
    return wall, dog.summary(), int(dog.state.step[0])


VARIANTS = {"shipped": {}, "no placement": dict(placement_gain=0.0, stance_time=0.0),
            "seed-like": dict(placement_gain=0.0, stance_time=0.0, torso_track_max=0.5)}


def largest_push(params, speed, sign, forces=range(20, 201, 20)):
    """Largest force [N] of a 0.2 s push survived (4 s without a fall), pushing in direction sign."""
    best = 0
    for f in forces:
        dog = qd.Run(params=params, gait="walk", speed=speed)
        dog.run(10.0)
        dog.state.ext_force[0, 0] = sign * f
        dog.run(0.2)
        dog.state.ext_force[0, 0] = 0.0
        dog.run(4.0)
        if dog.fell:
            break
        best = f
    return best


def ablation(speed):
    for name, kw in VARIANTS.items():
        p = qd.QuadrupedParams(**kw)
        fwd, back = largest_push(p, speed, 1), largest_push(p, speed, -1)
        runs = []
        for v in (0.5, 0.6, -0.4, -0.5):
            dog = qd.Run(params=p, gait="walk", speed=v)
            dog.run(20.0)
            s = dog.summary()
            runs.append(f"{v:+.1f}: " + (f"fell at {s['time']:.1f} s" if s["fell"] else f"{s['mean_speed']:+.3f} m/s"))
        print(f"{name:13s} pushes at {speed:g} m/s: forward {fwd} N, backward {back} N; 20 s walks "
              + "; ".join(runs))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated seconds per run")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--speed", type=float, default=0.3, help="commanded speed [m/s]")
    ap.add_argument("--gait", default="walk", choices=qd.GAITS)
    ap.add_argument("--ablation", action="store_true", help="push and speed limits per feedback variant")
    args = ap.parse_args(argv)
    if args.ablation:
        ablation(args.speed)
        return
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
