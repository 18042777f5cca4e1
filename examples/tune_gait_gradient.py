"""Tune the Simple Biped's gait by gradient ascent on its periodic gait (the step map's fixed
point), and score the result with the CMA-ES tuner's own objective (a walk from rest).

    python examples/tune_gait_gradient.py                       # 4 gains, 6 gradients, ~4 min
    python examples/tune_gait_gradient.py --names step_length0 clearance --iterations 3

Prints each gradient step (score of the periodic gait, gradient norm, largest parameter move
in units of its bounds), then the start and the tuned parameters side by side: the periodic
gait's speed, cost of transport and spectral radius, and `planarsim tune`'s score of a
10 s walk from rest with each (walkers/simple_biped/objective.py).
"""
from __future__ import annotations

import argparse

from walkers.gait_gradient import tune_gait
from walkers.simple_biped import objective

NAMES = ("ds_kd", "energy_gain", "ss_kd", "step_length0")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--names", nargs="+", default=list(NAMES), help="tunable fields to tune")
    ap.add_argument("--iterations", type=int, default=6, help="gradient steps")
    args = ap.parse_args(argv)

    def show(h):
        print(f"  step {h['iteration']}: score {h['score']:.4f}, |gradient| "
              f"{h['gradient_norm']:.3f}, largest move {h['largest_move']:.4f} "
              f"({h['evaluations']} fixed points)", flush=True)

    print(f"Simple Biped: gradient ascent on the periodic gait over {', '.join(args.names)}")
    r = tune_gait("simple-biped", names=args.names, iterations=args.iterations, progress=show)
    if r.stopped:
        print(f"  stopped: {r.stopped}")
    start, tuned = objective.Params(), objective.Params(**r.best_params)
    walks = [objective.evaluate(p) for p in (start, tuned)]
    print(f"  {'':34s} {'start':>10s} {'tuned':>10s}")
    for n in r.names:
        print(f"  {n:34s} {getattr(start, n):10.4g} {getattr(tuned, n):10.4g}")
    rows = (("periodic gait: score", r.start.score, r.best.score),
            ("periodic gait: speed [m/s]", r.start.speed, r.best.speed),
            ("periodic gait: cost of transport", r.start.cost_of_transport,
             r.best.cost_of_transport),
            ("periodic gait: spectral radius", r.start.spectral_radius, r.best.spectral_radius),
            ("10 s walk from rest: score", walks[0]["score"], walks[1]["score"]),
            ("10 s walk from rest: cost of transport", walks[0]["cost_of_transport"],
             walks[1]["cost_of_transport"]))
    for label, a, b in rows:
        print(f"  {label:34s} {a:10.4f} {b:10.4f}")
    print(f"  ({r.evaluations} fixed points in {r.seconds:.0f} s; fell: start "
          f"{walks[0]['fell']}, tuned {walks[1]['fell']})")
    return 0 if r.best_score > r.start_score else 1


if __name__ == "__main__":
    raise SystemExit(main())
