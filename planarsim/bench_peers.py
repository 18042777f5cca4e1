"""Scene timing and accuracy for planarsim and its peers (MuJoCo, pymunk, Box2D), measured the
same way in the same run.

Timing: each engine runs the scene's timing episode (bench_scenes.SCENES: 5 s for chains, 3 s
for the biped collapse, 2 s for the rod drop) from the start state once to warm up, then
`repeats` times (each from the start state; building the world is not timed); steps/s is the
median with the min-max spread. planarsim's figure is the compiled multi-step call
(Simulator.steps); its Python single-step loop is reported next to it.
Accuracy: one recorded run per engine (10 s for chains, else the episode), judged by
bench_metrics.accuracy.

The peers are optional (`pip install planarsim[compare]`); `available_peers` says which are
importable and why the others are not.
"""
from __future__ import annotations

import importlib
import statistics
import time

import numpy as np

import planarsim as ps
from .kernels._jit import jit
from .bench_metrics import ACCURACY_SECONDS, PEER_SCENES, accuracy, spec_from_model
from .bench_scenes import SCENES

#: peer name -> module implementing World(spec) with reset(), run(n), record(n)
PEER_MODULES = {"mujoco": "planarsim.bench_mujoco", "pymunk": "planarsim.bench_pymunk",
                "box2d": "planarsim.bench_box2d"}


def available_peers(names=None):
    """({name: module} of the importable peers, [one-line message per missing peer])."""
    found, missing = {}, []
    for name in names if names is not None else PEER_MODULES:
        if name not in PEER_MODULES:
            raise ValueError(f"unknown peer {name!r}; peers: {sorted(PEER_MODULES)}")
        mod = importlib.import_module(PEER_MODULES[name])
        try:
            importlib.import_module(mod.PACKAGE)
        except ImportError as exc:
            missing.append(f"peer {name}: not installed ({exc}); `pip install planarsim[compare]` "
                           "adds mujoco, pymunk and Box2D")
            continue
        found[name] = mod
    return found, missing


def _rates(run, reset, n, repeats):
    """steps/s of `repeats` timed runs of n steps, each after reset() (not timed)."""
    reset()
    run(n)  # warm-up episode
    rates = []
    for _ in range(repeats):
        reset()
        t0 = time.perf_counter()
        run(n)
        rates.append(n / (time.perf_counter() - t0))
    return rates


def _summary(rates, dt):
    med = statistics.median(rates)
    return dict(steps_per_s=med, steps_per_s_min=min(rates), steps_per_s_max=max(rates), rtf=med * dt)


def accuracy_steps(name, dt, seconds=None):
    """Steps of the accuracy run of scene `name` (`seconds` overrides the default)."""
    if seconds is None:
        seconds = ACCURACY_SECONDS["chain" if name.startswith("chain") else name]
    return max(1, int(round(seconds / dt)))


@jit
def _empty_kernel():
    return 0


def call_floor_s(calls=20000) -> float:
    """Wall time of one call of an empty compiled function from Python [s] (median of 5)."""
    _empty_kernel()
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(calls):
            _empty_kernel()
        times.append((time.perf_counter() - t0) / calls)
    return statistics.median(times)


def measure_planarsim(name, repeats=5, n_steps=None, accuracy_seconds=None):
    """Timing (compiled and Python-loop steps/s, first-call time) and, for the peer scenes,
    the accuracy figures of planarsim on scene `name`.

    python_over_floor: wall time of one Simulator.step() in a Python loop over the floor of
    one compiled call from Python, i.e. the step's own compiled cost (from the compiled
    multi-step run) plus one call of an empty compiled function (call_floor_s)."""
    build, n_default = SCENES[name]
    n = int(n_steps or n_default)
    model = build()
    sim = ps.Simulator(model)
    start = sim.snapshot()
    t0 = time.perf_counter()
    sim.steps(1)
    first = time.perf_counter() - t0  # numba compile, or load from the on-disk cache
    row = dict(scene=name, engine="planarsim", version=getattr(ps, "__version__", ""),
               bodies=model.n_body, timing="compiled Simulator.steps(n)", first_call_s=first)
    row.update(_summary(_rates(lambda k: sim.steps(k), lambda: sim.restore(start), n, repeats), model.dt))
    def python_loop(k):
        step = sim.step
        for _ in range(k):
            step()
    py = _rates(python_loop, lambda: sim.restore(start), n, repeats)
    row["python_steps_per_s"] = statistics.median(py)
    row["call_floor_s"] = call_floor_s()
    row["python_over_floor"] = (1.0 / row["python_steps_per_s"]) / (1.0 / row["steps_per_s"] + row["call_floor_s"])
    if name in PEER_SCENES:
        k = accuracy_steps(name, model.dt, accuracy_seconds)
        spec = spec_from_model(name, model, k * model.dt)
        sim.restore(start)
        traj = sim.run(n_steps=k, record_every=1)
        q = np.concatenate([model.q0[None], traj.q])
        v = np.concatenate([start.v[None], traj.v])
        row.update(accuracy(spec, q, v))
    return row


def measure_peer(peer, name, repeats=5, n_steps=None, accuracy_seconds=None):
    """The same figures for a peer module (bench_mujoco / bench_pymunk / bench_box2d)."""
    build, n_default = SCENES[name]
    n = int(n_steps or n_default)
    model = build()
    k = accuracy_steps(name, model.dt, accuracy_seconds)
    spec = spec_from_model(name, model, k * model.dt)
    world = peer.World(spec)
    row = dict(scene=name, engine=peer.ENGINE, version=peer.version(), bodies=spec.n_body, timing=world.timing)
    row.update(_summary(_rates(world.run, world.reset, n, repeats), spec.dt))
    q, v = world.record(k)
    row.update(accuracy(spec, q, v))
    warnings = getattr(world, "warnings", [])
    if warnings:
        step, text = warnings[0]
        row["warning"] = f"{text} (step {step}); figures up to there"
    return row
