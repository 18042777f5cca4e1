"""Tuning objective of Cornell Ranger (used by planarsim tune): its figure of merit, the
electrical cost of transport, at a useful speed.

score = - cot_weight * electrical cost of transport [-] (battery power, overhead included, per
          weight and speed)
        - speed_weight * max(0, min_speed - mean speed) [m/s]
        - fall_penalty * fall_loss (common.objective: 1 plus the share of the run lost)
Tuned: the motor programs' gains, push-off and landing settings (RangerParams.TUNABLE).
Deterministic: the same parameters give the same score in any process.
"""
from __future__ import annotations

from walkers.common.objective import fall_loss, finite

from .params import RangerParams
from .rollout import simulate

Params = RangerParams

DEFAULT_SETTINGS = dict(duration=10.0, terrain=None, cot_weight=1.0, min_speed=0.4,
                        speed_weight=10.0, fall_penalty=10.0, dt=1e-3)


def evaluate(params: RangerParams, settings: dict | None = None) -> dict:
    """Score one parameter set; returns dict(score, cost_of_transport, mean_speed, fell)."""
    st = dict(DEFAULT_SETTINGS, **(settings or {}))
    T = float(st["duration"])
    _, s, _ = simulate(T, gait="walk", terrain=st["terrain"], dt=st["dt"], params=params,
                       record_every=1000)
    cot = finite(s["cost_of_transport_electrical"], 10.0)
    speed = float(s["mean_speed"])
    score = (-st["cot_weight"] * cot - st["speed_weight"] * max(0.0, st["min_speed"] - speed)
             - st["fall_penalty"] * fall_loss(s, T))
    return dict(score=float(score), cost_of_transport=cot, mean_speed=speed, fell=bool(s["fell"]))
