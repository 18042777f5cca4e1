"""The compass gait (two rigid-body legs pinned at a point-mass hip) as a command-line walker.

Defaults after Goswami, Thuilot and Espiau (1996): hip 10 kg, legs 5 kg with their COM half
way, slope 3 degrees. The walker starts from `default_start`, a section state near the stable
period-one gait (found with planarsim.analysis from a rough guess; see the example
examples/passive_gait.py), and walks passively.
"""
from __future__ import annotations

import numpy as np

from walkers.base import simulation

from .params import CompassParams
from .run import GAIT_DOCS, GAITS, PassiveRun, PASSIVE_EXTRAS  # noqa: F401

NAME = "compass-gait"
SUMMARY_EXTRAS = PASSIVE_EXTRAS
Params = CompassParams   # the walker's parameters (planarsim params compass-gait)


def default_start(p: CompassParams | None = None) -> np.ndarray:
    """A section state (theta, theta_dot [rad/s], phi, phi_dot [rad/s]) near the stable gait
    of the default compass gait (its fixed point at dt = 2.5e-4 s, found by iterating the step
    map from (0.22, -1.1, 0.44, -1.4) and then Newton); a rough guess for other parameters."""
    return np.array([0.27081514, -1.09186744, 0.54163176, -0.71352648])


class Run(PassiveRun):
    """The compass gait walking down its slope (walkers.passive.run.PassiveRun)."""
    NAME = NAME
    Params = CompassParams

    def start(self, params):
        return default_start(params)


simulate = simulation(Run)
