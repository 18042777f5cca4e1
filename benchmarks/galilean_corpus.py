"""Galilean invariance of free systems on seeded corpora (not a test; tests/physics/
test_galilean_invariance.py runs the first 400 impacts and 50 chains of these).

    python benchmarks/galilean_corpus.py                   # 2,000 impacts, 500 chains
    python benchmarks/galilean_corpus.py --impacts 200 --chains 0

Each case (the test module's _impact_cases and _chain_cases: two free bodies in an impact, or
a free chain of two to four pinned bodies with armature and springs, spinning) runs at rest
and drifting at a constant speed; prints each case whose velocities less the drift differ by
more than 1e-8 of the largest or whose audit counts, and how many did. Exits 1 if any did.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.physics.test_galilean_invariance import (
    _chain,
    _chain_cases,
    _impact,
    _impact_cases,
)

TOL = 1e-8


def _differs(run, case, drift):
    v0, audits0 = run(case, (0.0, 0.0))
    v1, audits1 = run(case, drift)
    diff = np.abs(v1 - v0).max() / max(1.0, np.abs(v0).max())
    return diff if diff > TOL or audits0 or audits1 else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--impacts", type=int, default=2000, help="impacts (100 per seed)")
    ap.add_argument("--chains", type=int, default=500, help="chains (25 per seed)")
    args = ap.parse_args(argv)
    bad = 0
    for name, run, cases, per_seed, total in (
            ("impacts", _impact, _impact_cases, 100, args.impacts),
            ("chains", _chain, _chain_cases, 25, args.chains)):
        if total <= 0:
            continue
        seeds = -(-total // per_seed)
        count = 0
        differ = 0
        for seed in range(seeds):
            for case, drift in cases(seed, min(per_seed, total - count)):
                count += 1
                diff = _differs(run, case, drift)
                if diff is not None:
                    differ += 1
                    print(f"  {name} seed {seed}: {case} drifting {drift}: differs by {diff:.1e}")
        print(f"{name}: {differ} of {count} differ beyond {TOL:g} of their velocities or audit")
        bad += differ
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
