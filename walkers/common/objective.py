"""What the walkers' tuning objectives share (each walker's objective.py: ``Params``,
``DEFAULT_SETTINGS``, ``evaluate(params, settings) -> dict(score=..., ...)``, higher is better;
planarsim tune maximises the score with CMA-ES)."""
from __future__ import annotations

import math


def fall_loss(summary: dict, duration: float) -> float:
    """0 for a run that did not fall; else 1 plus the share of `duration` [s] it did not reach
    (a walker that falls scores below every one that does not, by at least the penalty)."""
    if not summary.get("fell"):
        return 0.0
    return 1.0 + max(0.0, 1.0 - float(summary.get("time", duration)) / duration)


def finite(x, worst: float) -> float:
    """x as a float, or `worst` when it is NaN or infinite (a cost of transport of a run that
    did not move, say)."""
    x = float(x) if x is not None else math.nan
    return x if math.isfinite(x) else worst
