"""Thin fast spinning shapes against 5 cm walls and slabs: how many pass through (not a test).

The sweep of tests/physics/test_impenetrability.py (its generator, build_case, and judge)
over more seeds: boxes 1 cm x 5-20 cm, capsules of radius 0.5 cm and 5-20 cm, polygons 1-3 cm
across, thrown at 100-300 m/s and turning at 0-300 rad/s into a static 5 cm wall or a free
5 cm slab of 100 kg, at dt 1e-3 and 1e-2 s, each run for 0.03 s. Every seed builds the same
case on every machine (numpy's default_rng(seed)). Per family (the shape's kind) it counts:
  through   the shape's centre ended a step beyond the slab's mid-plane (passed through)
  overlap   the shape ended a step overlapping the slab by more than the audit's 1e-8 m
  gain      the kinetic energy rose above its start by more than 1e-12 of it
  audit     the engine's audit counted a depth violation
  raised    the engine stopped with an error naming why (not silent)
  split out a step used every time-of-impact split it may take (StepOptions.max_ccd_splits)
and lists every case that passed through or overlapped (rerun one with --only).

    python benchmarks/thin_walls.py                     # 600 seeds x 2 targets x 2 dt: 2,400
    python benchmarks/thin_walls.py --seeds 80          # the test's 320 cases
    python benchmarks/thin_walls.py --only 123:wall:0.01
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from planarsim.compiled import audit_counts  # noqa: E402
from planarsim.kernels.checks.audit import DEPTH_TOL  # noqa: E402
from planarsim.kernels.info import INFO_CCD_SPLITS  # noqa: E402
from tests.physics.test_impenetrability import (  # noqa: E402
    ENERGY_ROUNDING, RUN_TIME, _projectile, build_case, judge, kinetic_energy)

TARGETS = ("wall", "slab")
DTS = (1e-3, 1e-2)      # [s]


def family(seed) -> str:
    """The kind of case `seed`'s shape (build_case draws the slab's tilt, then the shape)."""
    rng = np.random.default_rng(seed)
    rng.uniform(-0.3, 0.3)
    return _projectile(rng)[0]


def run(seed, target, dt, max_splits=None) -> dict:
    """Run one case for RUN_TIME [s] (StepOptions.max_ccd_splits = max_splits, None: the
    default), judged after every step; returns its counts and worst values (through, depth
    [m], gain [-], audit depth count, raised message, steps whose splits ran out, fastest
    turn [rad/s])."""
    model, core, radius, slab = build_case(seed, target, dt)
    tilt0 = np.random.default_rng(seed).uniform(-0.3, 0.3)
    options = ps.StepOptions() if max_splits is None else ps.StepOptions(max_ccd_splits=max_splits)
    sim = ps.Simulator(model, options)
    e0 = kinetic_energy(model, sim.state.v)
    out = dict(seed=seed, target=target, dt=dt, family=family(seed), through=False, depth=0.0,
               gain=-math.inf, audit=0, raised="", split_out=0, omega=0.0, first_through=-1)
    shot = 0 if slab < 0 else 1
    for k in range(int(round(RUN_TIME / dt))):
        try:
            sim.step()
        except ps.SimulationDiverged as exc:
            out["raised"] = str(exc).splitlines()[0][:160]
            break
        centre, depth = judge(sim.state.q, core, radius, slab, tilt0)
        if centre > 0.0 and not out["through"]:
            out["first_through"] = k
        out["through"] = out["through"] or centre > 0.0
        out["depth"] = max(out["depth"], depth)
        out["gain"] = max(out["gain"], kinetic_energy(model, sim.state.v) / e0 - 1.0)
        out["omega"] = max(out["omega"], abs(float(sim.state.v[shot, 2])))
        out["split_out"] += int(sim.ws.info[INFO_CCD_SPLITS] >= sim.options.max_ccd_splits)
    out["audit"] = int(audit_counts(sim.ws)["depth"])
    return out


def cases(seeds):
    for dt in DTS:
        for target in TARGETS:
            for seed in range(seeds):
                yield seed, target, dt


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=600, help="seeds per target and dt (default 600)")
    ap.add_argument("--only", action="append", default=[], help="SEED:TARGET:DT (repeatable)")
    ap.add_argument("--max-splits", type=int, default=None,
                    help="StepOptions.max_ccd_splits (default: StepOptions' own, 16)")
    a = ap.parse_args(argv)
    todo = ([(int(s), t, float(d)) for s, t, d in (x.split(":") for x in a.only)] if a.only
            else list(cases(a.seeds)))
    t0 = time.perf_counter()
    results = [run(*c, max_splits=a.max_splits) for c in todo]
    wall = time.perf_counter() - t0
    print(f"{'family':9s} {'runs':>5s} {'through':>8s} {'overlap':>8s} {'gain':>5s} {'audit':>6s} "
          f"{'raised':>7s} {'split out':>10s}")
    for fam in ("box", "capsule", "polygon", "all"):
        rs = [r for r in results if fam in ("all", r["family"])]
        if not rs:
            continue
        print(f"{fam:9s} {len(rs):5d} {sum(r['through'] for r in rs):8d} "
              f"{sum(r['depth'] > DEPTH_TOL for r in rs):8d} "
              f"{sum(r['gain'] > ENERGY_ROUNDING for r in rs):5d} {sum(r['audit'] > 0 for r in rs):6d} "
              f"{sum(bool(r['raised']) for r in rs):7d} {sum(r['split_out'] > 0 for r in rs):10d}")
    bad = [r for r in results if r["through"] or r["depth"] > DEPTH_TOL or r["raised"]]
    for r in bad:
        print(f"  {r['seed']}:{r['target']}:{r['dt']:g} {r['family']:8s} through={r['through']} "
              f"(step {r['first_through']}) depth={r['depth']:.3g} m  |omega| up to "
              f"{r['omega']:.0f} rad/s  steps out of splits {r['split_out']}  {r['raised']}")
    print(f"{len(results)} runs in {wall:.1f} s (compile or cache load included)")
    # a step the run completed (an error stops the run there): what it records is silent
    silent = sum(r["through"] or r["depth"] > DEPTH_TOL for r in results)
    print("PASS: none passed through or into a slab silently" if silent == 0 else
          f"FAIL: {silent} of {len(results)} passed through or into a slab silently")
    return 0 if silent == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
