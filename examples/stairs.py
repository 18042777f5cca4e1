"""The Simple Biped climbs five 10 cm stairs built from static boxes.

Each stair is a box fixed in the world (``add_shape(None, "box", ...)``); the biped's feet are
disks that touch them. Its controller is the one it walks with on flat ground, terrain-blind:
it guesses each strike height from the slope seen between its feet, and a swing clearance of
0.15 leg lengths (default 0.08) lifts the swing foot over each 10 cm riser.

    python examples/stairs.py [--duration 15] [--gif docs/gifs/stairs.gif]
"""
import argparse
import dataclasses

import walkers
from walkers.simple_biped.params import SimpleBipedParams

RISE, TREAD, N_STAIRS = 0.10, 0.6, 5     # [m], [m], stairs
FIRST = 1.5                              # x of the first riser [m]
LANDING = 30.0                           # length of the top landing [m]


def add_stairs(builder):
    """Five stairs: box k, fixed in the world, from its riser to the landing's end, (k + 1) RISE
    high."""
    end = FIRST + N_STAIRS * TREAD + LANDING
    for k in range(N_STAIRS):
        start = FIRST + k * TREAD
        height = (k + 1) * RISE
        builder.add_shape(None, "box", ((start + end) / 2, height / 2), end - start, height,
                          mu=1.0, name=f"stair{k}")


def main(duration=15.0, gif=None, clearance=0.15):
    """Walk up; returns (stairs climbed, summary dict): a stair counts once both feet have
    stood on it or higher (their height above it within 2 cm)."""
    params = dataclasses.replace(SimpleBipedParams(), clearance=clearance)
    traj, summary, model = walkers.load("simple-biped").simulate(duration, gait="walk",
                                                                  params=params, extras=add_stairs)
    feet_y = traj.q[:, 1:3, 1]
    top = N_STAIRS * RISE
    climbed = 0
    for k in range(1, N_STAIRS + 1):
        if ((feet_y >= k * RISE - 0.02).all(axis=1)).any():
            climbed = k
    summary["on_top"] = bool((feet_y[-1] >= top - 0.02).all())
    if gif:
        from planarsim.render import export_animation
        export_animation(traj, model, gif, fps=10, speed=1.5, duration=min(duration, 10.0),
                         size=(3.6, 2.0), colors=32)
    return climbed, summary


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=15.0)
    ap.add_argument("--gif", default=None, help="write an animation here")
    args = ap.parse_args()
    climbed, summary = main(args.duration, args.gif)
    print(f"climbed {climbed} of {N_STAIRS} stairs; on top: {summary['on_top']}; walked "
          f"{summary['distance']:.2f} m; fell: {summary['fell']}; audit {summary['audit']}")
