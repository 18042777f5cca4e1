"""Tuning objective of the Simple Biped (used by planarsim tune).

score = distance [m] walked in `duration` s (the speed loop aims at params.speed, which is not
        tuned, so this mostly rewards getting going and keeping up)
        - cot_weight * cost of transport [-] (positive actuator work per weight and distance)
        - fall_penalty * fall_loss (common.objective: 1 plus the share of the run lost)
Tuned: the walking gains, step length and swing shape (SimpleBipedParams.TUNABLE).
Deterministic: the same parameters give the same score in any process.
"""
from __future__ import annotations

from walkers.common.objective import fall_loss, finite

from .params import SimpleBipedParams
from .rollout import simulate

Params = SimpleBipedParams

DEFAULT_SETTINGS = dict(duration=10.0, terrain=None, cot_weight=10.0, fall_penalty=20.0,
                        dt=1e-3)


def evaluate(params: SimpleBipedParams, settings: dict | None = None) -> dict:
    """Score one parameter set; returns dict(score, distance, cost_of_transport, fell)."""
    st = dict(DEFAULT_SETTINGS, **(settings or {}))
    T = float(st["duration"])
    _, s, _ = simulate(T, gait="walk", terrain=st["terrain"], dt=st["dt"], params=params,
                       record_every=1000)
    cot = finite(s["cost_of_transport"], 10.0)
    score = s["distance"] - st["cot_weight"] * cot - st["fall_penalty"] * fall_loss(s, T)
    return dict(score=float(score), distance=float(s["distance"]), cost_of_transport=cot,
                fell=bool(s["fell"]))
