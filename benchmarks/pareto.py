"""Accuracy-matched comparison: cost against accuracy for planarsim and its peers.

Each engine runs each peer scene along an effort ladder (CURVES x the steps k per scene dt):
planarsim at a step of dt / k; pymunk and Box2D at more solver iterations and a step of dt / k;
MuJoCo with its Euler, implicitfast and RK4 integrators at dt / k. k < 1 (a step longer than
the scene's dt) shows the cheap end of each curve. Every point is judged by the same code
(metrics.accuracy on frames every max(dt, dt / k): every state a coarse step produces, every
scene dt otherwise) and timed the same way: the points of a scene go round in turn
(peers._rates), each running `timing_seconds` of simulated time from the start state;
cost = wall-clock seconds per simulated second (median).

A curve is one engine configuration along its ladder (e.g. "mujoco RK4" at dt*8 ... dt/8).
Its ratio at matched accuracy (matched) is its cost, interpolated log-log on its Pareto front
at the error planarsim reaches at the scene's dt, over planarsim's cost there; the raw ratio
compares both at dt (k = 1).
"""
from __future__ import annotations

import math
import statistics
from dataclasses import replace

import numpy as np

import planarsim as ps
from planarsim.integrator import unsupported_feature
from benchmarks.metrics import PEER_SCENES, accuracy, scene_seconds, spec_from_model
from benchmarks.peers import _rates
from benchmarks.scenes import biped_collapse, box_column, box_pyramid, chain, rod_drop

#: accuracy figures on the plots and in the matched ratios (metrics.accuracy keys, and
#: contact_error_m = the larger of the deepest sink and the end's gap |rest_gap_m| [m]). With a
#: ground the energy is not one of them: an inelastic impact loses energy by physics
ERRORS = ("energy_err_max", "pin_error_m", "contact_error_m")
#: errors below these are drawn and matched as these (rounding: a pin gap under 1 nm is the
#: exactness bound of the benchmark targets, report.PIN_TOL) [unit of the figure]
FLOORS = {"energy_err_max": 1e-12, "pin_error_m": 1e-9, "contact_error_m": 1e-9}
#: step of the bench scenes (scenes.py) [s]: the frame of every accuracy record
SCENE_DT = 1e-3
#: scenes of `--parts pareto` when none is named
DEFAULT_SCENES = ("chain4", "chain32", "rod_drop", "biped_collapse")

_FULL_K, _QUICK_K = (0.125, 0.25, 0.5, 1, 2, 4, 8), (1, 2)
#: engine -> [(curve label, World keyword arguments)]; each curve runs at every k of the ladder
CURVES = {
    # the default step (first order in the energy) and the accurate integrators
    # (StepOptions.integrator; mechanisms without contacts only: measure_scene skips them there)
    "planarsim": [("planarsim", {}), ("planarsim-rattle", {"integrator": "rattle"}),
                  ("planarsim-rattle4", {"integrator": "rattle4"}),
                  ("planarsim-rattle6", {"integrator": "rattle6"})],
    "pymunk": [("pymunk it10", {"iterations": 10}), ("pymunk it40", {"iterations": 40}),
               ("pymunk it40 stiff", {"iterations": 40, "slop": 0.0, "bias": 1e-12})],
    "box2d": [("box2d it8/3", {"velocity_iterations": 8, "position_iterations": 3}),
              ("box2d it30/10", {"velocity_iterations": 30, "position_iterations": 10}),
              ("box2d it30/10 skin", {"velocity_iterations": 30, "position_iterations": 10, "skin": "compensated"})],
    "mujoco": [("mujoco Euler", {"integrator": "Euler"}), ("mujoco implicitfast", {"integrator": "implicitfast"}),
               ("mujoco RK4", {"integrator": "RK4"}),
               ("mujoco Euler stiff", {"integrator": "Euler", "contact": "stiff"}),
               ("mujoco RK4 stiff", {"integrator": "RK4", "contact": "stiff"})],
}
#: keywords of the curves that set a peer's contact softness (pymunk's slop and bias, Box2D's
#: skin, MuJoCo's solref/solimp); those curves run on scenes with a ground only
CONTACT_KEYWORDS = frozenset({"slop", "bias", "skin", "contact"})


def ladder(engine, quick=False):
    """[(curve, kwargs, k)] of `engine`: k = steps per scene dt (the step is dt / k); the
    quick ladder keeps the first curve of each engine and k = 1, 2."""
    curves = CURVES[engine][:1] if quick else CURVES[engine]
    return [(label, kw, k) for label, kw in curves for k in (_QUICK_K if quick else _FULL_K)]


def build_model(name, dt):
    """The planarsim model of peer scene `name` at step dt [s]."""
    if name.startswith("chain"):
        return chain(int(name[5:]), dt=dt)
    builders = {"rod_drop": rod_drop, "biped_collapse": biped_collapse,
                "box_column10": lambda dt: box_column(10, dt=dt), "box_pyramid": box_pyramid}
    if name not in builders:
        raise ValueError(f"scene {name!r} has no peer version; peer scenes: {PEER_SCENES}")
    return builders[name](dt=dt)


