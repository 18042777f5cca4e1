"""Box2D's classic stress scenes and the contact-rich scenes (stress_scenes.py), timed in
planarsim and in the peers built from the same description, with planarsim's accuracy:

    python benchmarks/stress.py                        # every scene, every installed peer
    python benchmarks/stress.py stack20 pyramid55 --peers box2d --repeats 3 --seconds 0.5
    planarsim bench --parts stress                     # the same from the bench command

Per scene: planarsim's mean step [ms] (the compiled Simulator.steps(n) over the run) and its
mean and largest single step [ms] (a Python loop of Simulator.step(), each step timed in
`repeats` runs and its median taken, so that a step the machine preempted does not count), each
peer's mean step [ms] (its ShapeWorld.run: peers/box2d_peer.py, pymunk_peer.py,
mujoco_peer.py) and planarsim's mean over the peer's (> 1: planarsim is slower). Runs start
from the scene's start state (rebuilding is not timed), one warm-up each, then `repeats`
runs going round the engines in turn; the figure is the median. Accuracy of planarsim over
the same run, every step recorded: the largest pin gap [m], the largest overlap of two shapes
or of a shape and the ground [m], and in the resting scenes the largest distance a body gets
from its start [m] (each peer's too, at the end of its run: `peer drift`).
"""
from __future__ import annotations

import argparse
import importlib
import math
import statistics
import sys
import time

import numpy as np

import planarsim as ps
from benchmarks.stress_scenes import ALL_SCENES, STRESS_SCENES, accuracy, build_model

PEERS = {"box2d": "benchmarks.peers.box2d_peer", "pymunk": "benchmarks.peers.pymunk_peer",
         "mujoco": "benchmarks.peers.mujoco_peer"}


def available(names):
    """{name: module} of the peers among `names` whose package imports; prints the others."""
    found = {}
    for name in names:
        mod = importlib.import_module(PEERS[name])
        try:
            importlib.import_module(mod.PACKAGE)
        except ImportError as exc:
            print(f"peer {name}: not installed ({exc}); `pip install planarsim[compare]`")
            continue
        found[name] = mod
    return found


def step_times(sim, n) -> np.ndarray:
    """(n,) wall time [s] of each of n Simulator.step() calls."""
    out = np.empty(n)
    clock, step = time.perf_counter, sim.step
    for k in range(n):
        t0 = clock()
        step()
        out[k] = clock() - t0
    return out


def timed_rounds(engines, n, repeats) -> dict:
    """{key: median wall time [s] per step} of engines {key: (run, reset)}: one warm-up round,
    then `repeats` rounds going round the engines in turn (reset not timed)."""
    times = {key: [] for key in engines}
    for _ in range(repeats + 1):              # the first round warms up
        for key, (run, reset) in engines.items():
            reset()
            t0 = time.perf_counter()
            run(n)
            times[key].append((time.perf_counter() - t0) / n)
    return {key: statistics.median(t[1:]) for key, t in times.items()}


def peer_rows(scene, worlds, mean, n, ours) -> dict:
    """{peer: figures} of the timed peers: mean step, planarsim's over it (ours [s] per step,
    nan when planarsim failed), drift at the end of a run of a resting scene."""
    out = {}
    for key, world in worlds.items():
        drift = math.nan
        if scene.resting:
            world.reset()
            world.run(n)
            q0 = np.array([p.pos for p in scene.parts])
            drift = float(np.max(np.hypot(*(world.positions() - q0).T)))
        out[key] = dict(mean_ms=1e3 * mean[key], ratio=ours / mean[key], drift_m=drift, timing=world.timing)
    return out


def measure(name, peers, repeats=3, seconds=None, steps=None) -> dict:
    """Figures of scene `name` (module docstring) against peers {name: module} over `steps`
    steps, or `seconds` [s], or the scene's seconds. A run planarsim stops with an error of its
    own (SimulationDiverged: a pin it cannot hold) gives its message under "error" and no
    planarsim figures; the peers are timed all the same."""
    scene = ALL_SCENES[name]
    n = int(steps) if steps else max(1, int(round((seconds or scene.seconds) / scene.dt)))
    model = build_model(scene)
    sim = ps.Simulator(model)
    start = sim.snapshot()
    worlds = {key: mod.ShapeWorld(scene) for key, mod in peers.items()}
    row = dict(scene=name, bodies=scene.n_body, steps=n, mean_ms=math.nan, loop_mean_ms=math.nan,
               max_ms=math.nan, pin_gap_m=math.nan, overlap_m=math.nan, rest_drift_m=math.nan)
    try:
        sim.run(n_steps=n, record_every=n)         # does planarsim get through the run at all?
    except ps.SimulationDiverged as exc:
        row["error"] = str(exc)
        mean = timed_rounds({key: (w.run, w.reset) for key, w in worlds.items()}, n, repeats)
        row["peers"] = peer_rows(scene, worlds, mean, n, math.nan)
        return row
    engines = {"planarsim": (sim.steps, lambda: sim.restore(start))}
    engines.update({key: (w.run, w.reset) for key, w in worlds.items()})
    mean = timed_rounds(engines, n, repeats)
    loops = []
    for _ in range(repeats):
        sim.restore(start)
        loops.append(step_times(sim, n))
    single = np.median(loops, axis=0)       # each step's median: a preempted step is not its cost
    sim.restore(start)
    traj = sim.run(n_steps=n, record_every=1)
    row.update(mean_ms=1e3 * mean["planarsim"], loop_mean_ms=1e3 * float(np.mean(single)),
               max_ms=1e3 * float(np.max(single)), median_ms=1e3 * float(np.median(single)))
    row.update(accuracy(scene, model, traj.q))
    row["peers"] = peer_rows(scene, worlds, mean, n, mean["planarsim"])
    return row


