"""Held-out cases for the displacement law: no body moves in a step farther than its velocities
explain (not a test; tests/physics/test_no_body_moves_farther_than_its_velocities_explain.py
runs a seeded corpus of them).

    python benchmarks/displacement.py                      # 200 seeds x 2 strategies, 0.3 s each
    python benchmarks/displacement.py --seeds 400 --seconds 1.0
    python benchmarks/displacement.py --only 17:all        # one case, its worst step printed

Cases (numpy.random.default_rng(seed)): one or two bodies thrown at 1-200 m/s (log-uniform)
within 85 deg of straight down, 1 cm to 1 m above steep sums of sines (one to three sines of
wavelength 0.2-3 m whose slopes add up to 45-85 deg), dt 1e-3..1e-2 s (log-uniform), friction
mu 0..1.5. The bodies, by seed % 4: point masses with a point contact (continuous collision);
rod dumbbells (two point masses, 0.1-1 m apart, turning at up to 20 rad/s); and colliding
shapes (a box, a circle or a capsule, 2-40 cm, turning at up to 30 rad/s) in the last two.

The law (judge): over a step of h [s] every body's centre of mass moves
|q_end - q_start| <= h max(|v_start|, |v_end|) + SLACK (symplectic Euler moves it by exactly
h |v_end|; a position correction that moves it by more than that plus 1 cm is a jump), unless
the run stopped with an error of the engine's. A step taken in parts (split at a time of
impact, or in turn sub-steps) is judged part by part: each part's length times the largest
speed the body had in it, summed (parted_step_excess).
"""
from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import planarsim as ps  # noqa: E402
from planarsim import terrain  # noqa: E402
from planarsim.kernels.info import INFO_CCD_SPLITS, INFO_TURN_SUBSTEPS  # noqa: E402

SLACK = 0.01                 # [m] a step's displacement allowed beyond h max(|v0|, |v1|)
STRATEGIES = ("alternating", "all")
KINDS = ("point", "dumbbell", "shape", "shape")     # body kind by seed % 4


def steep_hills(rng):
    """Sum of 1-3 sines, wavelengths 0.2-3 m, slopes adding up to 45-85 deg."""
    n = int(rng.integers(1, 4))
    lam = rng.uniform(0.2, 3.0, size=n)
    steepest = math.tan(math.radians(rng.uniform(45.0, 85.0)))
    share = rng.uniform(0.2, 1.0, size=n)
    amp = steepest * share / share.sum() * lam / (2.0 * math.pi)
    return terrain.hills(amp, lam, rng.uniform(0.0, 2.0 * math.pi, size=n))


def throw(rng):
    """A launch velocity [m/s]: 1-200 m/s (log-uniform) within 85 deg of straight down."""
    speed = 10.0 ** rng.uniform(0.0, math.log10(200.0))
    heading = -math.pi / 2 + rng.uniform(-1.48, 1.48)
    return np.array([speed * math.cos(heading), speed * math.sin(heading)])


def _shape(rng, ground, b, name, x, gap, vel, mu):
    """A box, circle or capsule body (2-40 cm, density ~ 1000 kg/m^2) above the ground at x."""
    kind = ("box", "circle", "capsule")[int(rng.integers(0, 3))]
    size = 10.0 ** rng.uniform(math.log10(0.02), math.log10(0.4))
    angle = rng.uniform(-math.pi, math.pi)
    if kind == "box":
        w, hgt = size, size * rng.uniform(0.2, 1.0)
        mass = 1000.0 * w * hgt
        inertia = mass * (w * w + hgt * hgt) / 12.0
        shape = ("box", (0.0, 0.0), w, hgt, {"mu": mu})
        reach = 0.5 * math.hypot(w, hgt)
    elif kind == "circle":
        r = 0.5 * size
        mass = 1000.0 * math.pi * r * r
        inertia = 0.5 * mass * r * r
        shape = ("circle", (0.0, 0.0), r, {"mu": mu})
        reach = r
    else:
        half, r = 0.5 * size, 0.5 * size * rng.uniform(0.1, 0.5)
        mass = 1000.0 * (2.0 * half * 2.0 * r + math.pi * r * r)
        inertia = mass * ((2.0 * half) ** 2 / 12.0 + r * r / 2.0)
        shape = ("capsule", (-half, 0.0), (half, 0.0), r, {"mu": mu})
        reach = half + r
    # high enough that no part of it starts below the ground (the ground under its reach)
    lift = max(ground.height(x + d) for d in np.linspace(-reach, reach, 41)) + reach + gap
    b.add_body(name, mass, inertia, pos=(x, lift), angle=angle, vel=tuple(vel),
               omega=rng.uniform(-30.0, 30.0), shapes=[shape])