def frames(k):
    """(m, s): a frame is m scene dts of s steps each, for k steps per scene dt (k = s / m;
    k >= 1 an integer, else 1 / k an integer)."""
    if k >= 1:
        if k != int(k):
            raise ValueError(f"k = {k}: steps per scene dt must be an integer or 1 / integer")
        return 1, int(k)
    m = round(1.0 / k)
    if abs(m * k - 1.0) > 1e-9:
        raise ValueError(f"k = {k}: steps per scene dt must be an integer or 1 / integer")
    return m, 1


class _Planarsim:
    """planarsim at frame_dt / k steps per frame, with the peers' World interface; options:
    make_options keywords (integrator='rattle', say). A run the engine stops (a
    SimulationDiverged: a chain whipping faster than a long step resolves, say) keeps its
    message in `warnings` as (frame, text), as a peer's warning: it is not on the front."""

    def __init__(self, name, frame_dt, k, **options):
        self.sim = ps.Simulator(build_model(name, frame_dt / k), options=ps.make_options(**options))
        self.start, self.k = self.sim.snapshot(), k
        self.warnings = []

    def reset(self):
        self.sim.restore(self.start)

    def run(self, n):
        try:
            self.sim.steps(n * self.k)
        except ps.SimulationDiverged as err:
            self.warnings = self.warnings or [(-1, str(err).split(":")[0])]

    def record(self, n):
        """Poses and velocities (n + 1, n_body, 3) of an n-frame run from the start state, or
        the frames before the engine stopped it."""
        self.reset()
        self.warnings = []
        nb = self.sim.model.n_body
        q = np.zeros((n + 1, nb, 3))
        v = np.zeros_like(q)
        q[0], v[0] = self.sim.state.q[:nb], self.sim.state.v[:nb]
        for f in range(1, n + 1):
            try:
                self.sim.steps(self.k)
            except ps.SimulationDiverged as err:
                self.warnings = [(f, str(err).split(":")[0])]
                return q[:f], v[:f]
            q[f], v[f] = self.sim.state.q[:nb], self.sim.state.v[:nb]
        return q, v


