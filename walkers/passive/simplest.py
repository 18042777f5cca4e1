"""The simplest walking model (Garcia, Chatterjee, Ruina, Coleman 1998) as a command-line
walker: starts on the published stable gait at its slope and walks passively."""
from __future__ import annotations

import math

from walkers.base import simulation

from .params import SimplestParams
from .reference import GARCIA_THETA, GARCIA_THETA_DOT, simplest_heel_strike
from .run import GAIT_DOCS, GAITS, PassiveRun, PASSIVE_EXTRAS  # noqa: F401

NAME = "simplest-walker"
SUMMARY_EXTRAS = PASSIVE_EXTRAS
Params = SimplestParams   # the walker's parameters (planarsim params simplest-walker)


def garcia_start():
    """Section state of the published stable gait at gamma = 0.009 (phi, phi_dot from the
    impact law)."""
    th = GARCIA_THETA
    return simplest_heel_strike([-th, GARCIA_THETA_DOT / math.cos(2.0 * th)])


class Run(PassiveRun):
    """The simplest walker walking down its slope (walkers.passive.run.PassiveRun)."""
    NAME = NAME
    Params = SimplestParams

    def start(self, params):
        return garcia_start()


simulate = simulation(Run)
