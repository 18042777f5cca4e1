"""The simplest walking model (Garcia, Chatterjee, Ruina, Coleman 1998) as a command-line
walker: starts on the published stable gait at its slope and walks passively."""
from __future__ import annotations

import math

import numpy as np

from .gait import PassiveWalker, run_gait
from .params import SimplestParams
from .reference import GARCIA_THETA, GARCIA_THETA_DOT, simplest_heel_strike

NAME = "simplest-walker"
SUMMARY_EXTRAS = {
    "cost_of_transport": ("cost_of_transport", "mechanical energy lost per weight and distance along the slope over whole steps: sin(slope) on a steady gait"),
    "impacts": ("impacts", "how touchdowns were resolved: refined (located and resolved exactly) or engine"),
    "steps": ("controller_steps", "touchdowns the rollout recorded"),
}
Params = SimplestParams   # the walker's parameters (planarsim params simplest-walker)
GAITS = ("passive",)


def slope_from_terrain(terrain, default):
    """Slope gamma [rad] of a constant-slope terrain (falling toward +x), or `default`."""
    if terrain is None:
        return default
    coef = np.asarray(terrain.coef)
    if coef[2] != 0:
        raise ValueError(f"passive walkers need a constant slope (terrain 'slope:DEG' with DEG < 0 "
                         f"for downhill), got {getattr(terrain, 'name', 'terrain')!r}")
    gamma = -math.atan(coef[1])
    if gamma < 0:
        raise ValueError(f"passive walkers walk downhill toward +x: use a negative slope angle, "
                         f"got {math.degrees(-gamma):g} deg")
    return gamma


def garcia_start():
    """Section state of the published stable gait at gamma = 0.009 (phi, phi_dot from the
    impact law)."""
    th = GARCIA_THETA
    return simplest_heel_strike([-th, GARCIA_THETA_DOT / math.cos(2.0 * th)])


def simulate(duration=10.0, gait="passive", terrain=None, dt=1e-3, seed=0, params=None,
             x0=None, record_every=10, impacts="refined"):
    """Walk down the slope. Returns (Trajectory, summary dict, Model); impacts: see
    walkers.passive.gait.run_gait ("refined" or "engine")."""
    if gait not in GAITS:
        raise ValueError(f"{NAME}: unknown gait {gait!r}; gaits: {GAITS}")
    p = params or SimplestParams()
    p = SimplestParams(**{**p.as_dict(), "slope": slope_from_terrain(terrain, p.slope)})
    walker = PassiveWalker(p, dt=dt)
    traj, summary = run_gait(walker, garcia_start() if x0 is None else x0, duration, record_every, impacts)
    return traj, summary, walker.model
