"""step_jacobian through contact on a seeded corpus (not a test): boxes on slopes, disks on
slopes, disks and beads on hills and stacks of two or three boxes (shape pairs), from random masses, sizes, slopes, friction, speeds,
commands and step sizes, each moved for 5-100 steps and then judged against centred finite
differences (tests/planarsim/test_derivatives_contact.py difference_error: the positions
moved along the surface of the touching contacts and joints, the velocities and commands
every way; relative error <= 1e-6).

    python benchmarks/derivative_corpus.py                   # 200 of each family, seed 0
    python benchmarks/derivative_corpus.py --families stack --cases 100
    python benchmarks/derivative_corpus.py --cases 400 --seed 7 --families box disk

Prints per family how many cases were covered and within 1e-6 ("ok"), within 1e-6 with a
column at a kink within the differences' step ("ok, kink"), at a mode's edge
(StepJacobian.modes_changed), refused by name (NotImplementedError, by reason), not
touching or not settled when judged ("skipped"), stopped by the engine itself ("engine
refused": a motor too strong for the step), and wrong ("BAD", listed with their parameters:
the figure that must stay 0).
"""
from __future__ import annotations

import argparse
import collections
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "planarsim"))

import planarsim as ps  # noqa: E402
from planarsim.errors import SimulationDiverged  # noqa: E402
from planarsim.kernels.codes import MODE_FREE  # noqa: E402
from planarsim.kernels.geometry.terrain import closest_point, height  # noqa: E402
from test_derivatives_contact import (REL_TOL, box_stack, difference_error,  # noqa: E402
                                      moved, slope_case)


def on_hills(rng):
    """A disk (even draws) or a bead rolling on one sine of hills, and its command scale."""
    terrain = ps.terrain.hills([rng.uniform(0.005, 0.1)], [rng.uniform(0.5, 3.0)])
    coef = np.asarray(terrain.coef, dtype=float)
    dt = float(rng.choice([1e-3, 5e-3]))
    b = ps.ModelBuilder(dt=dt, terrain=terrain)
    x0, mass, mu = rng.uniform(-1, 1), 10 ** rng.uniform(-2, 2), rng.uniform(0, 1.5)
    if rng.uniform() < 0.5:
        radius, spin = rng.uniform(0.05, 0.5), rng.uniform(-10, 10)
        lo, hi = height(coef, x0) - 1.0, height(coef, x0) + radius + 1.0
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if closest_point(coef, x0, mid)[4] > radius else (mid, hi)
        body = b.add_body("disk", mass=mass, inertia=0.5 * mass * radius ** 2, pos=(x0, hi),
                          vel=(-spin * radius, 0.0), omega=spin)
        b.add_arc_contact("rim", body, (0.0, 0.0), radius, mu=mu)
        b.add_body_torque("drive", body)
        scale = mass * 9.81 * radius
    else:
        body = b.add_point_mass("bead", mass, pos=(x0, height(coef, x0)),
                                vel=(rng.uniform(-2, 2), 0.0))
        b.add_point_contact("bead", body, mu=mu)
        b.add_body_force("push", body, direction=(1.0, 0.0))
        scale = mass * 9.81
    return ps.Simulator(b.compile()), scale


FAMILIES = ["box", "disk", "hills", "stack"]


def case(family, rng):
    """(sim, commands u, their scale) of one random case of `family`."""
    if family in ("box", "disk"):
        return slope_case(family, rng)
    if family == "stack":
        count = int(rng.integers(2, 4))
        masses = 10 ** rng.uniform(-2, 2, count)
        sim = box_stack(rng.uniform(0.05, 1.0, count), rng.uniform(0.02, 0.3), masses,
                        rng.uniform(0, 1.5), rng.uniform(-2, 2), float(rng.choice([1e-3, 5e-3])))
        scale = masses[-1] * 9.81
    else:
        sim, scale = on_hills(rng)
    return sim, np.array([rng.uniform(-1, 1) * scale]), scale


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--families", nargs="+", default=list(FAMILIES), choices=FAMILIES)
    args = parser.parse_args(argv)
    bad_total = 0
    for family in args.families:
        rng = np.random.default_rng([args.seed, FAMILIES.index(family)])
        counts, bad = collections.Counter(), []
        for k in range(args.cases):
            sim, u, scale = case(family, rng)
            steps = int(rng.integers(5, 100))
            try:
                sim, settled = moved(sim, steps, u)
            except SimulationDiverged:
                counts["engine refused"] += 1
                continue
            if not settled or (sim.state.contact_mode == MODE_FREE).all():
                counts["skipped"] += 1
                continue
            try:
                err, kinks, edge = difference_error(sim, u, scale)
            except NotImplementedError as exc:
                counts["refused: " + str(exc).split("this step has ")[-1][:48]] += 1
                continue
            except SimulationDiverged:
                counts["engine refused"] += 1
                continue
            if edge:
                counts["mode at its edge"] += 1
            elif err > REL_TOL:
                counts["BAD"] += 1
                bad.append((k, steps, err))
            else:
                counts["ok, kink" if kinks else "ok"] += 1
        print(f"{family}: {dict(sorted(counts.items()))}")
        for k, steps, err in bad:
            print(f"  BAD case {k} (after {steps} steps): relative error {err:.3g}")
        bad_total += len(bad)
    return 1 if bad_total else 0


if __name__ == "__main__":
    sys.exit(main())
