"""Random free-swinging pin chains at the extremes (not a test): how many stop with an error,
and whether any that run break a pin or gain energy unaudited.

    python benchmarks/free_chains.py                   # seeds 0 1 2, 60 chains each
    python benchmarks/free_chains.py --seeds 5 --chains 20

Each chain: 2 to 50 thin rods pinned end to end, the first to the world, no ground, under
gravity from rest at random angles; link masses spread over up to six decades (or
alternating heavy and light), lengths 0.01-2 m, dt 1e-5-0.05 s, run for min(1 s, 2000
steps). A run that raises is counted as a stop (with its error's first words); a run that
ends with a pin gap above 1e-9 m, or whose energy rose above 2 % of m g L unaudited, is BAD.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from planarsim import compiled  # noqa: E402
from planarsim.energy import total_energy  # noqa: E402
from benchmarks.stress_scenes import pin_gap  # noqa: E402

G = 9.81


def chain(rng):
    """(model, scale [J], dt, steps) of one random chain."""
    n = int(rng.choice([2, 3, 5, 10, 20, 50]))
    ratio = 10 ** rng.uniform(0, 6)
    masses = np.exp(rng.uniform(0, math.log(ratio), n))
    if rng.random() < 0.3:
        masses = np.where(np.arange(n) % 2 == 0, ratio, 1.0)
    lengths = 10 ** rng.uniform(-2, 0.3, n)
    angles = rng.uniform(-math.pi, math.pi, n)
    dt = float(10 ** rng.uniform(-5, math.log10(0.05)))
    b = ps.ModelBuilder(dt=dt, ground=None)
    joint = np.zeros(2)
    prev = None
    for i in range(n):
        d = lengths[i] * np.array([math.cos(angles[i]), math.sin(angles[i])])
        body = b.add_body(f"link{i}", mass=float(masses[i]),
                          inertia=float(masses[i] * lengths[i] ** 2 / 12),
                          pos=tuple(joint + d / 2), angle=float(angles[i]))
        b.add_pin(f"pin{i}", prev, body, anchor_world=tuple(joint))
        prev, joint = body, joint + d
    steps = int(min(1.0, 2000 * dt) / dt)
    return b.compile(), float(masses.sum() * G * lengths.sum()), dt, steps


def run(seed, count):
    """(stops, bad) lines of `count` chains drawn from `seed`."""
    rng = np.random.default_rng(seed)
    stops, bad = [], []
    for case in range(count):
        model, scale, dt, steps = chain(rng)
        label = f"seed {seed} chain {case}: {model.n_body} links, dt {dt:.2e}"
        try:
            sim = ps.Simulator(model)
            start = total_energy(model, sim.state.q, sim.state.v)
            gap, rise = 0.0, -math.inf
            every = max(1, steps // 50)
            for _ in range(0, steps, every):
                sim.steps(every)
                gap = max(gap, pin_gap(model, sim.state.q[None]))
                rise = max(rise, total_energy(model, sim.state.q, sim.state.v) - start)
            audited = sum(compiled.audit_counts(sim.ws).values()) > 0
            if gap > 1e-9 or (rise > 0.02 * scale and not audited):
                bad.append(f"{label}: pin gap {gap:.1e} m, energy rise {rise / scale:.1e} of m g L")
        except ps.errors.SimulationDiverged as e:
            stops.append(f"{label}: {str(e)[:110]}")
    return stops, bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--chains", type=int, default=60, help="chains per seed")
    args = ap.parse_args(argv)
    start = time.perf_counter()
    stops, bad = [], []
    for seed in args.seeds:
        s, b = run(seed, args.chains)
        stops += s
        bad += b
    for line in stops:
        print("stop", line)
    for line in bad:
        print("BAD ", line)
    total = len(args.seeds) * args.chains
    print(f"{total} chains in {time.perf_counter() - start:.0f} s: {len(stops)} stopped with an "
          f"error, {len(bad)} broke a pin or gained energy unaudited")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
