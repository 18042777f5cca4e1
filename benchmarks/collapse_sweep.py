"""How robust the collapse of the 7-link biped is to nanometre perturbations (not a test).

    python benchmarks/collapse_sweep.py                  # k = 0..15, both strategies, 3 s each
    python benchmarks/collapse_sweep.py --paths 32 --seconds 5

The collapse is chaotic: the torso's start velocity changed by k nm/s gives a different path
for every k. Each path is run with every frame recorded and judged on what a user must be
able to trust: energy never above its start, no one-step rise above 1e-3 of it, every pin
closed to 1e-9 m, no corner deeper than 2 mm at any time nor 1 um at the end, nothing counted by the step's
audit. A line is
flagged BAD when any of these fails. The tests assert a subset on a few paths
(tests/physics/test_contacts.py); this prints the whole picture, for a change to the solver
or the contact modes to be judged on many paths rather than the one the bench runs. Takes
about 3 s (40 s for --paths 128). On 27bb09a (mode rounds with a cap): 12 of 32 paths BAD
(pin gaps up to 6.5e-6 m, one corner 14 um deep at rest). With the complementarity solve:
0 of 256 BAD (--paths 128), no step's audit counting anything.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from benchmarks.metrics import lowest_point, pin_separation, spec_from_model  # noqa: E402
from benchmarks.scenes import biped_collapse  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=16, help="perturbations k = 0..paths-1 [nm/s]")
    ap.add_argument("--seconds", type=float, default=3.0, help="simulated time per path [s]")
    args = ap.parse_args(argv)
    model = biped_collapse()
    spec = spec_from_model("biped_collapse", model, args.seconds)   # boxes on flat ground y = 0
    bad = 0
    for strategy in ("alternating", "all"):
        for k in range(args.paths):
            sim = ps.Simulator(model, ps.make_options(strategy))
            state = sim.state
            state.v[0, 0] += k * 1e-9
            sim.state = state
            traj = sim.run(args.seconds, record_every=1)
            energy = traj.energy(model)["total"]
            rise = float(np.diff(energy).max())
            above = float(energy.max() - energy[0])
            pins = pin_separation(spec, traj.q)
            corners = lowest_point(spec, traj.q)
            deepest, end = float(corners.min()), float(corners[-1])
            audit = int(sim.ws.audit.sum())
            flag = (above > 0 or rise > 1e-3 * energy[0] or pins > 1e-9 or deepest < -2e-3
                    or end < -1e-6 or audit > 0)
            bad += flag
            print(f"{strategy:11s} k={k:2d}  largest one-step energy rise {rise:9.2e} J  "
                  f"above start {above:9.2e} J  pin gap {pins:.1e} m  deepest {deepest:.1e} m  "
                  f"at end {end:.1e} m  audit {audit} {'BAD' if flag else ''}")
    print(f"{bad} of {2 * args.paths} paths BAD")
    return 0


if __name__ == "__main__":
    sys.exit(main())