def build(seed):
    """(model, kind) of case `seed` (see the module's docstring)."""
    rng = np.random.default_rng([seed, 55])
    ground = steep_hills(rng)
    dt = 10.0 ** rng.uniform(-3.0, -2.0)
    mu = rng.uniform(0.0, 1.5)
    kind = KINDS[seed % len(KINDS)]
    b = ps.ModelBuilder(dt=dt, terrain=ground)
    for i in range(int(rng.integers(1, 3))):
        x = 2.0 * i + rng.uniform(-0.5, 0.5)
        gap = 10.0 ** rng.uniform(-2.0, 0.0)
        vel = throw(rng)
        if kind == "point":
            b.add_point_mass(f"mass{i}", 10.0 ** rng.uniform(-1, 1), pos=(x, ground.height(x) + gap),
                             vel=tuple(vel))
            b.add_point_contact(f"mass{i}_c", f"mass{i}", mu=mu)
        elif kind == "dumbbell":
            length, turn = rng.uniform(0.1, 1.0), rng.uniform(-math.pi, math.pi)
            rate = rng.uniform(-20.0, 20.0)
            e = np.array([math.cos(turn), math.sin(turn)]) * length / 2
            lift = max(ground.height(x + sx * e[0]) + gap - sx * e[1] for sx in (-1.0, 1.0))
            for k, sx in enumerate((-1.0, 1.0)):
                p = np.array([x, lift]) + sx * e
                pv = vel + rate * sx * np.array([-e[1], e[0]])
                name = f"bell{i}_{k}"
                b.add_point_mass(name, 10.0 ** rng.uniform(-1, 1), pos=tuple(p), vel=tuple(pv))
                b.add_point_contact(f"{name}_c", name, mu=mu)
            b.add_rod(f"rod{i}", f"bell{i}_0", f"bell{i}_1")
        else:
            _shape(rng, ground, b, f"shape{i}", x, gap, vel, mu)
    return b.compile(), kind


def step_excess(q0, v0, q1, v1, h):
    """(n_body,) how far [m] each body's centre of mass moved in a step of h [s] beyond
    h max(|v_start|, |v_end|) (positive: farther than its velocities explain)."""
    moved = np.hypot(q1[:, 0] - q0[:, 0], q1[:, 1] - q0[:, 1])
    speed = np.maximum(np.hypot(v0[:, 0], v0[:, 1]), np.hypot(v1[:, 0], v1[:, 1]))
    return moved - h * speed


def parted(sim):
    """True if the engine took its last step in parts (time-of-impact splits or turn
    sub-steps): inside it a body moves at each part's velocities, which may exceed both
    ends' (a body struck and stopped again within the step)."""
    return sim.ws.info[INFO_CCD_SPLITS] > 0 or sim.ws.info[INFO_TURN_SUBSTEPS] > 1


def parted_step_excess(sim, q0, q1):
    """(n_body,) step_excess of a step the engine took in parts (parted): the path its
    velocities explain is the sum over the parts of each part's length times the largest
    speed the body had in it, which the engine records (Workspace.step_path)."""
    moved = np.hypot(q1[:, 0] - q0[:, 0], q1[:, 1] - q0[:, 1])
    return moved - sim.ws.step_path


def judged_excess(sim, q0, v0, q1, v1, h):
    """(n_body,) how far [m] each body moved in the last step of h [s] (from q0, v0 to q1, v1)
    beyond what its velocities explain: step_excess, or parted_step_excess for a step taken
    in parts."""
    return parted_step_excess(sim, q0, q1) if parted(sim) else step_excess(q0, v0, q1, v1, h)