def measure_scene(name, peers, quick=False, repeats=3, timing_seconds=1.0, accuracy_seconds=None):
    """[row per ladder point] of scene `name` for planarsim and the peers {name: module}: scene,
    engine, curve, k, dt [s], cost_s_per_s (wall s per simulated s, median of `repeats`),
    cost_min/cost_max, steps_per_s (steps of dt / k per wall s) and the accuracy figures."""
    if name not in PEER_SCENES:
        raise ValueError(f"scene {name!r} has no peer version; peer scenes: {PEER_SCENES}")
    dt = SCENE_DT
    seconds = accuracy_seconds or scene_seconds(name)
    n_acc = max(1, int(round(seconds / dt)))
    spec = spec_from_model(name, build_model(name, dt), n_acc * dt)
    points = {}
    accurate_ok = unsupported_feature(build_model(name, dt)) is None
    for engine in ("planarsim", *peers):
        for label, kw, k in ladder(engine, quick):
            if CONTACT_KEYWORDS & set(kw) and not spec.ground:
                continue    # contact softness: nothing to vary without contacts
            m, sub = frames(k)
            if engine == "planarsim":
                if kw.get("integrator", "euler") != "euler" and not accurate_ok:
                    continue    # an accurate integrator refuses contacts (planarsim.integrator)
                world = _Planarsim(name, m * dt, sub, **kw)
            else:
                world = peers[engine].World(replace(spec, dt=m * dt), substeps=sub, **kw)
            points[(engine, label, k)] = (world, m)
    big = max(m for _, m in points.values())
    n_time = big * max(1, int(round(timing_seconds / (big * dt))))   # whole frames for every m

    def runner(world, m):
        return lambda n: world.run(n // m)
    rates = _rates({key: (runner(w, m), w.reset) for key, (w, m) in points.items()}, n_time, repeats)
    rows = []
    for (engine, label, k), (world, m) in points.items():
        costs = [1.0 / (r * dt) for r in rates[(engine, label, k)]]
        row = dict(scene=name, engine=engine, curve=label, k=k, dt=dt / k,
                   cost_s_per_s=statistics.median(costs), cost_min=min(costs), cost_max=max(costs))
        row["steps_per_s"] = k / (row["cost_s_per_s"] * dt)
        q, v = world.record(max(1, n_acc // m))
        row.update(accuracy(replace(spec, dt=m * dt), q, v))
        if spec.ground:
            row["contact_error_m"] = max(row["penetration_m"], abs(row["rest_gap_m"]))
        warnings = getattr(world, "warnings", [])
        if warnings:
            row["warning"] = f"{warnings[0][1]} (frame {warnings[0][0]}); figures up to there"
        rows.append(row)
    return rows


def _err(row, metric):
    x = row.get(metric, math.nan)
    return math.nan if x is None or math.isnan(x) else max(abs(x), FLOORS[metric])


def front(rows, metric):
    """Pareto front [(cost, error)] of ladder points: cost rising, error falling strictly; a
    run that diverged (a peer's warning) reaches no accuracy and is left out."""
    pts = sorted((r["cost_s_per_s"], _err(r, metric)) for r in rows
                 if not math.isnan(_err(r, metric)) and not r.get("warning"))
    out = []
    for cost, err in pts:
        if not out or err < out[-1][1]:
            out.append((cost, err))
    return out


def cost_at(pts, target):
    """(cost, note) of a front at error `target`, interpolated log-log between the points that
    bracket it; note "cheapest" when the cheapest point is already as accurate, None when the
    front never reaches the target (cost nan)."""
    if not pts:
        return math.nan, None
    if pts[0][1] <= target:
        return pts[0][0], "cheapest"
    for (c0, e0), (c1, e1) in zip(pts, pts[1:]):
        if e1 <= target:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(c0) + f * (math.log(c1) - math.log(c0))), "interpolated"
    return math.nan, None


def crossing(a, b, samples=64):
    """Error [unit of the figure] at which front b's cost crosses front a's over the error
    range both span (log-log interpolation), or None; a list when they cross more than once."""
    if len(a) < 2 or len(b) < 2:
        return []
    lo = max(a[-1][1], b[-1][1])
    hi = min(a[0][1], b[0][1])
    if not lo < hi:
        return []
    grid = np.exp(np.linspace(math.log(hi), math.log(lo), samples))
    diff = np.array([math.log(cost_at(b, e)[0]) - math.log(cost_at(a, e)[0]) for e in grid])
    idx = np.nonzero(np.sign(diff[:-1]) * np.sign(diff[1:]) < 0)[0]
    return [float(math.exp((math.log(grid[i]) + math.log(grid[i + 1])) / 2)) for i in idx]


def order(rows, metric):
    """Log-log slope of the error against the step along one curve at the scene's dt and finer
    (k >= 1: the observed order of the method in that figure; nan with fewer than 2 points
    above the figure's floor)."""
    pts = [(r["dt"], _err(r, metric)) for r in rows
           if r["k"] >= 1 and not r.get("warning") and not math.isnan(_err(r, metric)) and _err(r, metric) > FLOORS[metric]]
    if len(pts) < 2 or len({p[0] for p in pts}) < 2:
        return math.nan
    h, e = np.log(np.array(pts)).T
    return float(np.polyfit(h, e, 1)[0])


def curves(rows):
    """{curve label: [rows in ladder order]} of one scene."""
    out = {}
    for r in rows:
        out.setdefault(r["curve"], []).append(r)
    return out


def figures(rows):
    """The accuracy figures of ERRORS that the scene of `rows` has (no energy with a ground)."""
    ground = any(not math.isnan(_err(r, "contact_error_m")) for r in rows)
    return [m for m in ERRORS if any(not math.isnan(_err(r, m)) for r in rows)
            and not (ground and m == "energy_err_max")]


def our_curves(rows):
    """Labels of planarsim's curves among `rows` (the default step first)."""
    return list(dict.fromkeys(r["curve"] for r in rows if r["engine"] == "planarsim"))


def matched(rows, metrics=None, ours="planarsim"):
    """[summary per peer curve] of one scene against planarsim's curve `ours` (the default
    step, or an accurate integrator's); every ratio is peer cost / our cost (how many times
    faster planarsim is). raw_ratio: both at the scene's dt (k = 1). Per figure:
    target = our error at dt; ratio = the curve's cost on its Pareto front at that
    error over our cost at dt (nan: not reached; note as cost_at); peer_target = the
    curve's error at dt, ratio_at_peer = the curve's cost at dt over our cost on our
    front at that error (nan: we do not reach it, or note "diverged": the curve's run
    at dt diverged); cross = errors where the two fronts
    cross; order, our_order = observed orders (slope of log error vs log step)."""
    metrics = figures(rows) if metrics is None else metrics
    by = {label: pts for label, pts in curves(rows).items() if pts[0]["engine"] != "planarsim"}
    mine = curves(rows)[ours]
    base = next(r for r in mine if r["k"] == 1)
    out = []
    for label, pts in by.items():
        own = next(r for r in pts if r["k"] == 1)
        s = dict(scene=base["scene"], ours=ours, curve=label, engine=pts[0]["engine"],
                 raw_ratio=own["cost_s_per_s"] / base["cost_s_per_s"])
        for m in metrics:
            target, peer_target = _err(base, m), _err(own, m)
            if math.isnan(target) or math.isnan(peer_target):
                continue
            cost, note = cost_at(front(pts, m), target)
            our_cost, our_note = cost_at(front(mine, m), peer_target)
            if own.get("warning"):      # the peer diverged at dt: no accuracy to match
                our_cost, our_note = math.nan, "diverged"
            s[m] = dict(target=target, ratio=cost / base["cost_s_per_s"], note=note,
                        peer_target=peer_target, ratio_at_peer=own["cost_s_per_s"] / our_cost,
                        note_at_peer=our_note, cross=crossing(front(mine, m), front(pts, m)),
                        order=order(pts, m), our_order=order(mine, m))
        out.append(s)
    return out
