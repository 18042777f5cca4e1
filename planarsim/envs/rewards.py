"""The DeepMind Control Suite's soft indicator ``tolerance`` (dm_control.utils.rewards), in
numpy: 1 inside ``bounds``, falling off outside them over ``margin`` along a sigmoid
('gaussian', 'hyperbolic', 'long_tail', 'reciprocal', 'cosine', 'linear', 'quadratic',
'tanh_squared') to ``value_at_margin`` at distance ``margin``. Same arithmetic, in the same
order, as dm_control's, so that its values agree bit for bit where numpy's functions do."""
from __future__ import annotations

import math
import warnings

import numpy as np

DEFAULT_VALUE_AT_MARGIN = 0.1
SIGMOIDS = ("gaussian", "hyperbolic", "long_tail", "reciprocal", "cosine", "linear", "quadratic",
            "tanh_squared")


def sigmoid_value(x, value_at_1, kind):
    """1 at x == 0, value_at_1 at |x| == 1, between 0 and 1 elsewhere."""
    if kind in ("cosine", "linear", "quadratic"):
        if not 0 <= value_at_1 < 1:
            raise ValueError(f"sigmoid {kind!r}: value_at_1 must be in [0, 1), got {value_at_1}")
    elif not 0 < value_at_1 < 1:
        raise ValueError(f"sigmoid {kind!r}: value_at_1 must be strictly between 0 and 1, got "
                         f"{value_at_1}")
    if kind == "gaussian":
        scale = np.sqrt(-2 * np.log(value_at_1))
        return np.exp(-0.5 * (x * scale) ** 2)
    if kind == "hyperbolic":
        scale = np.arccosh(1 / value_at_1)
        return 1 / np.cosh(x * scale)
    if kind == "long_tail":
        scale = np.sqrt(1 / value_at_1 - 1)
        return 1 / ((x * scale) ** 2 + 1)
    if kind == "reciprocal":
        scale = 1 / value_at_1 - 1
        return 1 / (abs(x) * scale + 1)
    if kind == "cosine":
        scale = np.arccos(2 * value_at_1 - 1) / np.pi
        scaled_x = x * scale
        with warnings.catch_warnings():
            warnings.filterwarnings(action="ignore", message="invalid value encountered in cos")
            cos_pi_scaled_x = np.cos(np.pi * scaled_x)
        return np.where(abs(scaled_x) < 1, (1 + cos_pi_scaled_x) / 2, 0.0)
    if kind == "linear":
        scale = 1 - value_at_1
        scaled_x = x * scale
        return np.where(abs(scaled_x) < 1, 1 - scaled_x, 0.0)
    if kind == "quadratic":
        scale = np.sqrt(1 - value_at_1)
        scaled_x = x * scale
        return np.where(abs(scaled_x) < 1, 1 - scaled_x ** 2, 0.0)
    if kind == "tanh_squared":
        scale = np.arctanh(np.sqrt(1 - value_at_1))
        return 1 - np.tanh(x * scale) ** 2
    raise ValueError(f"unknown sigmoid {kind!r}; known: {SIGMOIDS}")


def tolerance(x, bounds=(0.0, 0.0), margin=0.0, sigmoid="gaussian",
              value_at_margin=DEFAULT_VALUE_AT_MARGIN):
    """1 where lower <= x <= upper; outside, sigmoid(distance to the nearer bound / margin)
    (0 if margin == 0). A float for a scalar x, else an array."""
    lower, upper = bounds
    if isinstance(x, float) and kind_is_scalar(sigmoid):
        return _scalar_tolerance(x, lower, upper, margin, sigmoid, value_at_margin)
    if lower > upper:
        raise ValueError(f"tolerance: lower bound {lower} > upper bound {upper}")
    if margin < 0:
        raise ValueError(f"tolerance: margin must be >= 0, got {margin}")
    in_bounds = np.logical_and(lower <= x, x <= upper)
    if margin == 0:
        value = np.where(in_bounds, 1.0, 0.0)
    else:
        d = np.where(x < lower, lower - x, x - upper) / margin
        value = np.where(in_bounds, 1.0, sigmoid_value(d, value_at_margin, sigmoid))
    return float(value) if np.isscalar(x) else value


def kind_is_scalar(kind) -> bool:
    return kind in _SCALES


# each sigmoid's scale from value_at_1, and its value at scaled x (math on floats: the
# readings of a dmc step are Python floats, and numpy's scalar calls cost microseconds each)
_SCALES = {
    "gaussian": lambda v: math.sqrt(-2 * math.log(v)),
    "hyperbolic": lambda v: math.acosh(1 / v),
    "long_tail": lambda v: math.sqrt(1 / v - 1),
    "reciprocal": lambda v: 1 / v - 1,
    "cosine": lambda v: math.acos(2 * v - 1) / math.pi,
    "linear": lambda v: 1 - v,
    "quadratic": lambda v: math.sqrt(1 - v),
    "tanh_squared": lambda v: math.atanh(math.sqrt(1 - v)),
}
_CURVES = {
    "gaussian": lambda d, s: math.exp(-0.5 * (d * s) ** 2),
    "hyperbolic": lambda d, s: 1 / math.cosh(d * s),
    "long_tail": lambda d, s: 1 / ((d * s) ** 2 + 1),
    "reciprocal": lambda d, s: 1 / (abs(d) * s + 1),
    "cosine": lambda d, s: (1 + math.cos(math.pi * d * s)) / 2 if abs(d * s) < 1 else 0.0,
    "linear": lambda d, s: 1 - d * s if abs(d * s) < 1 else 0.0,
    "quadratic": lambda d, s: 1 - (d * s) ** 2 if abs(d * s) < 1 else 0.0,
    "tanh_squared": lambda d, s: 1 - math.tanh(d * s) ** 2,
}


def _scalar_tolerance(x, lower, upper, margin, kind, value_at_margin):
    """tolerance of a float x, with math's functions (the same checks and formulas)."""
    if lower > upper:
        raise ValueError(f"tolerance: lower bound {lower} > upper bound {upper}")
    if margin < 0:
        raise ValueError(f"tolerance: margin must be >= 0, got {margin}")
    if margin != 0:
        if kind in ("cosine", "linear", "quadratic"):
            if not 0 <= value_at_margin < 1:
                raise ValueError(f"sigmoid {kind!r}: value_at_1 must be in [0, 1), got "
                                 f"{value_at_margin}")
        elif not 0 < value_at_margin < 1:
            raise ValueError(f"sigmoid {kind!r}: value_at_1 must be strictly between 0 and 1, "
                             f"got {value_at_margin}")
    if lower <= x <= upper:
        return 1.0
    if margin == 0:
        return 0.0
    d = (lower - x if x < lower else x - upper) / margin     # (NaN for a NaN x)
    return float(_CURVES[kind](d, _SCALES[kind](value_at_margin)))
