"""Proportional-derivative laws and saturation (compiled).

pd(kp, kd, target, value, target_rate, rate) = kp (target - value) + kd (target_rate - rate)
Gains are per unit of whatever the caller multiplies by (e.g. [1/s^2] and [1/s] when the result
is an acceleration that the caller multiplies by a mass).
"""
from planarsim.compiled import jit


@jit
def pd(kp, kd, target, value, target_rate, rate):
    """kp (target - value) + kd (target_rate - rate)."""
    return kp * (target - value) + kd * (target_rate - rate)


@jit
def clamp(x, lo, hi):
    """x limited to [lo, hi]."""
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x
