"""Benchmark: animation export, in seconds per frame, of the command line's default animation
(10 s at 20 fps, 640x360 GIF) of the Simple Biped and the Cornell Ranger.

Prints, per walker and number of drawing processes, the wall and CPU milliseconds per frame
(best of `--repeats`; CPU counts the drawing processes too) and the file size. The machine's
other load shows in the wall time: compare runs made side by side.

    python benchmarks/render_speed.py [--repeats 3] [--workers 1 2] [--format gif]
"""
import argparse
import os
import tempfile
import time
from pathlib import Path

import walkers
from planarsim.render import export_animation
from walkers.gallery import gait_names


def measure(traj, model, names, out, workers, repeats):
    best = None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), os.times()
        export_animation(traj, model, out, fps=20, progress=False, label_names=names, workers=workers)
        wall, c1 = time.perf_counter() - t0, os.times()
        cpu = sum(getattr(c1, a) - getattr(c0, a) for a in ("user", "system", "children_user", "children_system"))
        best = min(best or (float("inf"), 0.0), (wall, cpu))
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--format", default="gif", choices=["gif", "mp4", "html"])
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as d:
        for name in ("simple-biped", "ranger"):
            mod = walkers.load(name)
            traj, _, model = mod.simulate(duration=10.0)
            names = gait_names(mod)
            out = Path(d) / f"{name}.{args.format}"
            export_animation(traj, model, out, fps=20, duration=0.5, progress=False, label_names=names)  # warm
            for workers in args.workers:
                wall, cpu = measure(traj, model, names, out, workers, args.repeats)
                n = 200
                print(f"{name:13s} workers={workers}: {1e3 * wall / n:5.1f} ms/frame wall, "
                      f"{1e3 * cpu / n:5.1f} ms/frame CPU, {out.stat().st_size / 1e6:.3f} MB", flush=True)


if __name__ == "__main__":
    main()
