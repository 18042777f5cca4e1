"""Gradient tuning of a walker's gait parameters on its periodic gait: the step map's fixed
point, next to the CMA-ES tuner (walkers/tune.py) and on its objective.

For parameters p (tunable fields, each scaled to z in [0, 1] by its bounds, as tune.py scales
them) the gait is the fixed point x*(p) of the walker's step map, found by Newton
(planarsim.analysis.find_fixed_point: the map's exact Jacobian where it has one, central
differences where not). Its objective is the tuner's score (the walker's objective.py) of a
walk of `duration` [s] at that gait, with nothing lost to a start from rest:

    J(p) = duration * speed - cot_weight * cost of transport

speed [m/s] and cost of transport [-] measured over one period of the map from x*(p). A gait
the map cannot keep (a fall on the way, no fixed point, a Floquet multiplier on or outside the
unit circle) scores -fall_penalty: below every gait that walks (the tuner's runs that fall
score lower still, by the distance they did not cover).

The method: gradient ascent in z with a backtracking line search (Armijo's rule), each
gradient from central differences of J (2 n fixed points, each from its own settled walk),
projected on the box, and each trial kept inside it. Deterministic: the same start and settings give the same
result.

    from walkers.gait_gradient import tune_gait
    result = tune_gait("simple-biped", names=("step_length0", "clearance"), iterations=5)

Walkers with a gait map that measures its period (``cycle(x)``): simple-biped.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from planarsim.analysis import StepMapError, find_fixed_point

#: walker -> (module, class) of its gait map (x0, step_map(), cycle(x), params=...)
GAIT_MAPS = {"simple-biped": ("walkers.simple_biped.gait_map", "SimpleBipedGaitMap")}

#: [s] walking before the section each fixed point's Newton starts from (so that J is a
#: function of the parameters alone, never of the evaluations before it)
SETTLE = 5.0
#: residual [m, m/s] a fixed point must reach: the stride map jumps by about 1e-4 between
#: nearby points (its controller switches on sim steps), which Newton cannot go below
FIXED_POINT_TOL = 5e-4
#: central-difference step of the gradient, in units of each parameter's bounds; the gait
#: map's O(dt) jumps (its controller switches on sim steps) move J by ~1e-4 of itself, so a
#: step well above that share of the range (the Simple Biped's gains sit at 2-3 % of theirs)
GRADIENT_STEP = 0.005
#: the line search's first trial moves the parameter that moves most by this [unit of bounds]
FIRST_MOVE = 0.02
#: Armijo's sufficient increase, per unit of (gradient . step)
ARMIJO = 1e-4
#: halvings of a trial step before the search gives up (no ascent along the gradient)
HALVINGS = 6


@dataclass
class GaitScore:
    """The objective at one parameter set: score (J, higher is better), the fixed point x [its
    map's coordinates], speed [m/s], cost_of_transport [-], spectral radius of the map's
    Jacobian there, why it failed ("" if it did not)."""
    score: float
    x: np.ndarray | None = None
    speed: float = float("nan")
    cost_of_transport: float = float("nan")
    spectral_radius: float = float("nan")
    failed: str = ""


@dataclass
class GradientTuneResult:
    """A gradient tuning run: best parameters (all fields), their score and the start's, the
    tuned names, per iteration dict(iteration, score, gradient_norm (of the gradient projected
    on the box), largest_move [unit of bounds], evaluations), the number of fixed points found
    (objective evaluations); stopped: why it ended early."""
    walker: str
    names: tuple
    best_params: dict
    best_score: float
    start_score: float
    start: GaitScore | None = None
    best: GaitScore | None = None
    history: list = field(default_factory=list)
    evaluations: int = 0
    seconds: float = 0.0
    stopped: str = ""


class GaitObjective:
    """J(z) of the module docstring for one walker, parameters `names` about `base` (the
    walker's params dataclass), settings as the tuner's (objective.DEFAULT_SETTINGS keys:
    duration, cot_weight, fall_penalty)."""

    def __init__(self, walker: str, names, base=None, settings: dict | None = None,
                 settle: float = SETTLE):
        import importlib

        from walkers.tune import objective_module
        objective = objective_module(walker)       # (an unknown walker: KeyError naming it)
        if walker not in GAIT_MAPS:
            raise ValueError(f"walker {walker!r} has no gait map that measures its period; "
                             f"gradient tuning takes: {', '.join(sorted(GAIT_MAPS))}")
        self.walker = walker
        module, cls = GAIT_MAPS[walker]
        module = importlib.import_module(module)
        self.gait_map = getattr(module, cls)
        # Newton's difference step where the map has no exact Jacobian: its module's EPS
        self.eps = float(getattr(module, "EPS", 1e-6))
        self.base = base if base is not None else objective.Params()
        tunable = list(self.base.names(True))
        if isinstance(names, str):
            names = (names,)
        names = tuple(names) if names is not None else tuple(tunable)
        unknown = [n for n in names if n not in tunable]
        if unknown or not names:
            raise ValueError(f"not tunable parameters of {walker}: {unknown or 'none given'}; "
                             f"tunable: {', '.join(tunable)}")
        if len(set(names)) != len(names):
            raise ValueError(f"parameters named twice: {names}")
        self.names = names
        self.bounds = self.base.bounds(True)[[tunable.index(n) for n in names]]
        self.settings = dict(objective.DEFAULT_SETTINGS, **(settings or {}))
        unused = {k: v for k, v in self.settings.items() if k not in ("duration", "cot_weight",
                  "fall_penalty") and v != objective.DEFAULT_SETTINGS.get(k)}
        if unused:
            raise ValueError(f"settings {unused} are not taken by the periodic gait's objective "
                             "(its gait map walks flat ground at its own dt)")
        self.settle = float(settle)
        self.evaluations = 0

    def z_of(self, params) -> np.ndarray:
        """Unit coordinates of params' tuned fields."""
        v = np.array([float(getattr(params, n)) for n in self.names])
        return (v - self.bounds[:, 0]) / (self.bounds[:, 1] - self.bounds[:, 0])

    def params_at(self, z):
        """The base parameters with the tuned fields at unit coordinates z (clipped to [0, 1])."""
        v = self.bounds[:, 0] + np.clip(z, 0.0, 1.0) * (self.bounds[:, 1] - self.bounds[:, 0])
        return self.base.replace(**{n: float(x) for n, x in zip(self.names, v)})

    def __call__(self, z) -> GaitScore:
        """J at unit coordinates z."""
        self.evaluations += 1
        st = self.settings
        fail = -float(st["fall_penalty"])
        try:
            gm = self.gait_map(settle=self.settle, params=self.params_at(z))
            fp = find_fixed_point(gm.step_map(), gm.x0, tol=FIXED_POINT_TOL, eps=self.eps)
            if not fp.converged:
                return GaitScore(fail, fp.x, failed=f"no fixed point (residual {fp.residual:.2g})")
            radius = float(np.max(np.abs(fp.multipliers)))
            if radius >= 1.0:
                return GaitScore(fail, fp.x, spectral_radius=radius, failed="unstable gait")
            c = gm.cycle(fp.x)
        except StepMapError as e:
            return GaitScore(fail, failed=str(e))
        if not (c["duration"] > 0.0 and c["distance"] > 0.0):
            return GaitScore(fail, fp.x, failed="the gait does not move forward")
        speed = c["distance"] / c["duration"]
        cot = c["positive_work"] / (c["weight"] * c["distance"])
        score = float(st["duration"]) * speed - float(st["cot_weight"]) * cot
        return GaitScore(score, fp.x, speed, cot, radius)

    def gradient(self, z, center: GaitScore) -> np.ndarray:
        """dJ/dz at z (center: J(z)) by central differences (GRADIENT_STEP); one-sided at the
        box's faces or where the other side's gait fails, 0 where both fail."""
        g = np.zeros(z.size)
        for i in range(z.size):
            sides = []
            for dz in (-GRADIENT_STEP, GRADIENT_STEP):
                t = z.copy()
                t[i] = min(max(z[i] + dz, 0.0), 1.0)
                if t[i] != z[i]:
                    r = self(t)
                    if not r.failed:
                        sides.append((t[i] - z[i], r.score))
            if len(sides) == 2:
                (da, a), (db, b) = sides
                g[i] = (b - a) / (db - da)
            elif sides:
                (d, a), = sides
                g[i] = (a - center.score) / d
        return g


def tune_gait(walker: str = "simple-biped", names=None, iterations: int = 10, params=None,
              settings: dict | None = None, settle: float = SETTLE,
              progress=None) -> GradientTuneResult:
    """Gradient ascent of J (module docstring) from `params` (default: the walker's defaults)
    over the tunable fields `names` (default: all of them) for at most `iterations`
    gradients; progress(dict) after each."""
    if int(iterations) < 1:
        raise ValueError(f"iterations={iterations} must be >= 1")
    t0 = time.perf_counter()
    J = GaitObjective(walker, names, params, settings, settle)
    z = J.z_of(J.base)
    if np.any((z < 0.0) | (z > 1.0)):
        raise ValueError(f"the start's parameters lie outside their bounds: {dict(zip(J.names, z))}")
    start = current = J(z)
    if start.failed:
        raise StepMapError(f"{walker}: no periodic gait at the start's parameters ({start.failed})")
    history, stopped = [], ""
    for it in range(int(iterations)):
        g = J.gradient(z, current)
        g[((z <= 0.0) & (g < 0.0)) | ((z >= 1.0) & (g > 0.0))] = 0.0   # (onto the box)
        norm = float(np.linalg.norm(g))
        if not norm > 0.0:
            stopped = "the gradient vanished (or points out of the box at every parameter)"
            break
        step = FIRST_MOVE / float(np.max(np.abs(g)))
        for _ in range(HALVINGS + 1):
            trial_z = np.clip(z + step * g, 0.0, 1.0)
            if np.array_equal(trial_z, z):
                trial = None
                break
            trial = J(trial_z)
            if not trial.failed and trial.score >= current.score + ARMIJO * float(g @ (trial_z - z)):
                break
            step *= 0.5
        else:
            stopped = "no ascent along the gradient (the line search gave up)"
            break
        if trial is None:
            stopped = "the step no longer moves the parameters"
            break
        moved = float(np.max(np.abs(trial_z - z)))
        z, current = trial_z, trial
        history.append(dict(iteration=it + 1, score=current.score, gradient_norm=norm,
                            largest_move=moved,
                            evaluations=J.evaluations))
        if progress is not None:
            progress(history[-1])
    return GradientTuneResult(walker, J.names, J.params_at(z).as_dict(), current.score,
                              start.score, start, current, history, J.evaluations,
                              time.perf_counter() - t0, stopped)
