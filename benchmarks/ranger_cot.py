"""Ranger's cost of transport against speed, default and tuned (``--params efficient``) gaits.

For each gait, the speed the push-off feedback aims at (``target_speed``, the gait's speed
setting) is swept; each point is one walk on flat ground of --duration seconds from the
walker's start, summarised as ``planarsim run ranger`` summarises it: speed over whole steps
(``step_speed``) and electrical cost of transport (``cost_of_transport_electrical``: positive
electrical energy of the three motors per weight and distance, first to last heel strike). A
walk that falls is listed and left out of the plot.

    python benchmarks/ranger_cot.py [--duration 40] [--points 9] [--out docs/figures/ranger_cot.png]

About a minute and a half on 2 cores at the defaults (18 walks of 40 s).
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

GAITS = ("default", "efficient")


def gait_params(gait: str):
    """RangerParams of the default gait or of the shipped set `gait` (walkers/ranger/<gait>.json)."""
    import walkers.ranger as ranger
    from walkers.common.params import load_values
    from walkers.ranger.params import RangerParams
    if gait == "default":
        return RangerParams()
    values = load_values(Path(ranger.__file__).parent / f"{gait}.json", RangerParams)
    return dataclasses.replace(RangerParams(), **values)


def walk(gait: str, target_speed: float, duration: float) -> dict:
    """One walk of `duration` [s] of `gait` with target_speed [m/s]: its summary's figures."""
    from walkers.ranger.rollout import simulate
    p = dataclasses.replace(gait_params(gait), target_speed=float(target_speed))
    _, s, _ = simulate(duration, gait="walk", params=p, record_every=1000)
    return dict(gait=gait, target_speed=float(target_speed), fell=bool(s["fell"]), steps=int(s["steps"]),
                speed=float(s["step_speed"]), cot_electrical=float(s["cost_of_transport_electrical"]),
                cot_total=float(s["cost_of_transport"]))


def sweep(targets, duration: float, workers: int = 2) -> list:
    jobs = [(g, t) for g in GAITS for t in targets]
    with ProcessPoolExecutor(workers) as pool:
        futures = [pool.submit(walk, g, t, duration) for g, t in jobs]
        return [f.result() for f in futures]


def plot(rows, path: Path, duration: float) -> None:
    """Electrical cost of transport (solid) and the same with the computers' 4.5 W (dashed)
    against speed, points joined in order of target_speed (the first and last labelled)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.6, 3.8), dpi=100)
    for gait, marker, color, label in (("default", "o", "C0", "default gait"),
                                       ("efficient", "s", "C1", "tuned (--params efficient)")):
        ok = [r for r in rows if r["gait"] == gait and not r["fell"] and math.isfinite(r["cot_electrical"])]
        ok.sort(key=lambda r: r["target_speed"])
        if not ok:
            continue
        v = [r["speed"] for r in ok]
        ax.plot(v, [r["cot_electrical"] for r in ok], marker + "-", color=color, ms=3.5, label=label)
        ax.plot(v, [r["cot_total"] for r in ok], "--", color=color, lw=0.8, alpha=0.6)
        for r, dy in ((ok[0], -12), (ok[-1], 6)):
            ax.annotate(f"{r['target_speed']:.2f}", (r["speed"], r["cot_electrical"]), fontsize=7,
                        color=color, textcoords="offset points", xytext=(4, dy))
    ax.axhline(0.28, color="0.5", lw=0.8, ls=":")
    ax.text(0.01, 0.28, " robot's 0.28 (with computers)", color="0.4", fontsize=7, ha="left",
            va="bottom", transform=ax.get_yaxis_transform())
    ax.set_xlabel("speed over whole steps [m/s]")
    ax.set_ylabel("cost of transport [-]")
    ax.set_title(f"Ranger, flat ground, {duration:g} s walks: target_speed swept (labels)\n"
                 "solid: electrical (motors); dashed: with the computers' 4.5 W", fontsize=8)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper center")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--duration", type=float, default=40.0, help="seconds per walk (default 40)")
    ap.add_argument("--points", type=int, default=19, help="target speeds per gait (default 19)")
    ap.add_argument("--range", default="0.36:0.9", help="target_speed range A:B [m/s] (default 0.36:0.9)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default="docs/figures/ranger_cot.png", help="PNG to write ('' for none)")
    a = ap.parse_args(argv)
    lo, hi = (float(v) for v in a.range.split(":"))
    t0 = time.perf_counter()
    rows = sweep(np.linspace(lo, hi, a.points), a.duration, a.workers)
    print(f"{'gait':10s} {'target [m/s]':>12} {'speed [m/s]':>11} {'CoT el.':>8} {'CoT total':>9} steps")
    for r in rows:
        print(f"{r['gait']:10s} {r['target_speed']:12.3f} {r['speed']:11.3f} {r['cot_electrical']:8.3f} "
              f"{r['cot_total']:9.3f} {r['steps']:5d}{'  FELL' if r['fell'] else ''}")
    if a.out:
        plot(rows, Path(a.out), a.duration)
        print(f"wrote {a.out}")
    print(f"({time.perf_counter() - t0:.0f} s)")
    return rows


if __name__ == "__main__":
    main()
