"""The passive walkers' step maps as families in one parameter, for planarsim.analysis
(continuation, bifurcation diagrams, basins) and ``planarsim analyze``."""
from __future__ import annotations

from dataclasses import fields

import numpy as np

from .gait import PassiveWalker, check_map_dt
from .params import CompassParams, RimlessParams, SimplestParams

PARAMS = {"simplest-walker": SimplestParams, "compass-gait": CompassParams,
          "rimless-wheel": RimlessParams}


def param_names(name: str) -> tuple:
    return tuple(f.name for f in fields(PARAMS[name]))


def param_bounds(name: str, param: str) -> tuple:
    f = {f.name: f for f in fields(PARAMS[name])}[param]
    return f.metadata["bounds"]


def initial_guess(name: str, params) -> np.ndarray:
    """A section state near the walker's period-one gait (a rough guess off the defaults)."""
    if name == "simplest-walker":
        from .simplest import garcia_start
        return garcia_start()
    if name == "rimless-wheel":
        from .rimless_wheel import closed_form
        return np.array([-closed_form(params)["omega_after"]])
    from .compass_gait import default_start
    return default_start(params)


class WalkerFamily:
    """p -> the step map of walker `name` with parameter `param` = p (other parameters from
    `base`, default the walker's defaults), at step size dt [s]. names: section coordinates.
    A dt that is no finite number > 0, or at which one evaluation of the map would need more
    than walkers.base.MAX_RUN_STEPS steps (gait.check_map_dt), is a ValueError naming it,
    before any walker is built."""

    def __init__(self, name: str, param: str, dt: float = 1e-3, base=None):
        if name not in PARAMS:
            raise ValueError(f"no step-map family for walker {name!r}; have {sorted(PARAMS)}")
        if param not in param_names(name):
            raise ValueError(f"{name} has no parameter {param!r}; parameters: {', '.join(param_names(name))}")
        self.name, self.param, self.dt = name, param, check_map_dt(dt)
        self.base = base if base is not None else PARAMS[name]()
        self.names = PassiveWalker(self.base, dt=self.dt).names

    def params(self, p):
        value = int(round(p)) if isinstance(getattr(self.base, self.param), int) else float(p)
        return self.base.replace(**{self.param: value})

    def walker(self, p) -> PassiveWalker:
        return PassiveWalker(self.params(p), dt=self.dt)

    def __call__(self, p):
        return self.walker(p).step_map()

    def guess(self, p) -> np.ndarray:
        return initial_guess(self.name, self.params(p))
