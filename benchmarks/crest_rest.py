"""Flat shapes landing on their side on a hill's crest (not a test): how many runs the engine
audits or stops, against the step's size beside the shape's rocking frequency.

    python benchmarks/crest_rest.py                 # 150 seeds, both contact strategies
    python benchmarks/crest_rest.py --seeds 40

Each seed draws one shape, a capsule (core 0.06-0.8 m, radius 5-80 mm) or a thin box (0.06-0.8
m by 5-100 mm), 0.1-10 kg, dropped flat (within 0.05 rad) 10 um to 1 cm above a sine hill whose
crest has a radius R of 1 to 300 m (log-uniform; slopes under about 30 deg), its middle within
a quarter of its length of the crest, falling at 0.01-3 m/s and turning at up to 6 rad/s, at
dt 1, 3 or 10 ms; 0.5 s. A flat edge on a crest rocks like a spring of stiffness m g R (its
contact point moves R phi along the edge when it turns by phi): w = sqrt(m g R / I), printed
as h w for the runs that end audited or stopped and for the rest (the step holds the edge at
the deepest point of its start, so it takes that spring explicitly; tests/physics/
test_flat_on_a_crest.py keeps the known defect).
"""
from __future__ import annotations

import argparse
import collections
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from planarsim import terrain  # noqa: E402
from planarsim.kernels.checks.audit import AUDIT_NAMES  # noqa: E402

GRAVITY = 9.81


def scene(seed):
    """(model, dt [s], h w [-]: the step against the shape's rocking on the crest)."""
    rng = np.random.default_rng(seed)
    lam = rng.uniform(1.0, 40.0)
    radius = 10 ** rng.uniform(0, 2.5)
    amp = min(lam ** 2 / (4 * math.pi ** 2 * radius), 0.09 * lam)   # crest radius, slope cap
    radius = lam ** 2 / (4 * math.pi ** 2 * amp)
    ground = terrain.hills([amp], [lam], [0.0])
    dt = float(rng.choice([1e-3, 3e-3, 1e-2]))
    b = ps.ModelBuilder(dt=dt, terrain=ground)
    crest = lam / 4                       # the sine's peak
    mass = 10 ** rng.uniform(-1, 1)
    half = rng.uniform(0.03, 0.4)
    mu = rng.uniform(0.2, 1.2)
    if rng.random() < 0.5:
        r = 10 ** rng.uniform(-2.3, -1.1)
        shape = ("capsule", (-half, 0.0), (half, 0.0), r, {"mu": mu})
        inertia = mass * ((2 * half) ** 2 / 12 + r * r / 2)
        low = r
    else:
        thick = 10 ** rng.uniform(-2.3, -1.0)
        shape = ("box", (0.0, 0.0), 2 * half, thick, {"mu": mu})
        inertia = mass * ((2 * half) ** 2 + thick ** 2) / 12
        low = thick / 2
    x = crest + rng.uniform(-0.5, 0.5) * half
    angle = rng.uniform(-0.05, 0.05) + (math.pi if rng.random() < 0.5 else 0.0)
    along = np.linspace(-half, half, 401)
    y = (float(np.max(ground.height(x + along * math.cos(angle)) - along * math.sin(angle)))
         + 1.02 * low + 10 ** rng.uniform(-5, -2))
    b.add_body("flat", mass, inertia, pos=(x, y), angle=angle,
               vel=(rng.uniform(-0.5, 0.5), -10 ** rng.uniform(-2, 0.5)),
               omega=rng.uniform(-6, 6), shapes=[shape])
    return b.compile(), dt, dt * math.sqrt(mass * GRAVITY * radius / inertia)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=150)
    args = ap.parse_args(argv)
    counts = collections.Counter()
    rocking = {"clean": [], "audited or stopped": []}
    for seed in range(args.seeds):
        model, dt, hw = scene(seed)
        for strategy in ("all", "alternating"):
            sim = ps.Simulator(model, ps.make_options(strategy))
            try:
                sim.steps(int(round(0.5 / dt)))
                audits = {k: int(v) for k, v in zip(AUDIT_NAMES, sim.ws.audit) if v}
                outcome = "audited" if audits else "clean"
            except ps.SimulationDiverged as stop:
                audits, outcome = {"stopped": str(stop)[:80]}, "stopped"
            counts[outcome] += 1
            rocking["clean" if outcome == "clean" else "audited or stopped"].append(hw)
            if outcome != "clean":
                print(f"  seed {seed:3d} {strategy:11s} {model.shape_names[0].split()[0]:7s} "
                      f"dt {dt:g}  h w {hw:6.2f}  {audits}")
    runs = sum(counts.values())
    print(f"{runs} runs: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for k, hws in rocking.items():
        if hws:
            print(f"  h w of the {k} runs: min {min(hws):.2f}, median "
                  f"{float(np.median(hws)):.2f}, max {max(hws):.2f}")
    return 0 if counts["clean"] == runs else 1


if __name__ == "__main__":
    sys.exit(main())
