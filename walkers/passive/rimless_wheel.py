"""The rimless wheel as a command-line walker: starts on its closed-form steady gait."""
from __future__ import annotations

import numpy as np

from .gait import PassiveWalker, run_gait
from .params import RimlessParams
from .reference import rimless_fixed_point
from .simplest import slope_from_terrain

NAME = "rimless-wheel"
SUMMARY_EXTRAS = {
    "cost_of_transport": ("cost_of_transport", "mechanical energy lost per weight and distance along the slope over whole steps: sin(slope) on a steady gait"),
    "impacts": ("impacts", "how touchdowns were resolved: refined (located and resolved exactly) or engine"),
    "steps": ("controller_steps", "touchdowns the rollout recorded"),
}
Params = RimlessParams   # the walker's parameters (planarsim params rimless-wheel)
GAITS = ("passive",)


def closed_form(p: RimlessParams) -> dict:
    """rimless_fixed_point for these parameters (hub inertia M k^2)."""
    return rimless_fixed_point(p.slope, p.n_spokes, p.spoke_length, p.hub_mass,
                               p.hub_mass * p.hub_gyration ** 2, p.gravity)


def simulate(duration=10.0, gait="passive", terrain=None, dt=1e-3, seed=0, params=None,
             x0=None, record_every=10, impacts="refined"):
    """Roll down the slope. Returns (Trajectory, summary dict, Model); impacts: see
    walkers.passive.gait.run_gait ("refined" or "engine")."""
    if gait not in GAITS:
        raise ValueError(f"{NAME}: unknown gait {gait!r}; gaits: {GAITS}")
    p = params or RimlessParams()
    p = RimlessParams(**{**p.as_dict(), "slope": slope_from_terrain(terrain, p.slope)})
    walker = PassiveWalker(p, dt=dt)
    if x0 is None:
        x0 = np.array([-closed_form(p)["omega_after"]])
    traj, summary = run_gait(walker, x0, duration, record_every, impacts)
    return traj, summary, walker.model
