"""Run the Simple Biped over hills, then export an animation (GIF or MP4) and summary plots.

    python examples/export_animation_and_plots.py [--duration 8] [--out walk.mp4] [--plot walk.png]
"""
import argparse

import planarsim as ps
from planarsim.render import export_animation, plot_summary
import walkers


def main(duration=8.0, out="walk.gif", plot="walk.png", fps=20, speed=1.0):
    biped = walkers.load("simple-biped")
    traj, summary, model = biped.simulate(duration, gait="walk", terrain=ps.terrain.default_hills())
    export_animation(traj, model, out, fps=fps, speed=speed)   # speed < 1: slow motion
    plot_summary(traj, model, plot)                            # angles, energy, power, contact modes
    traj.save(out.rsplit(".", 1)[0] + ".npz")                  # the data behind the pictures
    return traj, summary


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=8.0)
    ap.add_argument("--out", default="walk.gif")
    ap.add_argument("--plot", default="walk.png")
    ap.add_argument("--speed", type=float, default=1.0, help="playback speed (0.25 = slow motion)")
    a = ap.parse_args()
    traj, summary = main(a.duration, a.out, a.plot, speed=a.speed)
    print(summary)
