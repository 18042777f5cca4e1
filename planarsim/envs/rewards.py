"""The DeepMind Control Suite's soft indicator ``tolerance`` (dm_control.utils.rewards), in
numpy: 1 inside ``bounds``, falling off outside them over ``margin`` along a sigmoid
('gaussian', 'hyperbolic', 'long_tail', 'reciprocal', 'cosine', 'linear', 'quadratic',
'tanh_squared') to ``value_at_margin`` at distance ``margin``. Same arithmetic, in the same
order, as dm_control's, so that its values agree bit for bit where numpy's functions do.

The same for compiled code (``tolerance_at``, ``float_square``, ``numpy_mean``): the float
path's arithmetic in its order, so that a task's compiled reward (dmc_rewards.py) is the
Python one's float bit for bit."""
from __future__ import annotations

import math
import sys
import warnings

import numpy as np

from ..compile import MODE, PYTHON, kernel

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


# --- compiled: the float path's tolerance for compiled rewards (dmc_rewards.py) -------------

# sigmoid codes (tolerance_at's kind), SIGMOIDS' order
GAUSSIAN, HYPERBOLIC, LONG_TAIL, RECIPROCAL, COSINE, LINEAR, QUADRATIC, TANH_SQUARED = range(8)


def tolerance_terms(bounds=(0.0, 0.0), margin=0.0, sigmoid="gaussian",
                    value_at_margin=DEFAULT_VALUE_AT_MARGIN):
    """[lower, upper, margin, scale] as floats for tolerance_at (checked as tolerance checks
    them; scale: the sigmoid's, 0 where margin is 0 and the sigmoid never applies)."""
    lower, upper = bounds
    _scalar_tolerance(float(lower), lower, upper, margin, sigmoid, value_at_margin)  # (checks)
    scale = _SCALES[sigmoid](value_at_margin) if margin != 0 else 0.0
    return [float(lower), float(upper), float(margin), float(scale)]


if MODE == PYTHON:
    def _libm_pow(x, y):
        return math.pow(x, y)
else:
    import ctypes

    import llvmlite.binding as llvm
    from llvmlite import ir
    from numba import types
    from numba.core import cgutils
    from numba.extending import intrinsic

    # libm's pow (the process's: the one CPython's float power calls) under a name of its own,
    # published before compiled code that calls it is compiled or loaded: LLVM knows `pow`
    # and would fold pow(x, 2.0) into x * x; it cannot see into this one
    _POW = "planarsim_libm_pow"

    def _libm():
        """The C library whose pow CPython's float power calls: the process's own symbols
        (POSIX), the Universal C Runtime on Windows (CPython 3.5+ links it; CDLL(None) is
        refused there and find_library finds no C runtime)."""
        if sys.platform == "win32":
            return ctypes.CDLL("ucrtbase")
        return ctypes.CDLL(None)

    llvm.add_symbol(_POW, ctypes.cast(_libm().pow, ctypes.c_void_p).value)

    @intrinsic
    def _libm_pow(typingctx, x, y):
        """libm's pow(x, y) (floats), called as it is."""
        def codegen(context, builder, signature, args):
            fnty = ir.FunctionType(ir.DoubleType(), [ir.DoubleType(), ir.DoubleType()])
            fn = cgutils.get_or_insert_function(builder.module, fnty, _POW)
            return builder.call(fn, args)
        return types.float64(types.float64, types.float64), codegen


@kernel
def float_square(x):
    """x ** 2 of a Python float x as CPython computes it: libm's pow(|x|, 2.0), which is not
    always x * x (glibc's differs in the last bit for about 1 x in 1000). Overflow gives inf
    (CPython raises OverflowError)."""
    return _libm_pow(abs(x), 2.0)


@kernel
def _curve(d, s, kind):
    """The sigmoid `kind` at distance d [margins] with scale s (_CURVES, in their order)."""
    if kind == GAUSSIAN:
        return math.exp(-0.5 * float_square(d * s))
    if kind == HYPERBOLIC:
        return 1 / math.cosh(d * s)
    if kind == LONG_TAIL:
        return 1 / (float_square(d * s) + 1)
    if kind == RECIPROCAL:
        return 1 / (abs(d) * s + 1)
    if kind == COSINE:
        return (1 + math.cos(math.pi * d * s)) / 2 if abs(d * s) < 1 else 0.0
    if kind == LINEAR:
        return 1 - d * s if abs(d * s) < 1 else 0.0
    if kind == QUADRATIC:
        return 1 - float_square(d * s) if abs(d * s) < 1 else 0.0
    return 1 - float_square(math.tanh(d * s))


@kernel
def tolerance_at(x, lower, upper, margin, kind, scale):
    """tolerance of float x for bounds (lower, upper), margin and sigmoid code `kind` of scale
    `scale` (tolerance_terms: the parameters checked there, not here)."""
    if lower <= x <= upper:
        return 1.0
    if margin == 0:
        return 0.0
    d = (lower - x if x < lower else x - upper) / margin     # (NaN for a NaN x)
    return _curve(d, scale, kind)


@kernel
def numpy_mean(a, n):
    """np.mean of a[:n] (n >= 1) bit for bit: 0.0 plus numpy's pairwise sum (a plain sum
    below 8 entries, eight running sums up to 128), over n. Beyond 128 entries numpy splits
    the sum in halves first, which this does not (no task has that many)."""
    if n < 8:
        total = 0.0
        for i in range(n):
            total += a[i]
        return total / n
    r0, r1, r2, r3 = a[0], a[1], a[2], a[3]
    r4, r5, r6, r7 = a[4], a[5], a[6], a[7]
    i = 8
    while i < n - n % 8:
        r0 += a[i]
        r1 += a[i + 1]
        r2 += a[i + 2]
        r3 += a[i + 3]
        r4 += a[i + 4]
        r5 += a[i + 5]
        r6 += a[i + 6]
        r7 += a[i + 7]
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        total += a[i]
        i += 1
    return (0.0 + total) / n
