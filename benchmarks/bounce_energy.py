"""Random drops with restitution and friction: does any impact add energy? (not a test;
tests/physics/test_restitution_energy.py asserts on hypothesis-drawn drops)

    python benchmarks/bounce_energy.py                 # 300 drops, seed 1
    python benchmarks/bounce_energy.py --drops 1000 --seed 7

Each drop: a triangle, box, circle or capsule of 0.05-0.5 m, 0.01-100 kg, its inertia scaled
by 0.1-10, friction 0 or 0.1-2, restitution 1 or 0.2-1, dt 1e-4, 1e-3 or 5e-3 s, thrown at
the ground from 0.5-2 m with a random angle, spin (up to 30 rad/s) and velocity, for 1.5 s.
Energy is symplectic Euler's modified energy E - (h/2) m g v_y (what the scheme keeps in
flight), sampled every 10 steps. Prints each drop whose energy rose above its start by more
than 1e-6 of it or that the audit counted, and the largest rise.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from planarsim.compiled import audit_counts  # noqa: E402
from planarsim.energy import total_energy  # noqa: E402

G = 9.81


def modified_energy(sim, dt):
    """E - (h/2) sum_i m_i g v_y,i [J]: what symplectic Euler keeps under gravity alone."""
    m = sim.model
    mass = np.asarray(m.arrays.body_mass)
    return (total_energy(m, sim.state.q, sim.state.v)
            - 0.5 * dt * G * float(mass @ sim.state.v[:, 1]))


def shape_of(kind, s, aspect, spec):
    """(add_body's shape of `kind`, size s [m], a box's height aspect * s, options spec; its
    inertia about its centre per kg [m^2], uniform)."""
    if kind == "triangle":
        return ("polygon", [(-s / 2, -s / 3), (s / 2, -s / 3), (0, s / 2)], spec), s * s / 18
    if kind == "box":
        return ("box", (0.0, 0.0), s, s * aspect, 0.0, spec), s * s * (1 + aspect * aspect) / 12
    if kind == "circle":
        return ("circle", (0.0, 0.0), s / 2, spec), s * s / 8
    return ("capsule", (-s / 2, 0.0), (s / 2, 0.0), s / 5, spec), s * s / 12


def drop(rng):
    """(a description, the largest relative rise of the modified energy, audit count)."""
    kind = rng.choice(["triangle", "box", "circle", "capsule"])
    s = rng.uniform(0.05, 0.5)
    mass = 10 ** rng.uniform(-2, 2)
    mu = rng.choice([0.0, rng.uniform(0.1, 2.0)])
    e = rng.choice([1.0, rng.uniform(0.2, 1.0)])
    dt = float(rng.choice([1e-4, 1e-3, 5e-3]))
    aspect = rng.uniform(0.2, 1.0) if kind == "box" else 1.0
    shape, inertia = shape_of(kind, s, aspect, {"mu": mu, "restitution": e})
    b = ps.ModelBuilder(dt=dt)
    b.add_body("body", mass=mass, inertia=mass * inertia * 10 ** rng.uniform(-1, 1),
               pos=(0, rng.uniform(0.5, 2)), angle=rng.uniform(-3, 3),
               omega=rng.uniform(-30, 30), vel=(rng.uniform(-3, 3), rng.uniform(-5, 2)),
               shapes=[shape])
    sim = ps.Simulator(b.compile())
    start = modified_energy(sim, dt)
    top = start
    for _ in range(int(1.5 / dt) // 10):
        sim.steps(10)
        top = max(top, modified_energy(sim, dt))
    what = f"{kind} s={s:.2f} m={mass:.3g} mu={mu:.2f} e={e:.2f} dt={dt:g}"
    return what, (top - start) / abs(start), sum(audit_counts(sim.ws).values())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--drops", type=int, default=300)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    rises, flagged = [], 0
    for k in range(args.drops):
        what, rise, audits = drop(rng)
        rises.append(rise)
        if rise > 1e-6 or audits:
            flagged += 1
            print(f"{k:4d} {what} rise={rise:.2e} audits={audits}")
    print(f"{args.drops} drops: {flagged} rose above 1e-6 or were audited; "
          f"largest rise {max(rises):.2e} of the start's energy")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
