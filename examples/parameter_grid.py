"""A batch of rollouts over a parameter grid: the Simple Biped's achieved speed against its
target speed and the hills' amplitude. Rollouts run compiled; the grid runs on a process pool.

    python examples/parameter_grid.py [--duration 20] [--workers 2]
"""
import argparse
import itertools
from concurrent.futures import ProcessPoolExecutor


import planarsim as ps
import walkers


def rollout(args):
    speed, amplitude, duration = args
    ter = ps.terrain.hills([amplitude], [6.0]) if amplitude > 0 else ps.terrain.flat()
    _, summary, _ = walkers.load("simple-biped").simulate(duration, gait="walk", terrain=ter, speed=speed)
    return speed, amplitude, summary["mean_speed"], summary["fell"]


def grid(speeds=(0.5, 1.0, 1.5), amplitudes=(0.0, 0.1), duration=20.0, workers=2):
    jobs = [(s, a, duration) for s, a in itertools.product(speeds, amplitudes)]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(rollout, jobs))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=20.0)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    print(f"{'target m/s':>10s} {'hills m':>8s} {'achieved m/s':>12s} {'fell':>5s}")
    for speed, amp, achieved, fell in grid(duration=a.duration, workers=a.workers):
        print(f"{speed:10.2f} {amp:8.2f} {achieved:12.3f} {str(fell):>5s}")
