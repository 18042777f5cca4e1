"""Tuning objective of the robot dog (used by planarsim tune): follow the commanded speed,
cheaply, without falling.

score = - speed_weight * |mean speed - commanded speed| [m/s]
        - cot_weight * cost of transport [-] (positive motor work per weight and distance)
        - fall_penalty * fall_loss (common.objective: 1 plus the share of the run lost)
Tuned: the joint servo, the feed-forward share and the stepping settings
(QuadrupedParams.TUNABLE). Deterministic: the same parameters give the same score anywhere.
"""
from __future__ import annotations

from walkers.common.objective import fall_loss, finite

from .params import QuadrupedParams
from .rollout import simulate

Params = QuadrupedParams

DEFAULT_SETTINGS = dict(duration=8.0, terrain=None, speed_weight=10.0, cot_weight=1.0,
                        fall_penalty=10.0, dt=1e-3)


def evaluate(params: QuadrupedParams, settings: dict | None = None) -> dict:
    """Score one parameter set; returns dict(score, mean_speed, cost_of_transport, fell)."""
    st = dict(DEFAULT_SETTINGS, **(settings or {}))
    T = float(st["duration"])
    _, s, _ = simulate(T, gait="walk", terrain=st["terrain"], dt=st["dt"], params=params,
                       speed=params.speed, record_every=1000)
    cot = finite(s["cost_of_transport"], 10.0)
    speed = float(s["mean_speed"])
    score = (-st["speed_weight"] * abs(speed - params.speed) - st["cot_weight"] * cot
             - st["fall_penalty"] * fall_loss(s, T))
    return dict(score=float(score), mean_speed=speed, cost_of_transport=cot, fell=bool(s["fell"]))
