"""Bit-level fingerprints of every shipped walker's run, to show that a refactor leaves the
physics unchanged: for each walker in walkers.WALKERS and each of its gaits (plus SIMBICON with
a push), ``simulate(seconds)`` is run and one line printed: a blake2b digest of the recorded
q, v and t [SI units] and the summary's numbers (the audit counts included).

    python benchmarks/walker_digests.py [--seconds 5] > before.txt    # then diff after.txt
"""
from __future__ import annotations

import argparse
import hashlib
import math

import numpy as np

import walkers

#: runs beyond each walker's gaits: (walker, gait, extra simulate() keywords, label)
EXTRA_RUNS = (("simbicon", "walk", {"push": dict(force=60.0, start=2.0, duration=0.2)}, "push"),)


def digest(*arrays) -> str:
    """blake2b (16 hex digits) of the arrays' float64 bytes, shapes included."""
    h = hashlib.blake2b(digest_size=8)
    for a in arrays:
        a = np.ascontiguousarray(a, dtype=np.float64)
        h.update(repr(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _number(x) -> str:
    if isinstance(x, (bool, np.bool_, int, np.integer, str)):
        return repr(x if not isinstance(x, np.generic) else x.item())
    if isinstance(x, (float, np.floating)):
        return "nan" if math.isnan(x) else float(x).hex()
    if isinstance(x, dict):
        return "{" + ",".join(f"{k}:{_number(x[k])}" for k in sorted(x)) + "}"
    return repr(x)


def runs(names=()):
    """(walker name, gait, keywords, label) of every run digested (of walkers `names`, or all)."""
    names = names or sorted(walkers.WALKERS)
    for name in names:
        for gait in walkers.load(name).GAITS:
            yield name, gait, {}, gait
    yield from (r for r in EXTRA_RUNS if r[0] in names)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=5.0, help="simulated time per run [s]")
    ap.add_argument("names", nargs="*", help="walkers to digest (default: all)")
    a = ap.parse_args(argv)
    for name, gait, kw, label in runs(a.names):
        traj, summary, _ = walkers.load(name).simulate(a.seconds, gait=gait, **kw)
        print(f"{name:16s} {label:7s} traj {digest(traj.q, traj.v, traj.t)} frames {len(traj.t)}")
        print(f"{'':24s} summary {_number(summary)}")


if __name__ == "__main__":
    main()