def run_case(seed, strategy, seconds=0.3, jump_limit=SLACK):
    """Run case `seed` under `strategy` for `seconds` [s] with StepOptions.jump_limit (the
    engine's own check; 0: off), judged at every step. Returns a dict:
    excess (the largest step_excess, [m]), step and body where it is, raised (an engine
    error's first line, '' if none), jump (excess > SLACK with no error raised)."""
    model, kind = build(seed)
    sim = ps.Simulator(model, ps.make_options(strategy, jump_limit=jump_limit))
    h = model.dt
    steps = max(1, int(round(seconds / h)))
    out = dict(seed=seed, strategy=strategy, kind=kind, dt=h, steps=steps, excess=-math.inf,
               step=-1, body="", raised="", at=None)
    q0, v0 = sim.state.q.copy(), sim.state.v.copy()
    for k in range(steps):
        try:
            sim.step()
        except Exception as exc:     # an error of the engine's, naming why: raised, not silent
            if not type(exc).__module__.startswith("planarsim"):
                raise
            out["raised"] = f"{type(exc).__name__}: {str(exc).splitlines()[0][:200]}"
            break
        q1, v1 = sim.state.q.copy(), sim.state.v.copy()
        ex = judged_excess(sim, q0, v0, q1, v1, h)
        i = int(np.argmax(ex))
        if ex[i] > out["excess"]:
            out.update(excess=float(ex[i]), step=k, body=model.body_names[i],
                       at=(q0[i, :2].tolist(), q1[i, :2].tolist(), v0[i, :2].tolist(), v1[i, :2].tolist()))
        q0, v0 = q1, v1
    out["jump"] = out["excess"] > SLACK and not out["raised"]
    return out


def _run(args):
    return run_case(*args)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=200)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--seconds", type=float, default=0.3)
    ap.add_argument("--strategy", choices=STRATEGIES + ("both",), default="both")
    ap.add_argument("--only", action="append", default=[], metavar="SEED:STRATEGY")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--jump-limit", type=float, default=SLACK,
                    help=f"StepOptions.jump_limit [m] (default {SLACK}; 0: the engine's check off)")
    args = ap.parse_args(argv)
    strategies = STRATEGIES if args.strategy == "both" else (args.strategy,)
    cases = ([(int(t.split(":")[0]), t.split(":")[1]) for t in args.only] if args.only else
             [(s, st) for s in range(args.first, args.first + args.seeds) for st in strategies])
    work = [(seed, st, args.seconds, args.jump_limit) for seed, st in cases]
    t0 = time.perf_counter()
    run_case(0, "all", 0.01)                     # compile (or load) once, before forking
    if args.jobs > 1 and len(work) > 1:
        with multiprocessing.get_context("fork").Pool(args.jobs) as pool:
            results = pool.map(_run, work, chunksize=4)
    else:
        results = [_run(w) for w in work]
    jumps = [r for r in results if r["jump"]]
    raised = [r for r in results if r["raised"]]
    for kind in dict.fromkeys(KINDS):
        rs = [r for r in results if r["kind"] == kind]
        print(f"{kind:9s} runs {len(rs):4d}  jumps {sum(r['jump'] for r in rs):4d}  raised "
              f"{sum(bool(r['raised']) for r in rs):4d}  worst unexplained move "
              f"{max((r['excess'] for r in rs), default=math.nan):.3g} m")
    for r in sorted(jumps, key=lambda r: -r["excess"])[:12]:
        print(f"  {r['seed']}:{r['strategy']} {r['kind']} dt={r['dt']:.3g} body {r['body']} step "
              f"{r['step']}: {r['excess']:.3g} m beyond h|v| (q {r['at'][0]} -> {r['at'][1]}, "
              f"v {r['at'][2]} -> {r['at'][3]})")
    for r in raised[:12]:
        print(f"  raised {r['seed']}:{r['strategy']} {r['kind']}: {r['raised']}")
    print(f"{len(results)} runs, {len(jumps)} jumps (moves beyond h max|v| + {SLACK} m without an "
          f"error), {len(raised)} raised, {time.perf_counter() - t0:.1f} s")
    return 1 if jumps else 0


if __name__ == "__main__":
    sys.exit(main())
