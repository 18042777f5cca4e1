"""The rimless wheel as a command-line walker: starts on its closed-form steady gait."""
from __future__ import annotations

import numpy as np

from walkers.base import simulation

from .params import RimlessParams
from .reference import rimless_fixed_point
from .run import GAIT_DOCS, GAITS, PassiveRun, PASSIVE_EXTRAS  # noqa: F401

NAME = "rimless-wheel"
SUMMARY_EXTRAS = PASSIVE_EXTRAS
Params = RimlessParams   # the walker's parameters (planarsim params rimless-wheel)


def closed_form(p: RimlessParams) -> dict:
    """rimless_fixed_point for these parameters (hub inertia M k^2)."""
    return rimless_fixed_point(p.slope, p.n_spokes, p.spoke_length, p.hub_mass,
                               p.hub_mass * p.hub_gyration ** 2, p.gravity)


class Run(PassiveRun):
    """The rimless wheel rolling down its slope (walkers.passive.run.PassiveRun)."""
    NAME = NAME
    Params = RimlessParams

    def start(self, params):
        return np.array([-closed_form(params)["omega_after"]])


simulate = simulation(Run)