def _fmt(x, spec=".2e"):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def print_rows(rows, peer_names):
    """The table of measure() rows."""
    head = (f"{'scene':<15}{'bodies':>7}{'steps':>6}{'mean ms':>9}{'loop ms':>9}{'max ms':>9}"
            + "".join(f"{p + ' ms':>12}{'ratio':>8}" for p in peer_names)
            + f"{'pin gap m':>11}{'overlap m':>11}{'drift m':>11}"
            + "".join(f"{p + ' drift':>13}" for p in peer_names))
    print(head)
    for r in rows:
        line = (f"{r['scene']:<15}{r['bodies']:>7}{r['steps']:>6}{_fmt(r['mean_ms'], '.3f'):>9}"
                f"{_fmt(r['loop_mean_ms'], '.3f'):>9}{_fmt(r['max_ms'], '.3f'):>9}")
        for p in peer_names:
            pr = r["peers"].get(p)
            line += f"{_fmt(pr and pr['mean_ms'], '.3f'):>12}{_fmt(pr and pr['ratio'], '.2f'):>8}"
        line += f"{_fmt(r['pin_gap_m']):>11}{_fmt(r['overlap_m']):>11}{_fmt(r['rest_drift_m']):>11}"
        for p in peer_names:
            pr = r["peers"].get(p)
            line += f"{_fmt(pr and pr['drift_m']):>13}"
        print(line, flush=True)
    for r in rows:
        if "error" in r:
            print(f"{r['scene']}: planarsim stopped: {r['error']}")
    print("mean ms: compiled Simulator.steps(n) per step; loop ms / max ms: a Python loop of step(), "
          "mean and largest step (each step's median over the repeats); ratio: planarsim's mean over the peer's (> 1: planarsim slower); "
          "drift: largest distance of a body from its start in a resting scene (planarsim: over the run; "
          "peers: at its end)")


def run(names, peer_names, repeats=3, seconds=None, steps=None):
    """Measure and print the scenes `names` (against the installed peers among `peer_names`);
    returns the rows."""
    peers = available(peer_names)
    print(f"stress scenes against {', '.join(peers) or 'no peer'}: {repeats} repeats", flush=True)
    rows = []
    for name in names:
        rows.append(measure(name, peers, repeats, seconds, steps))
        print(f"measured {name}", file=sys.stderr, flush=True)
    print_rows(rows, list(peers))
    return rows


def growth(rows) -> tuple | None:
    """(exponent, (bodies, ms), (bodies, ms)): how planarsim's median step (a step at rest: the
    first step, which finds every contact and mode, excluded by the median) grows with the
    bodies from the smallest measured scene to the largest (log-log), or None."""
    sizes = sorted((r["bodies"], r["median_ms"]) for r in rows if "median_ms" in r)
    if len(sizes) < 2 or sizes[-1][0] == sizes[0][0]:
        return None
    (n0, t0), (n1, t1) = sizes[0], sizes[-1]
    return math.log(t1 / t0) / math.log(n1 / n0), (n0, t0), (n1, t1)


def run_worlds(peer_names, repeats=3, steps=None):
    """The worlds at rest (stress_scenes.WORLD_SCENES) against the peers, then how a step at
    rest grows with the bodies; returns the rows."""
    from benchmarks.stress_scenes import WORLD_SCENES
    rows = run(list(WORLD_SCENES), peer_names, repeats, steps=steps)
    found = growth(rows)
    if found is not None:
        k, (n0, t0), (n1, t1) = found
        print(f"worlds: a step at rest (median) grows as N^{k:.2f} from {n0} to {n1} bodies "
              f"({t0:.3f} ms to {t1:.3f} ms; target N^1.3: {'met' if k <= 1.3 else 'NOT MET'}); "
              "peak memory per world: python benchmarks/worlds.py", flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python benchmarks/stress.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", help=f"scenes (default all): {', '.join(STRESS_SCENES)}")
    ap.add_argument("--peers", default=",".join(PEERS), help="comma list of box2d, pymunk, mujoco, or none")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per engine (default 3)")
    ap.add_argument("--seconds", type=float, default=None, help="simulated seconds per run (default the scene's)")
    args = ap.parse_args(argv)
    unknown = [n for n in args.scenes if n not in STRESS_SCENES]
    if unknown:
        ap.error(f"unknown scene(s) {unknown}; choose from {list(STRESS_SCENES)}")
    peers = [] if args.peers == "none" else [p for p in args.peers.split(",") if p]
    bad = [p for p in peers if p not in PEERS]
    if bad:
        ap.error(f"unknown peer(s) {bad}; choose from {list(PEERS)}")
    if args.repeats < 1:
        ap.error(f"--repeats {args.repeats} must be >= 1")
    run(args.scenes or list(STRESS_SCENES), peers, args.repeats, args.seconds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
