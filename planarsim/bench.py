"""Benchmark runner: steps per second of the named scenes (warm, median of repeats).

    planarsim bench                     # all scenes (same as python benchmarks/run.py)
    planarsim bench chain4 rod_drop     # some
    planarsim bench --csv DIR           # also write DIR/<machine>/<scene>.csv

Each scene is built, compiled (first-call time printed), warmed up, snapshotted, then timed
from the snapshot `--repeats` times: compiled multi-step run, and a Python loop of single steps.
"""
from __future__ import annotations

import argparse
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import planarsim as ps
from .bench_scenes import SCENES


def time_scene(name, build, n_steps, repeats=5, python_steps=2000):
    model = build()
    sim = ps.Simulator(model)
    t0 = time.perf_counter()
    sim.steps(1)
    first = time.perf_counter() - t0
    sim.step()
    snap = sim.snapshot()
    compiled = []
    for _ in range(repeats):
        sim.restore(snap)
        t0 = time.perf_counter()
        sim.steps(n_steps)
        compiled.append(n_steps / (time.perf_counter() - t0))
    python = []
    for _ in range(max(1, repeats // 2)):
        sim.restore(snap)
        t0 = time.perf_counter()
        for _ in range(python_steps):
            sim.step()
        python.append(python_steps / (time.perf_counter() - t0))
    return dict(scene=name, bodies=model.n_body, first_call_s=first,
                steps_per_s=statistics.median(compiled), spread=(min(compiled), max(compiled)),
                python_steps_per_s=statistics.median(python))


def main(argv=None):
    ap = argparse.ArgumentParser(prog="planarsim bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", help=f"scenes to run (default all): {', '.join(SCENES)}")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--csv", metavar="DIR", default=None, help="write DIR/<machine>/<scene>.csv")
    args = ap.parse_args(argv)
    names = args.scenes or list(SCENES)
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        ap.error(f"unknown scene(s) {unknown}; choose from {list(SCENES)}")
    print(f"{'scene':16s} {'bodies':>6s} {'first call':>10s} {'steps/s (median, min-max)':>34s} {'python step/s':>14s}")
    rows = []
    for name in names:
        build, n = SCENES[name]
        r = time_scene(name, build, n, args.repeats)
        rows.append(r)
        print(f"{name:16s} {r['bodies']:6d} {r['first_call_s']:9.2f}s {r['steps_per_s']:12,.0f} "
              f"({r['spread'][0]:,.0f}-{r['spread'][1]:,.0f}) {r['python_steps_per_s']:14,.0f}", flush=True)
    chains = [r for r in rows if r["scene"].startswith("chain")]
    if len(chains) >= 3:
        n = np.array([r["bodies"] for r in chains], float)
        cost = np.array([1.0 / r["steps_per_s"] for r in chains])
        slope = np.polyfit(np.log(n), np.log(cost), 1)[0]
        print(f"chain cost per step ~ N^{slope:.2f} (log-log fit over N = {', '.join(str(int(x)) for x in n)})")
    if args.csv:
        out = Path(args.csv) / platform.node()
        out.mkdir(parents=True, exist_ok=True)
        for r in rows:
            (out / f"{r['scene']}.csv").write_text(
                "scene,bodies,first_call_s,steps_per_s,min,max,python_steps_per_s\n"
                f"{r['scene']},{r['bodies']},{r['first_call_s']:.3f},{r['steps_per_s']:.0f},"
                f"{r['spread'][0]:.0f},{r['spread'][1]:.0f},{r['python_steps_per_s']:.0f}\n")
        print(f"wrote {out}")


if __name__ == "__main__":
    sys.exit(main())
