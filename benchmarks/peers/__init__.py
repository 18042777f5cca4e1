"""Scene timing and accuracy for planarsim and its peers (MuJoCo, pymunk, Box2D), measured the
same way in the same run.

Timing: each engine runs the scene's timing episode (scenes.SCENES: 5 s for chains, 3 s
for the biped collapse, 2 s for the rod drop) from the start state once to warm up, then
`repeats` times, each from the start state (resetting or rebuilding the world is not timed),
the repeats going round the engines in turn; steps/s is the median with the min-max spread.
planarsim's figure is the compiled multi-step call (Simulator.steps); its Python single-step
loop is timed alongside.
Accuracy: one recorded run per engine (10 s for chains, else the episode), judged by
metrics.accuracy.

The peers are optional (`pip install planarsim[compare]`); `available_peers` says which are
importable and why the others are not.
"""
from __future__ import annotations

import importlib
import statistics
import time

import numpy as np

import planarsim as ps
from benchmarks.metrics import PEER_SCENES, accuracy, scene_seconds, spec_from_model
from benchmarks.scenes import SCENES
from planarsim.compiled import jit

#: peer name -> module implementing World(spec) with reset(), run(n), record(n)
PEER_MODULES = {"mujoco": "benchmarks.peers.mujoco_peer", "pymunk": "benchmarks.peers.pymunk_peer",
                "box2d": "benchmarks.peers.box2d_peer"}


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


def _rates(engines, n, repeats):
    """{key: [steps/s of `repeats` timed runs of n steps]} for engines {key: (run, reset)}.
    Every engine runs one warm-up episode, then the repeats go round the engines in turn (so
    a slow drift of the machine's load hits all engines alike); reset() is not timed."""
    for run, reset in engines.values():
        reset()
        run(n)
    rates = {key: [] for key in engines}
    for _ in range(repeats):
        for key, (run, reset) in engines.items():
            reset()
            t0 = time.perf_counter()
            run(n)
            rates[key].append(n / (time.perf_counter() - t0))
    return rates


def _summary(rates, dt):
    med = statistics.median(rates)
    return dict(steps_per_s=med, steps_per_s_min=min(rates), steps_per_s_max=max(rates), rtf=med * dt)


def accuracy_steps(name, dt, seconds=None):
    """Steps of the accuracy run of scene `name` (`seconds` overrides the default)."""
    if seconds is None:
        seconds = scene_seconds(name)
    return max(1, int(round(seconds / dt)))


@jit
def _empty_kernel():
    return 0


def median_call_s(fn, args=(), calls=20000, per_call=1) -> float:
    """Wall time [s] of one call of fn(*args) (divided by `per_call`: the steps one call takes),
    the median of 5 timed loops of `calls` calls, after one call to warm up."""
    fn(*args)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn(*args)
        times.append((time.perf_counter() - t0) / (calls * per_call))
    return statistics.median(times)


def call_floor_s(calls=20000) -> float:
    """Wall time of one call of an empty compiled function from Python [s] (median of 5)."""
    return median_call_s(_empty_kernel, calls=calls)


_EMPTY = {}


def net_rate(mod, steps_per_s):
    """{empty_step_s, steps_per_s_net} of a peer module at `steps_per_s`: the wall time of one
    step of an empty world by the same call path (measured once per process), and the rate
    with that time taken off every step: the scene's own cost, what the peer would reach
    with no call around its step."""
    if mod.ENGINE not in _EMPTY:
        _EMPTY[mod.ENGINE] = mod.empty_step_s()
    empty = _EMPTY[mod.ENGINE]
    own = 1.0 / steps_per_s - empty
    return dict(empty_step_s=empty, steps_per_s_net=1.0 / own if own > 0 else float("inf"))


def measure_scene(name, peers=None, repeats=5, n_steps=None, accuracy_seconds=None):
    """(planarsim row, [peer rows]) of scene `name`: timing interleaved over planarsim and
    the peers {name: module} (peers/mujoco_peer, pymunk_peer, box2d_peer), and for the peer
    scenes the accuracy figures of each.

    planarsim: first_call_s = first Simulator.steps call (numba compile or cache load);
    steps_per_s = compiled Simulator.steps(n); python_steps_per_s = a Python loop of
    Simulator.step(); python_over_floor = one step() in that loop over the floor of one
    compiled call from Python, i.e. the step's own compiled cost plus one call of an empty
    compiled function (call_floor_s).
    """
    peers = peers or {}
    build, n_default = SCENES[name]
    n = int(n_steps or n_default)
    model = build()
    sim = ps.Simulator(model)
    start = sim.snapshot()
    t0 = time.perf_counter()
    sim.steps(1)
    first = time.perf_counter() - t0
    k = accuracy_steps(name, model.dt, accuracy_seconds) if name in PEER_SCENES else 0
    spec = spec_from_model(name, model, k * model.dt) if name in PEER_SCENES else None
    if peers and spec is None:
        raise ValueError(f"scene {name!r} has no peer version; peer scenes: {PEER_SCENES}")
    worlds = {key: mod.World(spec) for key, mod in peers.items()}

    def python_loop(k):
        step = sim.step
        for _ in range(k):
            step()
    restore = lambda: sim.restore(start)  # noqa: E731
    engines = {"planarsim": (sim.steps, restore), "planarsim-python": (python_loop, restore)}
    engines.update({key: (w.run, w.reset) for key, w in worlds.items()})
    rates = _rates(engines, n, repeats)
    row = dict(scene=name, engine="planarsim", version=getattr(ps, "__version__", ""), bodies=model.n_body,
               timing="compiled Simulator.steps(n)", first_call_s=first)
    row.update(_summary(rates["planarsim"], model.dt))
    row["python_steps_per_s"] = statistics.median(rates["planarsim-python"])
    row["call_floor_s"] = call_floor_s()
    row["python_over_floor"] = (1.0 / row["python_steps_per_s"]) / (1.0 / row["steps_per_s"] + row["call_floor_s"])
    if spec is not None:
        sim.restore(start)
        traj = sim.run(n_steps=k, record_every=1)
        row.update(accuracy(spec, traj.q, traj.v))   # frame 0: the start
    peer_rows = []
    for key, world in worlds.items():
        mod = peers[key]
        r = dict(scene=name, engine=mod.ENGINE, version=mod.version(), bodies=spec.n_body, timing=world.timing)
        r.update(_summary(rates[key], spec.dt))
        r.update(net_rate(mod, r["steps_per_s"]))
        r.update(accuracy(spec, *world.record(k)))
        warnings = getattr(world, "warnings", [])
        if warnings:
            step, text = warnings[0]
            r["warning"] = f"{text} (step {step}); figures up to there"
        peer_rows.append(r)
    return row, peer_rows
