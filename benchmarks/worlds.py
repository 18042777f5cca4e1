"""Worlds of many boxes at rest: memory, the first step, the steps after it, how far a box
moves, the audit. Each world runs in its own process (its peak memory is its own), stopped
after --limit seconds (a first step that takes longer is reported as such).

    python benchmarks/worlds.py                          # every world, 200 steps each
    python benchmarks/worlds.py columns10x10 pyramid10 --steps 500 --limit 120
    python benchmarks/worlds.py --keep-factors         # StepOptions(keep_factors=1)
    python benchmarks/worlds.py --struck --steps 20 --limit 300   # piles struck after settling

Worlds: pyramid4 (10 boxes), columns10x10 (ten columns of ten 0.2 m boxes, 0.4 m apart), pyramid10 (55 boxes),
pyramid20 (210 boxes, each on two below), wall40x10 (400 bricks 0.4 x 0.2 m, staggered),
pyramid45 (1,035 boxes). Prints per world: bodies, contact slots, the contacts the
workspace's solve holds at the end, peak memory [MB], the first step [ms], the mean of the
later steps and the largest mean of a call of CALL_STEPS of them [ms], the largest move of a box from its start [m], the deepest overlap of
a listed contact before the last step [m] and the audit's total; then how the mean step at
rest grows with the number of bodies, from the smallest world run to the largest.

Struck piles (--struck): a world that settles for SETTLE steps, then one box is set moving,
and the steps from there are timed as above ('first' is the step that meets the blow):
pyramid20_thrown (the top box thrown up at 0.3 m/s: it leaves and lands about 60 ms later),
pyramid20_pushed (the middle box of the third level pushed sideways at 0.5 m/s, into its
neighbours), and the same push on the 21- and 36-box pyramids (pyramid6_pushed,
pyramid8_pushed). No growth is fitted.
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402

BOX = 0.2   # [m]


def _box(b, name, x, y, w=BOX, h=BOX):
    b.add_body(name, pos=(x, y), shapes=[("box", (0.0, 0.0), w, h, {"mu": 0.6})], density=100.0)


def columns(n_columns=10, n_rows=10):
    b = ps.ModelBuilder(dt=1e-3)
    for c in range(n_columns):
        for r in range(n_rows):
            _box(b, f"box{c}_{r}", 2 * BOX * c, BOX / 2 + BOX * r)
    return b.compile()


def pyramid(rows):
    """rows levels of 0.2 m boxes, each on two below (touching side by side)."""
    b = ps.ModelBuilder(dt=1e-3)
    for level in range(rows):
        n = rows - level
        for j in range(n):
            _box(b, f"box{level}_{j}", (j - (n - 1) / 2) * BOX, BOX / 2 + level * BOX)
    return b.compile()


def wall(n_columns=40, n_rows=10):
    """A staggered wall of 0.4 x 0.2 m bricks: odd rows shifted by half a brick."""
    b = ps.ModelBuilder(dt=1e-3)
    for r in range(n_rows):
        for c in range(n_columns):
            _box(b, f"brick{r}_{c}", 2 * BOX * c + (BOX if r % 2 else 0.0), BOX / 2 + BOX * r,
                 w=2 * BOX)
    return b.compile()


WORLDS = {
    "pyramid4": lambda: pyramid(4),
    "columns10x10": lambda: columns(10, 10),
    "pyramid10": lambda: pyramid(10),
    "pyramid20": lambda: pyramid(20),
    "wall40x10": lambda: wall(40, 10),
    "pyramid45": lambda: pyramid(45),
}


# the steps after the first are timed this many to a call of Simulator.steps, as a run takes
# them (a call's first step keeps every contact slot as its start: kernels/prev_copy.py)
CALL_STEPS = 10

# steps a struck world settles before its blow
SETTLE = 5


def _throw_top(q, v):
    """The top box thrown up at 0.3 m/s."""
    v[int(np.argmax(q[:, 1])), 1] = 0.3


def _push_third_level(q, v):
    """The middle box of the third level pushed sideways at 0.5 m/s."""
    levels = np.unique(q[:, 1].round(6))
    third = np.flatnonzero(np.abs(q[:, 1] - levels[2]) < 1e-3)
    v[third[third.size // 2], 0] = 0.5


# name -> (world, blow(q, v) applied after SETTLE steps)
STRUCK = {
    "pyramid6_pushed": (lambda: pyramid(6), _push_third_level),
    "pyramid8_pushed": (lambda: pyramid(8), _push_third_level),
    "pyramid20_thrown": (lambda: pyramid(20), _throw_top),
    "pyramid20_pushed": (lambda: pyramid(20), _push_third_level),
}


def _load_step():
    """The compiled step compiled or loaded into this process (one step of one box)."""
    ps.Simulator(columns(1, 1)).step()


def _measure(name, steps, out, keep_factors):
    try:
        _measure_world(name, steps, out, keep_factors)
    except Exception as exc:     # reported by run(), one line
        out.put(("error", f"{type(exc).__name__}: {exc}"))


def _measure_world(name, steps, out, keep_factors=0):
    from planarsim.compiled import audit_counts
    from planarsim.state import workspace_contacts
    _load_step()                         # the compiled step loaded (once a process), not timed
    model = WORLDS[name]() if name in WORLDS else STRUCK[name][0]()
    sim = ps.Simulator(model, options=ps.StepOptions(keep_factors=keep_factors))
    if name in STRUCK:
        sim.steps(SETTLE)
        STRUCK[name][1](sim.state.q, sim.state.v)
    q0 = sim.state.q.copy()
    out.put(("built", model.n_body, model.n_contact))
    t = time.perf_counter()
    sim.step()
    first = time.perf_counter() - t
    out.put(("first", first))
    times = []                           # [s] a step, by calls of CALL_STEPS steps
    left, total = steps - 1, 0.0
    while left > 0:
        n = min(CALL_STEPS, left)
        t = time.perf_counter()
        sim.steps(n)
        took = time.perf_counter() - t
        times.append(took / n)
        total += took
        left -= n
    times = np.array(times or [first])
    mean = total / (steps - 1) if steps > 1 else first
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    live = sim.ws.live[:sim.ws.n_live[0]]
    deepest = max(0.0, -float(np.min(sim.ws.contact_gap[live]))) if live.size else 0.0
    out.put(("done", workspace_contacts(model, sim.ws), rss, first, mean,
             float(times.max()), float(np.abs(sim.state.q - q0).max()),
             int(sum(audit_counts(sim.ws).values())), deepest))


def run(name, steps, limit, keep_factors=0):
    out = mp.Queue()
    proc = mp.Process(target=_measure, args=(name, steps, out, keep_factors))
    proc.start()
    proc.join(limit)
    said = {}
    while not out.empty():
        item = out.get()
        said[item[0]] = item[1:]
    stopped = proc.is_alive()
    if stopped:
        proc.kill()
        proc.join()
    if "error" in said:
        return f"{name:13s} {said['error'][0]}", None
    if not stopped and "done" not in said:
        return f"{name:13s} its process ended with exit code {proc.exitcode} and no figures", None
    if "done" in said:
        held, rss, first, mean, most, move, audit, deepest = said["done"]
        n_body, n_contact = said["built"]
        line = (f"{name:13s} {n_body:5d} bodies {n_contact:9,d} slots  holds {held:6,d}  "
                f"{rss:7.0f} MB  first {first * 1e3:9.1f} ms  then mean {mean * 1e3:7.3f} ms "
                f"(largest {most * 1e3:7.2f})  moved {move:.1e} m  deepest {deepest:.1e} m  "
                f"audit {audit}")
        return line, (n_body, mean)
    where = ("before its first step ended" if "first" not in said
             else f"after a first step of {said['first'][0]:.1f} s")
    built = said.get("built")
    size = f"{built[0]} bodies {built[1]:,} slots, " if built else ""
    return f"{name:13s} {size}stopped at the {limit:g} s limit {where}", None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("worlds", nargs="*", help=f"of {list(WORLDS)} (default: all), or with "
                    f"--struck of {list(STRUCK)}")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--limit", type=float, default=120.0, help="seconds per world")
    ap.add_argument("--keep-factors", action="store_true",
                    help="StepOptions(keep_factors=1): a pile at rest keeps its factors")
    ap.add_argument("--struck", action="store_true",
                    help="the struck piles (STRUCK): settled, then one box set moving")
    a = ap.parse_args(argv)
    known = STRUCK if a.struck else WORLDS
    a.worlds = a.worlds or list(known)
    unknown = [w for w in a.worlds if w not in known]
    if unknown:
        ap.error(f"unknown world(s) {unknown}; the {'struck piles' if a.struck else 'worlds'} "
                 f"are {list(known)}")
    # the compiled step compiled (minutes on a fresh clone) or loaded once, in a process of its
    # own and without a time limit, so that no world's limit holds the compile: each world's
    # process then loads it from the cache, and this one stays as light as it was (its
    # children's peak memory is theirs)
    t = time.perf_counter()
    warm = mp.Process(target=_load_step)
    warm.start()
    warm.join()
    print(f"(the compiled step made ready in {time.perf_counter() - t:.1f} s; not timed below)",
          flush=True)
    sizes = []
    failed = 0
    for name in a.worlds:
        line, size = run(name, a.steps, a.limit, int(a.keep_factors))
        print(line, flush=True)
        if size is not None:
            sizes.append(size)
        else:
            failed += 1
    if len(sizes) >= 2 and not a.struck:
        (n0, t0), (n1, t1) = min(sizes), max(sizes)
        if n1 > n0:
            growth = np.log(t1 / t0) / np.log(n1 / n0)
            print(f"a step at rest grows as N^{growth:.2f} from {n0} to {n1} bodies "
                  f"({t0 * 1e3:.3f} ms to {t1 * 1e3:.3f} ms)")
    if failed:
        print(f"{failed} of {len(a.worlds)} worlds gave no figures (above)")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
